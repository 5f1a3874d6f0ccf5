#pragma once
// A scenario run: the simulator feeds PE-SLAM in memory, frame by frame,
// while ground truth goes to the harness through its own sink; at the end
// the trajectories are evaluated and the report folder is written.
//
// Threads (default): a render thread steps the physics and renders into a
// bounded queue; a sensor thread applies the sensor model into a second
// one (in the closed loop the render thread does both, for a short
// steering latency), paced at the camera's frame rate; the calling thread
// pops frames and runs tracking (of one or two SLAM systems); local mapping
// runs on each System's worker, at a lower priority (mapping_nice).  With `sync` everything runs inline on
// the calling thread and the run is bit-reproducible.
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>

#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/run/map_session.hpp"
#include "pvb/run/report.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/sim/robot.hpp"

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

/// ORB-SLAM2 RGB-D settings for the scenario's camera (camera.yaml of
/// `pvbench record` and of a run's report).
dataset::OrbSlamSettings orbslam_settings_for(const scenes::Scenario& scenario);
/// The scenario's IMU, encoders and mounts as a recording describes them
/// (the nominal drive: sim::nominal_description).
dataset::RobotCalibration robot_calibration_for(const scenes::Scenario& scenario);

/// Where a run may start along the scenario's route: from 0 to 1 m before
/// its end.  "" when `start_m` fits, else what was expected, e.g. "a
/// distance from 0 to 1 m before the route's end (12.50 m long)", or with
/// `scenario_file` "(the route of FILE is 12.50 m long)".
std::string start_m_expectation(const scenes::Scenario& scenario, double start_m,
                                const std::string& scenario_file = "");

/// Runs the scenario and writes the report folder (also when interrupted or
/// aborted).  Throws pvb::Error for bad configuration or I/O.
RunReport run_scenario(const RunOptions& options);

/// Closed loop: the robot's planar pose from a camera pose, given the
/// camera's fixed mounting measured at the start: `offset_b` is the camera
/// position relative to the axle centre in the robot frame (x forward,
/// y left) and `yaw_offset` the camera heading minus the robot heading.
/// The camera heading is the direction of its optical axis projected on
/// the ground plane.
struct CameraMount {
  Eigen::Vector2d offset_b = Eigen::Vector2d::Zero();
  double yaw_offset = 0;
};
/// Heading (rad, CCW from x) of a camera's optical axis (z) on the ground plane.
double camera_heading(const geom::SE3d& T_w_c);
/// Measures the mount from a ground-truth robot pose and camera pose taken together.
CameraMount measure_mount(const sim::Pose2d& base, const geom::SE3d& T_w_c);
/// The robot pose implied by a camera pose and the mount.
sim::Pose2d base_from_camera(const geom::SE3d& T_w_c, const CameraMount& mount);

}  // namespace pvb::run
