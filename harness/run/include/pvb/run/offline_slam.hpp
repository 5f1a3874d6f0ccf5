#pragma once
// The offline SLAM pipeline of `pvbench slam`: PE-SLAM (or its ORB-SLAM2
// baseline) on a TUM RGB-D folder, frame by frame from the disk.  It writes
// the trajectories (CameraTrajectory.txt, CameraTrajectoryRefined.txt,
// KeyFrameTrajectory.txt), per-frame timing (timing.csv) and stats.json;
// with a groundtruth.txt in the folder it evaluates ATE and RPE; unless
// disabled, the dense map goes to PointCloud.ply (docs/slam.md).
//
// The command line only parses the flags, gives them here and prints what
// the hooks hand it: the pipeline writes nothing to stdout or stderr itself.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "pvb/run/map_session.hpp"
#include "pvb/slam/core/settings.hpp"

namespace pvb::run {

/// A sequence that names no seed (a TUM download) runs with this PE-match seed.
inline constexpr std::uint32_t kDefaultOfflineSeed = 1;

struct OfflineSlamOptions {
  std::string sequence;  ///< TUM RGB-D folder
  std::string settings;  ///< ORB-SLAM2 RGB-D settings file
  std::string out;       ///< output folder
  bool overwrite = false;
  bool no_pe_match = false;  ///< the baseline: ORB-SLAM2's motion model
  bool sync = false;         ///< no worker threads: bit-identical runs
  bool no_dense = false;     ///< no dense map
  std::uint32_t seed = kDefaultOfflineSeed;
  std::string seed_source = "default";  ///< where the seed came from (resolve_offline_seed)
  long long max_frames = 0;             ///< frames to track, 0: all
  double max_missing = 0.1;             ///< share of the frames that may be missing or corrupt
  bool dump_matches = false;            ///< score the motion model's matches (motion_matches.csv)
  bool dump_map = false;                ///< Map.txt
  MapOptions map;
  /// Overrides the settings' System.Sensors (--sensors); nullopt: keep it.
  std::optional<sensor::SensorSetup> sensors;
  /// Set asynchronously (a signal) to stop taking frames; may be null.
  const std::atomic<bool>* stop = nullptr;

  /// stdout text, exactly as it is to be printed (lines end in '\n').
  std::function<void(const std::string&)> on_text;
  /// One stderr line without its newline: "warning: ..." or "note: ...".
  std::function<void(const std::string&)> on_warning;
  /// Before the first frame: the progress bar's label and the frames to track.
  std::function<void(const std::string& label, std::size_t total)> on_progress_begin;
  /// After each frame: frames done and the tracking state.
  std::function<void(std::size_t done, const std::string& state)> on_progress;
  /// After the last frame (before the outputs are written).
  std::function<void()> on_progress_end;
};

/// PE-match's seed: `flag` (--seed) when given, else the seed the recording
/// was made with (its meta.json, as pvbench record writes it, or a run
/// folder's metrics.json), so that a replay is the run it recorded; else
/// kDefaultOfflineSeed.  Sets options->seed and seed_source.
void resolve_offline_seed(std::optional<std::uint32_t> flag, OfflineSlamOptions* options);

/// Checks the numeric options (--max-frames, --max-missing): ConfigError
/// naming the flag and the range.
void check_offline_options(const OfflineSlamOptions& options);

/// One run.  The constructor reads the settings (warnings through
/// on_warning), opens the sequence, checks every path, loads a map and
/// prepares the output folder; run() tracks, writes the outputs and
/// stats.json and then throws for a run that stopped on bad input or never
/// initialised (after everything is written).  run() returns 0, or 130
/// when a stop request ended the frames (or came while writing).
class OfflineSlam {
 public:
  explicit OfflineSlam(const OfflineSlamOptions& options);
  ~OfflineSlam();
  OfflineSlam(const OfflineSlam&) = delete;
  OfflineSlam& operator=(const OfflineSlam&) = delete;

  /// The settings the run uses (flags and supplied sections applied).
  const slam::Settings& settings() const;
  int run();

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pvb::run
