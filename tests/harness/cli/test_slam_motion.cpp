// pvbench slam with the motion sensors on small hand-made folders: the
// streams a setup fuses are checked before any work (one error line each),
// accelerometer.txt is read in TUM's frame whoever wrote it (a pvbench
// recording and a TUM download both begin the map the right way up), and
// the command line refuses what it used to ignore.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

#include "pvb/common/text.hpp"
#include "pvb/dataset/motion_files.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/time.hpp"
#include "run_pvbench.hpp"

using namespace pvb;

namespace {

constexpr int kFrames = 8, kWidth = 320, kHeight = 240;
constexpr double kFocalPx = 300, kDepthM = 2.0, kShiftPx = 2.0;

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_slam_motion_" + name + "_" + std::to_string(::getpid());
  std::filesystem::remove_all(d);
  return d;
}

/// The robot: a level camera 0.8 m up looking along the base's x; the IMU
/// beside it, its axes turned 30 degrees about the camera's y.
dataset::RobotCalibration robot() {
  dataset::RobotCalibration c;
  geom::Mat3d R_b_c;
  R_b_c << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // optical z forward, x right, y down
  c.T_b_c = geom::make_se3(R_b_c, geom::Vec3d(0.15, 0, 0.8));
  c.T_b_i = c.T_b_c * geom::make_se3(Eigen::Matrix3d(Eigen::AngleAxisd(0.5236, Eigen::Vector3d::UnitY())),
                                     geom::Vec3d(0.01, 0.005, -0.012));
  // a BMI088 at 200 Hz
  c.imu.gyro_noise_density = 2.44e-4;
  c.imu.gyro_random_walk = 2e-5;
  c.imu.accel_noise_density = 1.57e-3;
  c.imu.accel_random_walk = 4e-4;
  c.imu_rate_hz = 200;
  return c;
}

/// A textured plane sliding past the level camera at 30 fps, camera.yaml
/// (with the robot's IMU.* and Robot.* keys when `with_robot`).
std::string make_frames(const std::string& name, bool with_robot) {
  const std::string dir = fresh(name);
  cv::Mat texture(kHeight + 20, kWidth + 2 * kFrames * static_cast<int>(kShiftPx), CV_8UC3);
  cv::RNG(5).fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.5);
  dataset::TumSequenceWriter writer(dir);
  for (int i = 0; i < kFrames; ++i) {
    sensor::RgbdFrame f;
    f.t_ns = geom::frame_time_ns(0, i, 30.0);
    f.index = static_cast<std::size_t>(i);
    texture(cv::Rect(static_cast<int>(i * kShiftPx), 10, kWidth, kHeight)).copyTo(f.rgb);
    f.depth_m = cv::Mat(kHeight, kWidth, CV_32FC1, cv::Scalar(kDepthM));
    writer.write(
        f, geom::make_se3(geom::Mat3d::Identity(), geom::Vec3d(i * kShiftPx * kDepthM / kFocalPx, 0, 0)));
  }
  dataset::OrbSlamSettings s;
  s.K = {kFocalPx, kFocalPx, 159.5, 119.5, kWidth, kHeight};
  s.bf = 0.075 * kFocalPx;
  if (with_robot) s.robot = robot();
  dataset::write_orbslam_settings(dir + "/camera.yaml", s);
  return dir;
}

/// The robot standing still, its motion files as pvbench records them:
/// 200 Hz from 0.2 s before the first frame to 0.1 s after the last.
void write_motion(const std::string& dir) {
  const dataset::RobotCalibration c = robot();
  dataset::MotionFilesWriter w(dir, c);
  const Eigen::Vector3d f_i = c.T_b_i.linear().transpose() * Eigen::Vector3d(0, 0, 9.80665);
  std::vector<sensor::ImuSample> imu;
  std::vector<sensor::WheelTicks> ticks;
  for (std::int64_t t_ns = -200'000'000; t_ns <= 400'000'000; t_ns += 5'000'000) {
    imu.push_back({t_ns, Eigen::Vector3d::Zero(), f_i});
    if (t_ns % 20'000'000 == 0) ticks.push_back({t_ns, 0, 0});
  }
  w.write(imu, ticks);
}

test::RunResult slam(const std::string& seq, const std::string& out, const std::string& extra) {
  return test::run_pvbench("slam --sequence " + seq + " --settings " + seq + "/camera.yaml --out " + out +
                           " --sync --no-dense " + extra);
}

