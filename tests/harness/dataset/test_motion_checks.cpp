// A folder's motion streams, read for a sensor setup and checked against
// the frames and the settings (motion_checks.hpp): each way a stream can
// fool a run is one error naming the file and line (or the settings' key).
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/motion_checks.hpp"
#include "pvb/dataset/motion_files.hpp"
#include "pvb/dataset/tum_imu.hpp"

using namespace pvb;

namespace {

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_motion_checks_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + d + " && mkdir -p " + d + "/imu0").c_str());
  return d;
}

/// The error `f` throws (IoError or ConfigError), or "" when none.
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

const char* kEurocHeader = "#timestamp [ns],w_RS_S_x,w_RS_S_y,w_RS_S_z,a_RS_S_x,a_RS_S_y,a_RS_S_z\n";

/// imu0/data.csv at 200 Hz over [t0_s, t1_s], the IMU at rest (g on -y:
/// a level camera's axes), with `edit` applied to each line's text.
std::string euroc_csv(double t0_s, double t1_s,
                      const std::function<std::string(int, std::int64_t)>& line = {}) {
  std::string text = kEurocHeader;
  for (int k = 0; t0_s + k * 0.005 <= t1_s + 1e-9; ++k) {
    const auto t_ns = static_cast<std::int64_t>(std::llround((t0_s + k * 0.005) * 1e9));
    text += line ? line(k, t_ns) : std::to_string(t_ns) + ",0.001,0,0,0.02,-9.81,0.03\n";
  }
  return text;
}

dataset::MotionNeeds needs(bool accel, bool gyro, bool wheels) {
  return {accel, gyro, wheels, "--sensors test"};
}

/// The readings of `dir` for `n`, checked against frames over [0, 2] s.
void read_and_check(const std::string& dir, const dataset::MotionNeeds& n, std::optional<double> imu_hz = 200,
                    double first_s = 0, double last_s = 2) {
  const dataset::MotionReadings m = dataset::read_motion_readings(dir, n);
  dataset::MotionExpectations e;
  e.first_frame_t_ns = static_cast<std::int64_t>(first_s * 1e9);
  e.last_frame_t_ns = static_cast<std::int64_t>(last_s * 1e9);
  e.settings_file = "camera.yaml";
  e.imu_rate_hz = imu_hz;
  e.encoder_rate_hz = 50;
  e.ticks_per_rev = 1024;
  e.wheel_radius_m = 0.1;
  dataset::check_motion_readings(m, e);
}

void expect_error(const std::string& what, const std::string& file_line, const std::string& words) {
  EXPECT_NE(what.find(file_line), std::string::npos) << what;
  EXPECT_NE(what.find(words), std::string::npos) << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;  // one line
}

}  // namespace

TEST(MotionChecks, AGoodStreamPasses) {
  const std::string d = fresh("good");
  write_file(d + "/imu0/data.csv", euroc_csv(0, 2));
  EXPECT_EQ(error_of([&] { read_and_check(d, needs(true, true, false)); }), "");
}

// What a setup needs must be there: imu0 as a folder with readings, wheels.csv.
TEST(MotionChecks, MissingEmptyOrMisplacedFilesAreNamed) {
  std::string d = fresh("header_only");
  write_file(d + "/imu0/data.csv", kEurocHeader);
  expect_error(error_of([&] { read_and_check(d, needs(true, true, false)); }), "imu0/data.csv",
               "no readings");
  write_file(d + "/imu0/data.csv", "");
  expect_error(error_of([&] { read_and_check(d, needs(true, false, false)); }), "imu0/data.csv",
               "no readings");

  d = fresh("imu0_file");
  std::system(("rmdir " + d + "/imu0").c_str());
  write_file(d + "/imu0", "not a folder\n");
  write_file(d + "/accelerometer.txt", "0.0 0 9.81 0\n");
  expect_error(error_of([&] { read_and_check(d, needs(true, false, false)); }), "/imu0", "is not a folder");

  d = fresh("nothing");
  expect_error(error_of([&] { read_and_check(d, needs(true, false, false)); }), d,
               "neither imu0/data.csv nor accelerometer.txt");
  expect_error(error_of([&] { read_and_check(d, needs(true, true, false)); }), "imu0/data.csv", "missing");
  write_file(d + "/accelerometer.txt", "0.0 0 9.81 0\n");  // an accelerometer has no gyroscope
  expect_error(error_of([&] { read_and_check(d, needs(true, true, false)); }), "imu0/data.csv",
               "use --sensors camera+accel");
  write_file(d + "/imu0/data.csv", euroc_csv(0, 2));
  expect_error(error_of([&] { read_and_check(d, needs(true, true, true)); }), "wheels.csv", "missing");
  // A setup that needs nothing reads nothing, whatever is there.
  write_file(d + "/imu0/data.csv", "garbage\n");
  EXPECT_TRUE(dataset::read_motion_readings(d, needs(false, false, false)).empty());
}

