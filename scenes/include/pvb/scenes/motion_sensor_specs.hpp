#pragma once
// The robot's body sensors as a scenario describes them: the physics rate,
// the IMU (pose on the robot, rate, Kalibr noise model) and the wheel
// encoders (scenes/SCHEMA.md, docs/sensors.md).
#include <Eigen/Core>
#include <optional>
#include <string>

#include "pvb/geometry/se3.hpp"
#include "pvb/sensor/motion.hpp"

namespace pvb::scenes {

/// One inertial sensor of the IMU in Kalibr's noise model.  Units are those
/// of the reading: rad/s for the gyroscope, m/s^2 for the accelerometer.
struct InertialNoise {
  double noise_density = 0;  ///< white noise, unit / sqrt(Hz)
  double random_walk = 0;    ///< bias random walk, unit / s / sqrt(Hz)
  double turn_on_bias = 0;   ///< standard deviation of the bias at power-on, unit
  double range = 1e9;        ///< readings saturate at +-range, unit
  int bits = 0;              ///< resolution: 2 range / 2^bits a step; 0: none
};

/// A MEMS part's datasheet figures (docs/sensors.md gives the sources).
enum class ImuPart { kBmi088, kBmi055 };
const char* to_string(ImuPart part);
/// The gyroscope's and the accelerometer's noise of a part.
InertialNoise part_gyro(ImuPart part);
InertialNoise part_accel(ImuPart part);

struct Imu {
  ImuPart part = ImuPart::kBmi088;
  /// Samples a second; unset: 200 Hz when the physics rate is a multiple of
  /// it, else the divisor of the physics rate nearest to 200 Hz.
  std::optional<double> rate_hz;
  /// Where the IMU sits in the camera's optical frame (x right, y down, z
  /// forward), metres, and how its axes turn from the camera's (roll, pitch,
  /// yaw about the camera's x, y, z, degrees).
  Eigen::Vector3d p_c_i_m{0.010, 0.005, -0.012};
  Eigen::Vector3d rpy_c_i_deg{0.0, 0.0, 0.0};
  InertialNoise gyro = part_gyro(ImuPart::kBmi088);
  InertialNoise accel = part_accel(ImuPart::kBmi088);
};

/// The IMU's noise in Kalibr's model: its gyroscope's and accelerometer's
/// noise densities and random walks (imu.yaml, the settings' IMU.*).
sensor::ImuNoise kalibr_noise(const Imu& imu);

/// Incremental encoders on both driven wheels.
struct Wheels {
  int ticks_per_rev = 1024;
  /// Samples a second; unset: 50 Hz when the physics rate is a multiple of
  /// it, else the divisor of the physics rate nearest to 50 Hz.
  std::optional<double> rate_hz;
};

/// The physics step.  Unset rate: the largest step of at most 2 ms that
/// divides the camera period.
struct Physics {
  std::optional<double> rate_hz;
};

struct Scenario;
/// The camera's optical frame (x right, y down, z forward) in the robot's
/// base: the free body whose origin is the middle of the wheel axle, x
/// forward, z up.  The camera sits on the mast at camera.mount_forward_m,
/// camera.mount_height_m above the ground, turned by yaw_deg and pitch_deg.
geom::SE3d T_base_camera(const Scenario& s);
/// The IMU's frame in the camera's: imu.p_c_i_m and imu.rpy_c_i_deg.
geom::SE3d T_camera_imu(const Imu& imu);
/// The IMU's frame in the base: T_base_camera * T_camera_imu.
geom::SE3d T_base_imu(const Scenario& s);

/// The divisor of `physics_hz` (physics_hz / k for a whole k) nearest to
/// `wanted_hz`; the lower one on a tie.
double nearest_divisor_rate(double physics_hz, double wanted_hz);
/// Whether `rate_hz` divides `physics_hz` (physics_hz / rate_hz is whole).
bool divides(double rate_hz, double physics_hz);

}  // namespace pvb::scenes
