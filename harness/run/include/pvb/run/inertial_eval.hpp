#pragma once
// The inertial state a SLAM system reached, against the truth where there
// is one (docs/evaluation.md, "Inertial state and biases"):
//  - when the inertial state became trusted (MapGravity::ready), gravity's
//    tilt from the map's -z, against the true down where there is ground
//    truth, and the initialisation's whitened RMS;
//  - per keyframe with an inertial state, its final estimated IMU biases
//    against the true biases at the keyframe's time (imu0/truth.csv of a
//    recording or a run's folder, interpolated linearly between readings),
//    with the RMS of the error's norm over the keyframes.
// Times are seconds from the run's first frame.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pvb/eval/gravity.hpp"
#include "pvb/report/inertial_report.hpp"
#include "pvb/slam/core/keyframe_motion.hpp"

namespace pvb::run {

/// The biases in one IMU reading (imu0/truth.csv's bw_* and ba_*).
struct BiasTruth {
  std::int64_t t_ns = 0;
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
};

/// The biases of imu0/truth.csv (13 columns; '#' lines skipped), in time
/// order.  IoError naming the file and line for a malformed line.
std::vector<BiasTruth> read_bias_truth(const std::string& path);

/// What an online wheel calibration should find on a simulated robot: its
/// effective (rolling-straight) radius and track over the described ones,
/// the radius split between the wheels by `radius_difference`.
slam::WheelCalibration wheels_true(double effective_radius_m, double effective_track_m, double described_radius_m,
                                   double described_track_m, double radius_difference);

/// The simulated robot's effective wheel radius and track over the
/// described ones, from a recording's robot_truth.yaml (what an online
/// wheel calibration should find).  IoError naming the file and the key
/// when it cannot be read.
slam::WheelCalibration read_wheels_true(const std::string& path);

/// One line for the console: the wheels' calibration so far, and the
/// robot's where known.
std::string wheels_text(const slam::WheelFit& w, const std::optional<slam::WheelCalibration>& truth);

/// The true biases at t_ns: linear between the two readings around it, the
/// first or last reading outside them.  `truth` non-empty, in time order.
BiasTruth bias_truth_at(const std::vector<BiasTruth>& truth, std::int64_t t_ns);

/// Keeps, of one frame's readings (in time order), the first and the last
/// in `kept`.  A frame's time lies between its last reading and the next
/// frame's first, so `bias_truth_at` at any frame time gives from what is
/// kept the biases it gives from every reading: a long run keeps two
/// readings a frame, not the IMU's rate.
void keep_frame_ends(const std::vector<BiasTruth>& frame_readings, std::vector<BiasTruth>* kept);

/// One keyframe's estimated biases (slam::System::keyframe_states()).
struct KeyframeBias {
  std::uint64_t id = 0;
  std::int64_t t_ns = 0;
  slam::ImuBias bias;
};

/// The keyframes' biases against `truth` (non-empty); t0_ns: the run's first frame.
BiasComparison compare_biases(std::vector<KeyframeBias> keyframes, const std::vector<BiasTruth>& truth,
                              std::int64_t t0_ns, bool has_gyro);

/// The angle, degrees, between g_w and the map's -z.
double gravity_tilt_deg(const Eigen::Vector3d& g_w);

/// The gravity error (eval::gravity_error, degrees) of the first pose of
/// `est` at or after t_ns against `gt`, whose world's down is down_w;
/// nullopt when no such pose associates with the ground truth.
std::optional<double> gravity_error_at_deg(const eval::Trajectory& gt, const eval::Trajectory& est,
                                           const geom::Vec3d& down_w, const eval::GravityEstimates& estimates,
                                           std::int64_t t_ns);

/// What MapGravity says; biases left unset.
InertialReport inertial_report(const slam::MapGravity& gravity, std::int64_t t0_ns);

}  // namespace pvb::run
