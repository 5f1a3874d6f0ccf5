#pragma once
// The motion sensors in the SLAM settings: which ones the core fuses
// (System.Sensors), and the IMU.* and Robot.* sections that describe them.
// Settings (settings.hpp) holds them; LocalMappingOptions (options.hpp)
// and Tracking::use_motion_sensors take them too.
#include <optional>
#include <string_view>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/inertial/imu_preintegration.hpp"
#include "pvb/slam/inertial/wheel_preintegration.hpp"

namespace pvb::slam {

/// Which sensors the core fuses (System.Sensors, or a flag of the apps).
enum class SensorSetup {
  kCamera,           ///< "camera": RGB-D only (ORB-SLAM2's RGB-D)
  kCameraImu,        ///< "camera+imu": RGB-D and a 6-axis IMU
  kCameraImuWheels,  ///< "camera+imu+wheels": and the wheel encoders
  kCameraAccel,      ///< "camera+accel": RGB-D and an accelerometer without gyro (the Kinect v1)
};
const char* to_string(SensorSetup s);
/// "camera", "camera+imu", "camera+imu+wheels" or "camera+accel"; nullopt otherwise.
std::optional<SensorSetup> parse_sensor_setup(std::string_view text);
bool uses_imu(SensorSetup s);     ///< gyro and accelerometer
bool uses_accel(SensorSetup s);   ///< the accelerometer (all but kCamera)
bool uses_wheels(SensorSetup s);

/// IMU.* section, ORB-SLAM3's keys read as ORB-SLAM3 reads them (optional;
/// needed by the setups with an IMU or accelerometer).
struct ImuSettings {
  bool present = false;  ///< the section was in the file
  ImuNoise noise;        ///< IMU.NoiseGyro, NoiseAcc, GyroWalk, AccWalk
  double rate_hz = 200;  ///< IMU.Frequency
  geom::SE3d T_b_c = geom::SE3d::Identity();  ///< IMU.T_b_c1: the camera in the IMU (body) frame
  /// IMU.AccNoiseInflation (ours, optional): the factor on IMU.NoiseAcc
  /// the core weighs the accelerometer with. A noise density describes the
  /// sensor at rest; on a robot driving rough ground the readings carry
  /// more (docs/slam_inertial.md, "Accelerometer noise on a moving robot").
  double accel_noise_inflation = 3.0;
  /// IMU.AccWalkInflation (ours, optional): the factor on IMU.AccWalk in
  /// the bias walk between keyframes. The initialisation cannot tell the
  /// accelerometer's bias from a tilt on a drive at constant speed; at the
  /// datasheet's walk the bias it leaves cannot move when a turn shows it
  /// (docs/slam_inertial.md, "Accelerometer noise on a moving robot").
  double accel_walk_inflation = 100.0;
  /// The noise the core's preintegration uses: `noise` with the
  /// accelerometer's density and random walk times their inflations.
  ImuNoise fused_noise() const {
    ImuNoise n = noise;
    n.accel_noise_density *= accel_noise_inflation;
    n.accel_random_walk *= accel_walk_inflation;
    return n;
  }
};

/// Robot.* section (ours, optional; needed by camera+imu+wheels).
struct RobotSettings {
  bool present = false;
  WheelDrive drive;                ///< Robot.WheelRadius, Track, TicksPerRev
  double encoder_rate_hz = 50;     ///< Robot.EncoderFrequency
  geom::SE3d T_base_c = geom::SE3d::Identity();    ///< Robot.T_base_c1: the camera in the base frame
  geom::SE3d T_base_imu = geom::SE3d::Identity();  ///< Robot.T_base_imu
};

}  // namespace pvb::slam