/// The first pose of CameraTrajectory.txt: its camera's y axis (image down) in the map.
Eigen::Vector3d first_camera_down_in_map(const std::string& out) {
  std::istringstream in(read_file(out + "/CameraTrajectory.txt"));
  std::string line;
  while (std::getline(in, line) && (line.empty() || line[0] == '#')) {
  }
  std::istringstream f(line);
  double t, x, y, z, qx, qy, qz, qw;
  f >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
  return Eigen::Quaterniond(qw, qx, qy, qz).toRotationMatrix().col(1);
}

void expect_one_error(const test::RunResult& r, const std::string& words) {
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output.rfind("pvbench: error: ", 0), 0u) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << r.output;  // one line
  EXPECT_NE(r.output.find(words), std::string::npos) << r.output;
}

}  // namespace

// A pvbench recording without imu0 reads its own accelerometer.txt: the
// first camera's image-down must point down the map (it pointed up, +0.989).
TEST(SlamMotion, APvbenchRecordingBeginsTheMapTheRightWayUp) {
  const std::string seq = make_frames("pvbench", true);
  write_motion(seq);
  std::filesystem::remove_all(seq + "/imu0");
  const std::string out = fresh("pvbench_out");
  const test::RunResult r = slam(seq, out, "--sensors camera+accel");
  ASSERT_EQ(r.code, 0) << r.output;
  const Eigen::Vector3d down = first_camera_down_in_map(out);
  EXPECT_LT(down.z(), -0.999) << down.transpose() << "\n" << r.output;
}

// A TUM download: the Kinect at rest, level, reads +g on its y.
TEST(SlamMotion, ATumRecordingBeginsTheMapTheRightWayUp) {
  const std::string seq = make_frames("tum", false);
  std::string text = "# accelerometer data\n# timestamp ax ay az\n";
  for (std::int64_t t_ns = -200'000'000; t_ns <= 400'000'000; t_ns += 2'000'000)
    text += geom::format_tum_time(t_ns) + " 0.0 9.80665 0.0\n";
  write_file(seq + "/accelerometer.txt", text);
  const std::string out = fresh("tum_out");
  const test::RunResult r = slam(seq, out, "--sensors camera+accel");
  ASSERT_EQ(r.code, 0) << r.output;
  const Eigen::Vector3d down = first_camera_down_in_map(out);
  EXPECT_LT(down.z(), -0.999) << down.transpose() << "\n" << r.output;
}

// The streams a setup fuses are checked before anything is written.
TEST(SlamMotion, BadStreamsAreOneErrorLineBeforeAnyWork) {
  const std::string seq = make_frames("streams", true);
  write_motion(seq);
  const std::string out = fresh("streams_out");
  ASSERT_EQ(slam(seq, out, "--sensors camera+imu+wheels").code, 0);
  // IMU.Frequency against the data's 200 Hz
  const std::string yaml = read_file(seq + "/camera.yaml");
  write_file(seq + "/fast.yaml", yaml.substr(0, yaml.find("IMU.Frequency")) + "IMU.Frequency: 10000.0\n" +
                                     yaml.substr(yaml.find('\n', yaml.find("IMU.Frequency")) + 1));
  const std::string fast_out = fresh("fast_out");
  const test::RunResult fast = test::run_pvbench("slam --sequence " + seq + " --settings " + seq +
                                                 "/fast.yaml --out " + fast_out + " --sensors camera+imu");
  expect_one_error(fast, "IMU.Frequency: expected the rate of the readings, 200 Hz");
  EXPECT_FALSE(std::filesystem::exists(fast_out));  // refused before the output folder is made
  // wheels.csv missing; then no motion files at all
  std::filesystem::remove(seq + "/wheels.csv");
  expect_one_error(slam(seq, fresh("wheels_out"), "--sensors camera+imu+wheels"), "wheels.csv: missing");
  std::filesystem::remove_all(seq + "/imu0");
  std::filesystem::remove(seq + "/accelerometer.txt");
  expect_one_error(slam(seq, fresh("none_out"), "--sensors camera+accel"), "holds no accelerometer readings");
  // camera alone reads none of them
  EXPECT_EQ(slam(seq, fresh("camera_out"), "--sensors camera").code, 0);
}

// --sensors '' was camera; --allow-other-station without --map was ignored.
TEST(SlamMotion, OptionsThatSaidNothingAreRefused) {
  const std::string seq = make_frames("options", false);
  expect_one_error(slam(seq, fresh("empty_out"), "--sensors ''"), "command line: --sensors: expected camera");
  const test::RunResult run =
      test::run_pvbench("run --scenario " + std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml --out " +
                        fresh("run_out") + " --allow-other-station");
  expect_one_error(run, "command line: --allow-other-station: expected a --map");
}
