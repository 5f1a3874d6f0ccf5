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
#include <string>

#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/report/report.hpp"
#include "pvb/run/run_options.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/sim/robot.hpp"

namespace pvb::run {

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
