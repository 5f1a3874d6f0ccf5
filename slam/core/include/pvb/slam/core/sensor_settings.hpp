#pragma once
// The motion sensors in the SLAM settings: which ones the core fuses
// (System.Sensors, a sensor::SensorSetup), and the IMU.* and Robot.*
// sections that describe them, in the sensor layer's vocabulary
// (pvb/sensor/motion.hpp).  Settings (settings.hpp) holds them as one
// MotionSensorSettings, which System checks once and hands to tracking
// (Tracking::use_motion_sensors) and local mapping (LocalMappingOptions).
#include <string>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/inertial/wheel_calibration.hpp"
#include "pvb/slam/inertial/wheel_preintegration.hpp"
#include "pvb/sensor/motion.hpp"

namespace pvb::slam {

/// IMU.* section, ORB-SLAM3's keys read as ORB-SLAM3 reads them (optional;
/// needed by the setups with an IMU or accelerometer).
struct ImuSettings {
  bool present = false;  ///< the section was in the file
  sensor::ImuNoise noise;  ///< IMU.NoiseGyro, NoiseAcc, GyroWalk, AccWalk
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
  sensor::ImuNoise fused_noise() const {
    sensor::ImuNoise n = noise;
    n.accel_noise_density *= accel_noise_inflation;
    n.accel_random_walk *= accel_walk_inflation;
    return n;
  }
};

/// Robot.* section (ours, optional; needed by camera+imu+wheels).
struct RobotSettings {
  bool present = false;
  sensor::DriveDescription drive;  ///< Robot.WheelRadius, Track, TicksPerRev
  double encoder_rate_hz = 50;     ///< Robot.EncoderFrequency
  geom::SE3d T_base_c = geom::SE3d::Identity();    ///< Robot.T_base_c1: the camera in the base frame
  geom::SE3d T_base_imu = geom::SE3d::Identity();  ///< Robot.T_base_imu
  /// Robot.WheelNoiseTranslation, WheelNoiseYaw, WheelNoiseYawTurn (ours,
  /// optional): what the wheel increments are weighed with. The defaults
  /// suit wheels whose radii may differ by a few tenths of a percent;
  /// wheels of equal radius hold their heading far better on a straight.
  WheelNoise wheel_noise;
  /// Robot.CalibrateWheels (ours, optional, 0/1): each wheel's radius and
  /// the track are fitted online to the keyframes' motion, and the encoders
  /// read with the fit (docs/slam_inertial.md).
  WheelCalibrationOptions wheel_calibration;
};

/// The motion sensors a system fuses and what the settings say of them.
struct MotionSensorSettings {
  /// System.Sensors (ours, optional): the sensors fused; absent: camera.
  sensor::SensorSetup setup = sensor::SensorSetup::kCamera;
  ImuSettings imu;      ///< IMU.* (optional section)
  RobotSettings robot;  ///< Robot.* (optional section)
  /// Throws ConfigError naming `source` (the settings file) when a section
  /// that `setup` needs is absent (an app calls it after a flag changed
  /// the setup; System before it uses them).
  void check(const std::string& source) const;
};

}  // namespace pvb::slam
