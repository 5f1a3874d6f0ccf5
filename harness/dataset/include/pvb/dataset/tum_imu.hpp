#pragma once
// The motion readings a TUM RGB-D folder may hold, read into
// sensor::ImuSample (docs/sensors.md, "The Kinect v1's accelerometer"):
//  - imu0/data.csv (EuRoC's layout, pvbench recordings): gyroscope and
//    accelerometer in the IMU's own frame, as recorded;
//  - else accelerometer.txt (the TUM RGB-D benchmark's Kinect v1
//    accelerometer, "timestamp ax ay az" in m/s^2, about 500 lines a
//    second): no gyroscope (gyro_radps quiet NaN), the specific force put
//    into the colour camera's optical frame by kR_c_kinect_accel.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "pvb/sensor/motion.hpp"

namespace pvb::dataset {

/// The Kinect v1 accelerometer's axes (as TUM writes them) in the colour
/// camera's optical frame (x right, y down, z forward): f_c = R * f_kinect.
/// Fitted on fr1/rpy against the ground-truth orientations: x and y change
/// sign, z stays (a proper rotation, 180 degrees about the optical axis).
Eigen::Matrix3d kinect_accel_to_optical();

/// The TUM mocap world's up direction (unit, in the groundtruth.txt world),
/// from the same fit on fr1/rpy: 2.8 degrees from +z.
Eigen::Vector3d tum_world_up();

/// The Kinect v1 accelerometer (Kionix KXSD9 in the sensor's head).
struct KinectAccelerometer {
  static constexpr double kCountsPerG = 819;  ///< libfreenect's FREENECT_COUNTS_PER_G
  static constexpr double kStandardGravity = 9.80665;
  /// One count: 0.01197 m/s^2 (the step between the values of accelerometer.txt).
  static constexpr double kStepMps2 = kStandardGravity / kCountsPerG;
  static constexpr double kRateHz = 500;  ///< lines a second of accelerometer.txt (504 in fr1/rpy)
  /// White noise of one reading, m/s^2: the largest axis's scatter of the
  /// second differences of fr1/rpy (0.104 m/s^2, z; x 0.056, y 0.081), about
  /// 9 counts, far above the quantisation (step / sqrt(12) = 0.0035).
  static constexpr double kReadingNoiseMps2 = 0.104;
  /// The same as a noise density (IMU.NoiseAcc): reading noise / sqrt(rate).
  static double noise_density() { return kReadingNoiseMps2 / 22.360679774997898; }  // sqrt(500)
  /// Bias random walk (IMU.AccWalk), m/s^3/sqrt(Hz): not measured (28 s of
  /// data); ten times the default of the IMU settings.
  static constexpr double kRandomWalk = 4.0e-3;
};

/// Readings no IMU gives, per axis: 200 g (an ADXL375's range) and
/// 100 rad/s (5700 deg/s, above any MEMS gyroscope's range).  A reading
/// beyond them is a damaged line, not a measurement.
inline constexpr double kMaxAccelMps2 = 2000.0;
inline constexpr double kMaxGyroRadps = 100.0;

/// Reads accelerometer.txt, TUM's "timestamp ax ay az" in the Kinect v1
/// accelerometer's axes (kinect_accel_to_optical), put into the optical
/// frame.  IoError naming the file and line for a line that is not that (a
/// time stamp in seconds and three finite numbers within kMaxAccelMps2), and
/// for a time stamp not after the line before's (readings are in time
/// order, each once).  `lines`, when given, gets each reading's line.
std::vector<sensor::ImuSample> read_tum_accelerometer(const std::string& path,
                                                      std::vector<int>* lines = nullptr);

/// Reads imu0/data.csv ("t_ns,wx,wy,wz,ax,ay,az"); IoError naming the file
/// and line for a line that is not that (an integer time stamp in ns within
/// int64 and six finite numbers within the bounds above), and for a time
/// stamp not after the line before's.
std::vector<sensor::ImuSample> read_euroc_imu(const std::string& path, std::vector<int>* lines = nullptr);

/// Which motion readings `dir` holds.
enum class TumImuSource {
  kNone,
  kEurocImu,          ///< imu0/data.csv
  kKinectAccelerometer,  ///< accelerometer.txt without imu0/data.csv
};
TumImuSource tum_imu_source(const std::string& dir);

/// The readings of `dir` (empty for kNone).
std::vector<sensor::ImuSample> read_tum_imu(const std::string& dir);

}  // namespace pvb::dataset
