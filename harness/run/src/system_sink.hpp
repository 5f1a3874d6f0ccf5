#pragma once
// The SLAM systems of a run: each with its output files (CameraTrajectory,
// KeyFrameTrajectory, timing.csv), its per-frame bookkeeping and its loss
// and recovery events, finished and evaluated at the end.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pvb/common/output_file.hpp"
#include "pvb/eval/gravity.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/run/inertial_eval.hpp"
#include "pvb/run/loss_log.hpp"
#include "pvb/run/map_eval.hpp"
#include "pvb/report/report.hpp"
#include "pvb/run/run_options.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"
#include "cost_log.hpp"
#include "run_log.hpp"

namespace pvb::run {

/// One SLAM system with its output files and bookkeeping.
struct SystemSink {
  MapOptions map_options;
  SlamRun run;
  std::unique_ptr<slam::System> system;
  std::string dir;
  OutputFile cam_traj, kf_traj, timing;
  CostLog costs;  ///< costs.csv; run.costs at finish()
  eval::Trajectory est;
  eval::GravityEstimates gravity_estimates;  ///< the core's gravity where it changed (eval::record_gravity)
  std::optional<double>
      gravity_true_deg;      ///< at the trusted time, against the ground truth (evaluate_gravity)
  eval::Trajectory refined;  ///< filled by finish()
  eval::Trajectory keyframes;  ///< filled by finish(): the keyframes' final poses (KeyFrameTrajectory.txt)
  std::optional<std::int64_t> first_t_ns;  ///< the first frame's time: the inertial report's t = 0
  slam::TrackingState prev_state = slam::TrackingState::kNotInitialized;
  bool prev_provisional = false;  ///< the last frame was tracked in a provisional map
  bool inertial_logged = false;   ///< run.log has said when the inertial state became trusted
  LossLog loss_log{""};           ///< why each lost frame stayed lost (run.log)
  double tracking_ms = 0, orb_ms = 0, inline_mapping_ms = 0;
  std::vector<std::int64_t> keyframe_t_ns;  ///< every keyframe made, for the revisit labels
  /// The dense maps' files written by finish() (corrected, live, and
  /// before_loop / after_loop when a loop was closed), read back for scoring.
  std::vector<DenseMapFile> dense_files;
  /// What stopped the system's work (a worker's IoError: the disk under its
  /// spill files filled); empty while it works.
  std::string failure;

  /// The system, with the saved map loaded when `map` names one; nothing
  /// is written until open_outputs().
  SystemSink(const std::string& mode, const slam::Settings& settings, bool sync, std::uint32_t seed,
             const std::string& out_dir, const MapOptions& map = {});

  /// Creates the folder (when missing) and the per-frame output files.
  void open_outputs();

  /// Tracks one frame, writes its lines and records loss and recovery.
  slam::FrameResult track(const sensor::RgbdFrame& frame, RunLog& log);

  /// Writes the lines of a loss that lasts to the end of the run.
  void end_losses(RunLog& log);

  /// Stops mapping, rewrites the keyframe trajectory with refined poses,
  /// writes the dense maps.  A worker's IoError is kept in `failure`, and
  /// what it left is written all the same.
  void finish();

  /// ATE/RPE of the trajectory (and of the refined one) against `gt`,
  /// the gravity error and the keyframes' tilt drift.
  void evaluate(const eval::Trajectory& gt);
  /// A setup with an IMU: the inertial state (run.inertial) after finish(),
  /// its keyframes' biases against `truth` when it is not empty.
  /// The inertial state and biases against `truth`; the wheels' online
  /// calibration against `wheels_true` where given.
  void evaluate_inertial(const std::vector<BiasTruth>& truth,
                         const std::optional<slam::WheelCalibration>& wheels_true = std::nullopt);
  /// The localisation in a loaded map against `gt`, and the final map
  /// saved when the options say so (run::finish_map).
  void finish_map(const eval::Trajectory& gt, const std::string& scenario, const std::string& scenario_file);

 private:
  /// The dense maps' PLY files (dense_files); run.dense_map.
  void save_dense_maps();
  /// run.gravity and run.tilt against `gt` (site frame, z up) after run.eval.
  void evaluate_gravity(const eval::Trajectory& gt);
  /// Once the inertial state is trusted: a line in run.log saying when and what was found.
  void log_inertial_state(int index, RunLog& log);
  /// The counters and the per-frame record.
  void count(const slam::FrameResult& r, int index, double t_s);
  /// The frame's lines in CameraTrajectory, KeyFrameTrajectory and timing.csv.
  void write_lines(const slam::FrameResult& r, int index);
};

using SystemSinks = std::vector<std::unique_ptr<SystemSink>>;

/// The systems that see the frames (options.mode): PE-SLAM or the baseline
/// in out_dir, and with kCompare the baseline beside PE-SLAM in
/// out_dir/baseline.  The first is the primary run.  `map`: the map
/// options (options.map with the run's station).  Their saved maps are
/// loaded; their output files are not opened yet (open_outputs()).
SystemSinks make_systems(const slam::Settings& settings, const RunOptions& options, std::uint32_t seed,
                         const MapOptions& map);

}  // namespace pvb::run
