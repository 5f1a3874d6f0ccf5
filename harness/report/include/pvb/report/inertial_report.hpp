#pragma once
// The inertial state a SLAM system reached as the report holds it
// (docs/evaluation.md, "Inertial state and biases"): when it became
// trusted, gravity's tilt, and per keyframe the estimated IMU biases
// against the true ones; metrics.json's "inertial" object.  Building it
// from a System and the truth is harness/run's inertial_eval.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pvb/slam/inertial/wheel_calibration.hpp"

namespace pvb::run {

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
  /// With wheels calibrated online: the fit, and the robot as simulated
  /// against its description (effective radius and track over the
  /// described ones) where known.
  std::optional<slam::WheelFit> wheels;
  std::optional<slam::WheelCalibration> wheels_true;
};

/// {"trusted", "trusted_t_s", "trusted_keyframe", "gravity_tilt_deg", "init_rms", "biases"}: null where
/// not trusted; "biases" null without truth, else {"keyframes", "gyro_rms_radps", "accel_rms_mps2",
/// "gyro_final_radps", "accel_final_mps2", "keyframe_id", "t_s", "gyro_est_radps", "gyro_true_radps",
/// "accel_est_mps2", "accel_true_mps2"} (series of [x, y, z] per keyframe; gyro ones null without a gyro);
/// "wheels" null without an online wheel calibration, else {"left_scale", "right_scale", "track_scale",
/// "radii_known", "track_known", "intervals", "refused", "rolled_m", "turned_rad", "true_left_scale",
/// "true_right_scale", "true_track_scale"} (the true ones null without truth).
std::string inertial_json(const InertialReport& r);

}  // namespace pvb::run
