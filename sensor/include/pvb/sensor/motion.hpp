#pragma once
// The robot's own motion sensors: an IMU and the wheel encoders.
#include <Eigen/Core>
#include <cstdint>
#include <limits>

namespace pvb::sensor {

/// One IMU reading in the IMU's frame: the angular rate and the specific
/// force (acceleration minus gravity: +9.81 m/s^2 up at rest), each the
/// mean over the sample period that ends at t_ns (EuRoC's imu0 layout).
/// An accelerometer without a gyroscope (the Kinect v1's) leaves
/// gyro_radps quiet NaN in every component: has_gyro() is false.
struct ImuSample {
  std::int64_t t_ns = 0;
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
};

/// Whether `s` holds an angular rate: false when gyro_radps has a NaN (a
/// reading of an accelerometer alone).
inline bool has_gyro(const ImuSample& s) { return !s.gyro_radps.hasNaN(); }

/// gyro_radps of a reading without a gyroscope.
inline Eigen::Vector3d no_gyro() {
  return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
}

/// The two wheel encoders' counts at t_ns, positive forward.
struct WheelTicks {
  std::int64_t t_ns = 0;
  std::int64_t left = 0;
  std::int64_t right = 0;
};

}  // namespace pvb::sensor
