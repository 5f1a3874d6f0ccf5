// The motion sensors' files: the settings keys as ORB-SLAM3 reads them
// (OpenCV FileStorage, reals where it wants reals), and the readings,
// counts and odometry as written.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <unistd.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/motion_files.hpp"
#include "pvb/dataset/tum_sequence.hpp"

using namespace pvb;

namespace {

dataset::RobotCalibration calibration() {
  dataset::RobotCalibration c;
  c.imu.gyro_noise_density = 2.44e-4;
  c.imu.gyro_random_walk = 2e-5;
  c.imu.accel_noise_density = 1.57e-3;
  c.imu.accel_random_walk = 4e-4;
  c.imu_rate_hz = 200;
  c.drive = {0.1, 0.42, 1024};
  c.encoder_rate_hz = 50;
  c.T_b_c = geom::make_se3(Eigen::Matrix3d(Eigen::AngleAxisd(-1.2, Eigen::Vector3d::UnitX())),
                           Eigen::Vector3d(0.15, 0, 0.7));
  c.T_b_i = c.T_b_c * geom::make_se3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.01, 0.005, -0.012));
  return c;
}

std::vector<std::string> lines_of(const std::string& path) {
  std::vector<std::string> out;
  std::istringstream in(read_file(path));
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

}  // namespace

// ORB-SLAM3 reads IMU.* with FileNode::real() after checking isReal(), and
// IMU.T_b_c1 as a 4 x 4 float matrix; ORB-SLAM2's keys are still there.
TEST(MotionFiles, SettingsCarryOrbSlam3ImuKeysAsItReadsThem) {
  dataset::OrbSlamSettings s;
  s.K = {525, 525, 319.5, 239.5, 640, 480};
  s.robot = calibration();
  const cv::FileStorage fs(dataset::orbslam_settings_text(s), cv::FileStorage::READ | cv::FileStorage::MEMORY);
  ASSERT_TRUE(fs.isOpened());
  for (const char* key : {"IMU.NoiseGyro", "IMU.NoiseAcc", "IMU.GyroWalk", "IMU.AccWalk", "IMU.Frequency",
                          "Robot.WheelRadius", "Robot.Track", "Robot.EncoderFrequency", "Camera.fx"})
    EXPECT_TRUE(fs[key].isReal()) << key;
  EXPECT_DOUBLE_EQ(fs["IMU.Frequency"].real(), 200.0);
  EXPECT_DOUBLE_EQ(fs["IMU.GyroWalk"].real(), 2e-5);
  EXPECT_TRUE(fs["Robot.TicksPerRev"].isInt());
  cv::Mat T;
  fs["IMU.T_b_c1"] >> T;
  ASSERT_EQ(T.rows, 4);
  ASSERT_EQ(T.cols, 4);
  EXPECT_EQ(T.type(), CV_32F);
  // the camera in the IMU frame: the IMU is 1-2 cm from the camera, axes parallel
  EXPECT_NEAR(T.at<float>(0, 3), -0.01, 1e-6);
  EXPECT_NEAR(T.at<float>(2, 3), 0.012, 1e-6);
  EXPECT_NEAR(T.at<float>(1, 1), 1.0, 1e-6);
  EXPECT_EQ(fs["DepthMapFactor"].real(), s.depth_map_factor);
}