// Out of order, repeated, all-zero stamps: refused, as the wheels reader
// refuses them, never sorted.
TEST(MotionChecks, StampsMustIncreaseInEveryReader) {
  const std::string d = fresh("order");
  write_file(d + "/imu0/data.csv",
             std::string(kEurocHeader) + "5000000,0,0,0,0,-9.81,0\n4000000,0,0,0,0,-9.81,0\n");
  expect_error(error_of([&] { dataset::read_euroc_imu(d + "/imu0/data.csv"); }), "data.csv:3",
               "is not after line 2's");
  write_file(d + "/imu0/data.csv", std::string(kEurocHeader) + "0,0,0,0,0,-9.81,0\n0,0,0,0,0,-9.81,0\n");
  expect_error(error_of([&] { dataset::read_euroc_imu(d + "/imu0/data.csv"); }), "data.csv:3", "a repeated");
  write_file(d + "/accelerometer.txt", "# timestamp ax ay az\n1.002 0 9.8 0\n1.001 0 9.8 0\n");
  expect_error(error_of([&] { dataset::read_tum_accelerometer(d + "/accelerometer.txt"); }),
               "accelerometer.txt:3", "is not after line 2's");
  write_file(d + "/wheels.csv", "#t,l,r\n20000000,1,2\n20000000,3,4\n");
  expect_error(error_of([&] { dataset::read_wheel_ticks(d + "/wheels.csv"); }), "wheels.csv:3",
               "is not after");
}

// A stamp beyond int64, a reading of 1e30, ticks that are not whole.
TEST(MotionChecks, ValuesNoSensorGivesAreRefusedWithTheirLine) {
  const std::string d = fresh("values");
  write_file(d + "/imu0/data.csv", std::string(kEurocHeader) + "99999999999999999999,0,0,0,0,-9.81,0\n");
  expect_error(error_of([&] { dataset::read_euroc_imu(d + "/imu0/data.csv"); }), "data.csv:2",
               "within int64");
  write_file(d + "/imu0/data.csv",
             std::string(kEurocHeader) + "0,0,0,0,0,-9.81,0\n5000000,0,0,0,1e30,-9.81,0\n");
  expect_error(error_of([&] { dataset::read_euroc_imu(d + "/imu0/data.csv"); }), "data.csv:3",
               "acceleration x");
  write_file(d + "/imu0/data.csv", std::string(kEurocHeader) + "0,0,400,0,0,-9.81,0\n");
  expect_error(error_of([&] { dataset::read_euroc_imu(d + "/imu0/data.csv"); }), "data.csv:2",
               "angular rate y");
  write_file(d + "/accelerometer.txt", "0.5 0 1e30 0\n");
  expect_error(error_of([&] { dataset::read_tum_accelerometer(d + "/accelerometer.txt"); }),
               "accelerometer.txt:1", "acceleration y");
  write_file(d + "/wheels.csv", "#t,l,r\n20000000,1.5,2\n");
  expect_error(error_of([&] { dataset::read_wheel_ticks(d + "/wheels.csv"); }), "wheels.csv:2",
               "whole numbers");
  write_file(d + "/wheels.csv", "#t,l,r\n20000000,1,99999999999999999999\n");
  expect_error(error_of([&] { dataset::read_wheel_ticks(d + "/wheels.csv"); }), "wheels.csv:2",
               "within int64");
}

// The stream covers the frames: no 3 s gap, no end 2 s early, no start 3 s late.
TEST(MotionChecks, GapsAndStreamsThatMissFramesAreNamed) {
  const std::string d = fresh("cover");
  write_file(d + "/imu0/data.csv", euroc_csv(0, 2, [](int k, std::int64_t t_ns) {
               const std::int64_t shifted = t_ns >= 500'000'000 ? t_ns + 3'000'000'000LL : t_ns;
               return std::to_string(shifted) + ",0,0,0,0,-9.81,0\n";
             }));
  // line 2 is t = 0; the reading at 0.5 s (line 102) comes 3.005 s after the one before
  expect_error(error_of([&] { read_and_check(d, needs(true, true, false), std::nullopt, 0, 5); }),
               "data.csv:102", "no reading for 3.005 s");
  write_file(d + "/imu0/data.csv", euroc_csv(0, 1));
  expect_error(error_of([&] { read_and_check(d, needs(true, true, false)); }), "data.csv:202",
               "the readings end 1.000 s before the last frame");
  write_file(d + "/imu0/data.csv", euroc_csv(3, 5));
  expect_error(error_of([&] { read_and_check(d, needs(true, true, false), 200, 0, 5); }), "data.csv:2",
               "the readings start 3.000 s after the first frame");
}

