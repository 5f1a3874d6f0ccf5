#pragma once
// The robot's own motion sensors, an IMU and the wheel encoders: their
// readings, and the one vocabulary every layer describes them with (the
// scenario, the simulator, recordings and the SLAM settings): which of them
// a system fuses with the camera, the IMU's noise and the drive the
// encoders turn with.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

namespace pvb::sensor {

/// Which sensors a SLAM system fuses: System.Sensors of the settings, a
/// scenario's slam.sensors, the apps' --sensors.
enum class SensorSetup {
  kCamera,           ///< "camera": RGB-D only (ORB-SLAM2's RGB-D)
  kCameraImu,        ///< "camera+imu": RGB-D and a 6-axis IMU
  kCameraImuWheels,  ///< "camera+imu+wheels": and the wheel encoders
  kCameraAccel,      ///< "camera+accel": RGB-D and an accelerometer without gyro (the Kinect v1)
};
/// Every setup, in the order messages list them.
inline constexpr std::array<SensorSetup, 4> kSensorSetups = {
    SensorSetup::kCamera, SensorSetup::kCameraImu, SensorSetup::kCameraImuWheels, SensorSetup::kCameraAccel};
/// "camera", "camera+imu", "camera+imu+wheels" or "camera+accel".
const char* to_string(SensorSetup s);
/// The setup named `text` (to_string's names); nullopt otherwise.
std::optional<SensorSetup> parse_sensor_setup(std::string_view text);
/// What a key or an option naming a setup accepts, for messages and help:
/// "camera, camera+imu, camera+imu+wheels or camera+accel".
std::string sensor_setup_values();
bool uses_imu(SensorSetup s);    ///< gyro and accelerometer
bool uses_accel(SensorSetup s);  ///< the accelerometer (all but kCamera)
bool uses_wheels(SensorSetup s);

/// Kalibr's continuous-time noise model of an IMU (imu.yaml; ORB-SLAM3's
/// IMU.NoiseGyro, NoiseAcc, GyroWalk, AccWalk).
struct ImuNoise {
  double gyro_noise_density = 1.7e-4;   ///< rad/s/sqrt(Hz)
  double accel_noise_density = 2.0e-3;  ///< m/s^2/sqrt(Hz)
  double gyro_random_walk = 2.0e-5;     ///< rad/s^2/sqrt(Hz)
  double accel_random_walk = 4.0e-4;    ///< m/s^3/sqrt(Hz)
};

/// What odometry needs to know of a differential-drive robot: the nominal
/// wheel radius, the track (between the wheels' contact points) and the
/// encoders' counts per wheel revolution.
struct DriveDescription {
  double wheel_radius_m = 0.1;
  double track_m = 0.42;
  int ticks_per_rev = 1024;
};

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
