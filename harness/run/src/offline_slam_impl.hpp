#pragma once
// `pvbench slam`'s run (pvb/run/offline_slam.hpp) as its two source files
// share it: offline_slam.cpp (inputs, the frame loop, outputs, stats.json)
// and offline_slam_eval.cpp (evaluation against the sequence's ground
// truth, the map's localisation scores and save, place recognition).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cost_log.hpp"
#include "motion_match_scorer.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/io_paths.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/eval/gravity.hpp"
#include "pvb/eval/metrics.hpp"
#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/run/offline_slam.hpp"
#include "pvb/run/inertial_eval.hpp"
#include "pvb/run/map_eval.hpp"
#include "pvb/run/output_names.hpp"
#include "pvb/run/place_events.hpp"
#include "pvb/run/sensor_setup.hpp"
#include "pvb/slam/core/system.hpp"
#include "pvb/slam/dense/point_cloud.hpp"
#include "pvb/suite/metrics_file.hpp"

namespace pvb::run {
// The run's own types (named: the run's class holds them).
namespace offline_detail {

/// Why the frame loop ended.
enum class StopReason {
  kEnd,             ///< every frame of the sequence (or max_frames of them)
  kSignal,          ///< a stop request (Ctrl-C or SIGTERM)
  kTooManyMissing,  ///< more than max_missing of the frames skipped
  kImageSize,       ///< an image differs from Camera.width x Camera.height
  kSystemError,     ///< the core stopped working (a worker's IoError: the disk under its files filled)
};

const char* stop_name(StopReason r);

/// printf into a string.
__attribute__((format(printf, 1, 2))) std::string strf(const char* format, ...);

/// Counts and per-frame series of one run.
struct Tally {
  std::size_t frames = 0, lost = 0, not_init = 0, poses = 0;
  std::size_t dead_reckoned = 0;  ///< frames carried by the motion sensors (TrackingState::kDeadReckoning)
  std::vector<double> tracking_ms, pe_ms;
  std::vector<double> cpu_ms;  ///< caller-thread CPU per frame: tracking, plus inline mapping in sync mode
  std::string init_failure;    ///< why the last frame failed to initialise
  std::vector<std::int64_t> keyframe_t_ns;  ///< every keyframe made
  std::vector<std::int64_t> frame_t_ns;     ///< every frame tracked
  eval::GravityEstimates gravity;           ///< the core's gravity where it changed (eval::record_gravity)
};
}  // namespace offline_detail

using offline_detail::StopReason;
using offline_detail::Tally;
using offline_detail::strf;

/// The run, in stages: inputs and outputs are opened by the constructor,
/// run() tracks, writes the final outputs and stats.json, and then reports
/// a run that stopped early or never initialised as an error.
class OfflineSlam::Impl {
 public:
  explicit Impl(const OfflineSlamOptions& a);
  int run();
  const slam::Settings& settings() const { return settings_; }

 private:
  slam::Settings read_settings();
  /// The motion readings the setup fuses against the frames and the
  /// settings; a supplied Kinect description takes the readings' rate.
  void check_motion();
  void open_outputs();
  bool stop_requested() const { return a_.stop && a_.stop->load(); }
  void text(const std::string& s) const {
    if (a_.on_text) a_.on_text(s);
  }
  void warn(const std::string& line) const {
    if (a_.on_warning) a_.on_warning(line);
  }
  StopReason track_frames();
  /// Tracks one frame and writes its lines; none when the core stopped
  /// working (system_error_ says why).
  std::optional<slam::TrackingState> track_one(const sensor::RgbdFrame& frame);
  void write_timing_line(const sensor::RgbdFrame& frame, const slam::FrameResult& r, double cpu_ms);
  std::string write_final_outputs();
  /// Stops the workers; a worker's IoError becomes the run's system error.
  void shutdown_system();
  std::string dense_json(std::size_t cloud_points);
  std::string stats_json(StopReason stop, const std::string& dense_json);
  void print_loop_closing(std::ostringstream* js);
  void evaluate(std::ostringstream* js);
  /// Gravity error per frame and the keyframes' pitch and roll error (docs/evaluation.md).
  void evaluate_gravity(const eval::Trajectory& gt, const eval::Trajectory& est, const eval::Sim3Transform& alignment,
                        std::ostringstream* js);
  void evaluate_refined(const eval::Trajectory& gt, const eval::EvalOptions& eo, std::ostringstream* js);
  /// A setup with an accelerometer: stats.json's "inertial", the keyframes'
  /// biases against the folder's imu0/truth.csv when it has one.
  void evaluate_inertial(std::ostringstream* js);
  /// Labels the loops and relocalisations against `gt` and prints them.
  void label_places(const eval::Trajectory& gt);
  void fail_if_incomplete(StopReason stop) const;
  /// Scores localisation in a loaded map and saves the final map; appends stats.json's "map".
  void finish_map(std::ostringstream* js);

  bool imu_supplied_ = false;  ///< set by read_settings() (first: initialised before settings_)
  const OfflineSlamOptions a_;
  slam::Settings settings_;
  dataset::TumSequenceReader reader_;
  std::unique_ptr<slam::System> system_;
  OutputFile cam_traj_, kf_traj_, timing_;
  CostLog costs_;  ///< costs.csv, and "costs" in stats.json
  std::unique_ptr<MotionMatchScorer> scorer_;
  Tally tally_;
  PlaceRecognition place_;             ///< collected after the run, labelled when there is ground truth
  std::string image_size_error_;       ///< set when the loop stopped on an image of the wrong size
  std::string system_error_;           ///< why the core stopped working (StopReason::kSystemError)
  std::optional<MapReport> map_;       ///< with --map or --save-map
  std::optional<double>
      gravity_true_deg_;  ///< the core's gravity at its trusted time against the ground truth
};

}  // namespace pvb::run
