#pragma once
// What a scenario run is asked to do (`pvbench run`'s options, a campaign
// session's run): code that only fills or reads the options includes this,
// not the whole run API (pvb/run/run.hpp).
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>

#include "pvb/run/map_session.hpp"
#include "pvb/sensor/motion.hpp"

namespace pvb::run {

/// Which SLAM systems see the frames.
enum class SlamMode {
  kPeSlam,    ///< PE-SLAM only
  kBaseline,  ///< the baseline only (PE-match off: ORB-SLAM2's motion model)
  kCompare,   ///< both on the same rendered frames; PE-SLAM is the primary run
};

struct RunOptions {
  std::string scenario_file;
  std::string out_dir;
  /// An earlier pvbench output in out_dir is emptied first (--overwrite);
  /// false: a folder that holds anything is refused.
  bool overwrite = false;
  std::optional<std::uint64_t> seed;  ///< overrides the scenario's seed (also seeds PE-match)
  int max_frames = 0;                 ///< cap (0: the scenario's duration)
  /// Overrides the scenario's route.start_m: the robot starts this far
  /// along its route (--start-m); at least 1 m before its end.
  std::optional<double> start_m;
  bool sync = false;                  ///< no threads: bit-identical runs
  SlamMode mode = SlamMode::kPeSlam;
  /// Overrides the settings' sensor setup (camera.yaml's System.Sensors,
  /// absent: camera) for every system (--sensors).
  std::optional<sensor::SensorSetup> sensors;
  /// Two setups on the same rendered frames (--compare-sensors A,B): the
  /// primary run fuses B, the reference run (report.baseline, folder
  /// baseline/) fuses A; both with PE-match unless mode is kBaseline.
  /// Not with kCompare.
  std::optional<std::pair<sensor::SensorSetup, sensor::SensorSetup>> compare_sensors;
  bool closed_loop = false;        ///< steer from the SLAM pose instead of ground truth
  bool loop_closing = true;        ///< false: LoopClosing.enabled = 0 for every system (--no-loop-closing)
  /// Score the dense maps against the scenario's true surface
  /// (docs/map_accuracy.md); false: write them only (--no-map-eval).
  bool map_eval = true;
  /// Start from a saved map (localise in it or extend it) and/or save the
  /// final map (--map, --map-mode, --save-map).
  MapOptions map;
  std::string gl = "auto";         ///< auto, egl or osmesa
  std::size_t queue_capacity = 3;  ///< frames the producer may run ahead (open loop)
  /// Pipelined: release frame i no earlier than i / fps after the first,
  /// as a camera delivers them, instead of as fast as the stages go.
  bool pace = true;
  /// Pipelined: nice value of SLAM's background workers (local and dense
  /// mapping); nullopt: 10 when paced, 0 otherwise.  Tracking makes a
  /// keyframe only when local mapping is idle, so mapping takes whatever
  /// CPU is left; at a lower priority it takes only that, and the stages
  /// that must keep up with the camera are not slowed by it.  Free-running
  /// stages leave it nothing, hence 0 without pacing.
  std::optional<int> mapping_nice;
  /// Set asynchronously (by a signal handler) to stop the run; the partial
  /// report is then written with status "interrupted".  May be null.
  const std::atomic<bool>* stop = nullptr;
  /// Receives each log line (also written to run.log); may be empty.
  std::function<void(const std::string&)> on_log;
  /// Called after each processed frame with (frames done, frames total).
  std::function<void(std::size_t, std::size_t)> on_progress;
};

}  // namespace pvb::run