// The readings go out line by line; odometry integrates the counts.
TEST(MotionFiles, ReadingsAndOdometryAreWrittenPerFrame) {
  const std::string dir = ::testing::TempDir() + "motion_files_" + std::to_string(::getpid());
  dataset::MotionFilesWriter w(dir, calibration());
  // 1 s straight at one revolution a second, then 1 s with the right wheel
  // a revolution ahead: a turn of 2 pi r / track
  sensor::RgbdFrame f;
  for (int k = 0; k <= 100; ++k) {
    const std::int64_t t_ns = k * 20'000'000LL;
    const std::int64_t base = std::min(k, 50) * 1024 / 50 + std::max(0, k - 50) * 1024 / 50;
    const std::int64_t extra = std::max(0, k - 50) * 1024 / 50;
    f.wheel_ticks.push_back({t_ns, base, base + extra});
    f.imu.push_back({t_ns, Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0, 0, 9.81)});
    if (k % 10 == 0) {
      w.write(f);
      f.imu.clear();
      f.wheel_ticks.clear();
    }
  }
  const auto imu = lines_of(dir + "/imu0/data.csv");
  ASSERT_EQ(imu.size(), 102u);
  EXPECT_EQ(imu[0].rfind("#timestamp [ns],w_RS_S_x", 0), 0u);
  EXPECT_EQ(imu[1], "0,0.1,0.2,0.3,0,0,9.81");
  EXPECT_EQ(lines_of(dir + "/accelerometer.txt").size(), 104u);
  EXPECT_EQ(lines_of(dir + "/wheels.csv").back(), "2000000000,2048,3072");
  const auto odom = lines_of(dir + "/odom.txt");
  std::istringstream last(odom.back());
  double t, x, y, z, qx, qy, qz, qw;
  last >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
  const double yaw = 2 * std::atan2(qz, qw);
  EXPECT_NEAR(yaw, 2 * M_PI * 0.1 / 0.42, 1e-3);
  EXPECT_NEAR(t, 2.0, 1e-9);
  EXPECT_GT(x, 2 * M_PI * 0.1);  // the straight metre and part of the arc
  EXPECT_NE(read_file(dir + "/imu.yaml").find("gyroscope_random_walk: 2.0e-05"), std::string::npos);
  EXPECT_NE(read_file(dir + "/robot.yaml").find("ticks_per_rev: 1024"), std::string::npos);
}

// What a recording wrote reads back reading for reading, split between
// frames by time; a damaged line names its file and line.
TEST(MotionFiles, ReadingsReadBackAndGoWithTheirFrames) {
  const std::string dir = ::testing::TempDir() + "motion_read_" + std::to_string(::getpid());
  {
    dataset::MotionFilesWriter w(dir, calibration());
    std::vector<sensor::ImuSample> imu;
    std::vector<sensor::WheelTicks> ticks;
    for (int k = 1; k <= 40; ++k) {
      imu.push_back({k * 5'000'000LL, Eigen::Vector3d(0.01 * k, -0.02, 1e-7), Eigen::Vector3d(0.1, -9.8, 0.25 * k)});
      if (k % 4 == 0) ticks.push_back({k * 5'000'000LL, 3 * k, -k});
    }
    w.write(imu, ticks);
  }
  const dataset::MotionReadings m = dataset::read_motion_readings(dir);
  ASSERT_EQ(m.imu.size(), 40u);
  ASSERT_EQ(m.ticks.size(), 10u);
  EXPECT_EQ(m.imu[6].t_ns, 35'000'000);
  EXPECT_DOUBLE_EQ(m.imu[6].gyro_radps.x(), 0.07);
  EXPECT_DOUBLE_EQ(m.imu[6].gyro_radps.z(), 1e-7);
  EXPECT_DOUBLE_EQ(m.imu[6].accel_mps2.z(), 1.75);
  EXPECT_EQ(m.ticks[9].left, 120);
  EXPECT_EQ(m.ticks[9].right, -40);
  // A frame at 100 ms after one at 50 ms takes the readings in (50, 100] ms.
  sensor::RgbdFrame f;
  dataset::attach_readings(m, 50'000'000, 100'000'000, &f);
  ASSERT_EQ(f.imu.size(), 10u);
  EXPECT_EQ(f.imu.front().t_ns, 55'000'000);
  EXPECT_EQ(f.imu.back().t_ns, 100'000'000);
  EXPECT_EQ(f.wheel_ticks.size(), 3u);  // at 60, 80 and 100 ms

  write_file(dir + "/wheels.csv", "#timestamp [ns],left [ticks],right [ticks]\n20000000,1,2\n40000000,x,3\n");
  try {
    dataset::read_motion_readings(dir);
    FAIL() << "expected an IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("wheels.csv"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(":3"), std::string::npos) << e.what();
  }
}
