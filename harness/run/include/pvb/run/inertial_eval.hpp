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

/// The true biases at t_ns: linear between the two readings around it, the
/// first or last reading outside them.  `truth` non-empty, in time order.
BiasTruth bias_truth_at(const std::vector<BiasTruth>& truth, std::int64_t t_ns);

/// One keyframe's estimated biases (slam::System::keyframe_states()).
struct KeyframeBias {
  std::uint64_t id = 0;
  std::int64_t t_ns = 0;
  slam::ImuBias bias;
};

using Axes = std::array<std::vector<double>, 3>;  ///< x, y, z series

/// Per keyframe (in time order): the estimated and the true biases.
struct BiasComparison {
  bool has_gyro = true;  ///< false: an accelerometer alone (no gyro bias estimated; gyro fields left out)
  std::vector<std::uint64_t> keyframe_id;
  std::vector<double> t_s;  ///< seconds from the run's first frame
  Axes gyro_est_radps, gyro_true_radps, accel_est_mps2, accel_true_mps2;
  /// RMS over the keyframes of |estimated - true|, and the last keyframe's.
  double gyro_rms_radps = 0, accel_rms_mps2 = 0;
  double gyro_final_radps = 0, accel_final_mps2 = 0;
};

/// The keyframes' biases against `truth` (non-empty); t0_ns: the run's first frame.
BiasComparison compare_biases(std::vector<KeyframeBias> keyframes, const std::vector<BiasTruth>& truth,
                              std::int64_t t0_ns, bool has_gyro);

/// The inertial state of a system that fuses an IMU.
struct InertialReport {
  bool trusted = false;    ///< the inertial initialisation succeeded
  double trusted_t_s = 0;  ///< from the run's first frame (trusted only)
  std::uint64_t trusted_keyframe = 0;
  double gravity_tilt_deg = 0;           ///< g_w's angle from the map's -z (trusted only)
  double init_rms = 0;                   ///< the initialisation's whitened residual RMS (trusted only)
  std::optional<BiasComparison> biases;  ///< with truth and keyframes with an inertial state
  /// With ground truth (trusted only): the angle between the core's gravity
  /// and the true down at the first pose at or after the trusted time, both
  /// seen from that camera (eval::gravity_error).  Unlike gravity_tilt_deg,
  /// which measures the map against itself, it sees a map levelled upside
  /// down: 180 degrees.
  std::optional<double> gravity_true_deg;
};

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

/// {"trusted", "trusted_t_s", "trusted_keyframe", "gravity_tilt_deg", "init_rms", "biases"}: null where
/// not trusted; "biases" null without truth, else {"keyframes", "gyro_rms_radps", "accel_rms_mps2",
/// "gyro_final_radps", "accel_final_mps2", "keyframe_id", "t_s", "gyro_est_radps", "gyro_true_radps",
/// "accel_est_mps2", "accel_true_mps2"} (series of [x, y, z] per keyframe; gyro ones null without a gyro).
std::string inertial_json(const InertialReport& r);

}  // namespace pvb::run
