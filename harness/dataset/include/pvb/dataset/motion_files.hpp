#pragma once
// The motion sensors' files of a recording (docs/sensors.md): EuRoC's
// imu0/data.csv, TUM's accelerometer.txt, the raw encoder counts
// (wheels.csv), an OpenLORIS-style odom.txt from those counts, Kalibr's
// imu.yaml and the robot's description (robot.yaml).
#include <string>
#include <vector>

#include "pvb/common/output_file.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/sensor/rgbd_frame.hpp"
#include "pvb/sensor/wheel_odometry.hpp"

namespace pvb::dataset {

/// What a recording says of the robot carrying the camera.
struct RobotCalibration {
  sensor::ImuNoise imu;        ///< Kalibr's noise model of the IMU
  double imu_rate_hz = 200;
  sensor::DriveDescription drive;        ///< nominal values
  double encoder_rate_hz = 50;
  geom::SE3d T_b_c = geom::SE3d::Identity();  ///< camera optical frame in the base
  geom::SE3d T_b_i = geom::SE3d::Identity();  ///< IMU in the base
};

/// Kalibr's imu.yaml of an IMU reading at `rate_hz`.
std::string kalibr_imu_yaml(const sensor::ImuNoise& noise, double rate_hz);
/// robot.yaml: the nominal drive, the rates and both mounts.
std::string robot_yaml(const RobotCalibration& c);

/// Writes the readings that come with each frame; every file is flushed
/// after each frame, so an interrupted recording keeps what it wrote.
class MotionFilesWriter {
 public:
  /// Creates imu0/ in `dir` and the files, with imu.yaml and robot.yaml.
  /// accelerometer.txt is written as TUM's: the Kinect v1 accelerometer's
  /// axes (tum_imu.hpp), the IMU's readings turned by the camera's mount.
  MotionFilesWriter(const std::string& dir, const RobotCalibration& c);
  void write(const sensor::RgbdFrame& frame) { write(frame.imu, frame.wheel_ticks); }
  void write(const std::vector<sensor::ImuSample>& imu, const std::vector<sensor::WheelTicks>& ticks);

 private:
  OutputFile imu_csv_, accel_txt_, wheels_csv_, odom_txt_;
  sensor::WheelOdometry odometry_;
  Eigen::Matrix3d R_kinect_i_;  ///< the IMU's axes in the Kinect accelerometer's (accelerometer.txt)
};

/// A folder's motion readings, read back: the IMU's (read_tum_imu:
/// imu0/data.csv, else a Kinect's accelerometer.txt) and the encoders'
/// (wheels.csv), each in time order (empty when the files are absent), with
/// the file each came from and each reading's line in it.
struct MotionReadings {
  std::vector<sensor::ImuSample> imu;
  std::vector<sensor::WheelTicks> ticks;
  std::string imu_file, ticks_file;      ///< empty when not read
  std::vector<int> imu_line, tick_line;  ///< the line of each reading
  bool empty() const { return imu.empty() && ticks.empty(); }
};

/// Reads the motion files in `dir` that are there.  A malformed line, a
/// non-finite value or a time that does not increase is an IoError naming
/// the file and line.
MotionReadings read_motion_readings(const std::string& dir);

/// What a run needs of a folder's motion files: its sensor setup's streams.
struct MotionNeeds {
  bool accelerometer = false;  ///< imu0/data.csv, else accelerometer.txt
  bool gyroscope = false;      ///< imu0/data.csv (gyroscope and accelerometer)
  bool wheels = false;         ///< wheels.csv
  std::string who;             ///< named in errors ("--sensors camera+imu")
  bool any() const { return accelerometer || gyroscope || wheels; }
};

/// Reads the files `needs` names, and no other: nothing when it needs
/// nothing.  A file it needs that is missing, of the wrong kind (imu0 a
/// file, data.csv a folder) or holds no readings is an IoError naming it
/// and `needs.who`; a bad line, as above.
MotionReadings read_motion_readings(const std::string& dir, const MotionNeeds& needs);

/// The encoders' readings of wheels.csv ("t_ns,left,right", whole numbers
/// within int64, times increasing); IoError naming the file and line.
std::vector<sensor::WheelTicks> read_wheel_ticks(const std::string& path, std::vector<int>* lines = nullptr);

/// The frame's IMU readings as a recording holds them: each value rounded
/// to the nine significant digits the files keep, so that SLAM on a live
/// run sees what SLAM on its recording reads back.
void round_as_written(sensor::RgbdFrame* frame);

/// The readings with time in (t0_ns, t1_ns] appended to `frame` (binary search).
void attach_readings(const MotionReadings& m, std::int64_t t0_ns, std::int64_t t1_ns, sensor::RgbdFrame* frame);

}  // namespace pvb::dataset