// Stamps in microseconds, and a rate the settings do not give.
TEST(MotionChecks, TheRateMustBeTheSettingsAndASensorsOwn) {
  const std::string d = fresh("rate");
  write_file(d + "/imu0/data.csv", euroc_csv(0, 2, [](int k, std::int64_t t_ns) {
               return std::to_string(t_ns / 1000) + ",0,0,0,0,-9.81,0\n";  // microseconds
             }));
  expect_error(error_of([&] { read_and_check(d, needs(true, true, false)); }), "data.csv:402",
               "are the time stamps in the file's unit (nanoseconds)?");
  write_file(d + "/imu0/data.csv", euroc_csv(0, 2));
  expect_error(error_of([&] { read_and_check(d, needs(true, true, false), 10000); }),
               "camera.yaml: IMU.Frequency", "the rate of the readings, 200 Hz");
  expect_error(error_of([&] { read_and_check(d, needs(true, true, false), 10000); }), "", "got 10000");
}

// An accelerometer that reads 0 (or g in another unit) is no accelerometer.
TEST(MotionChecks, AnAllZeroAccelerometerIsRefused) {
  const std::string d = fresh("zero");
  write_file(d + "/imu0/data.csv", euroc_csv(0, 2, [](int k, std::int64_t t_ns) {
               return std::to_string(t_ns) + ",0.01,0,0,0,0,0\n";
             }));
  expect_error(error_of([&] { read_and_check(d, needs(true, true, false)); }), "imu0/data.csv",
               "median reading is 0 m/s^2");
}

// A count that jumps 2^40 ticks between readings 20 ms apart.
TEST(MotionChecks, AWheelCountThatJumpsIsRefused) {
  const std::string d = fresh("jump");
  write_file(d + "/imu0/data.csv", euroc_csv(0, 2));
  std::string wheels = "#t,l,r\n";
  for (int k = 0; k <= 100; ++k)
    wheels += std::to_string(k * 20'000'000LL) + "," + std::to_string(k == 60 ? (1LL << 40) + 60 : k) + "," +
              std::to_string(k) + "\n";
  write_file(d + "/wheels.csv", wheels);
  expect_error(error_of([&] { read_and_check(d, needs(true, true, true)); }), "wheels.csv:62",
               "changes by 1.09951e+12 ticks");
}

// accelerometer.txt holds TUM's frame, the Kinect accelerometer's: a level
// camera's IMU, written by the recorder, reads back up in the camera frame
// (it read back upside down when written in the IMU's axes).
TEST(MotionChecks, AccelerometerTxtIsWrittenAndReadInTumsFrame) {
  const std::string d = fresh("frame");
  dataset::RobotCalibration c;
  c.T_b_c = geom::make_se3(Eigen::Matrix3d(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX())),
                           Eigen::Vector3d(0.15, 0, 0.8));
  c.T_b_i = c.T_b_c * geom::make_se3(Eigen::Matrix3d(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())),
                                     Eigen::Vector3d(0.01, 0, 0));
  const Eigen::Vector3d up_c(0, -9.81, 0);  // a level camera: y points down
  const Eigen::Matrix3d R_c_i = (c.T_b_c.inverse() * c.T_b_i).linear();
  {
    dataset::MotionFilesWriter w(d + "/rec", c);
    w.write({{5'000'000, Eigen::Vector3d::Zero(), R_c_i.transpose() * up_c}}, {});
  }
  const std::vector<sensor::ImuSample> s = dataset::read_tum_accelerometer(d + "/rec/accelerometer.txt");
  ASSERT_EQ(s.size(), 1u);
  EXPECT_LT((s[0].accel_mps2 - up_c).norm(), 1e-6) << s[0].accel_mps2.transpose();
  // A TUM download at rest with the camera level reads +g on the Kinect's y.
  write_file(d + "/accelerometer.txt", "1.0 0.0 9.81 0.0\n");
  EXPECT_LT((dataset::read_tum_accelerometer(d + "/accelerometer.txt")[0].accel_mps2 - up_c).norm(), 1e-12);
}
