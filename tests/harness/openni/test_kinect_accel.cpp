// The Kinect v1's accelerometer end to end without a Kinect: a fakenect
// dump of pv_station (its camera pitched 12 degrees down: a known tilt; its
// accelerometer without turn-on bias)
// played through fakenect, the freenect:// plug-in and `pvbench camera
// --sensors camera+accel`: the run records accelerometer.txt as TUM does
// (the Kinect's axes), which reads back as the true gravity, and the map
// begins level.  Motion setups the source cannot feed are refused.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli_output.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_imu.hpp"

namespace {

constexpr int kFrames = 45;
constexpr double kDegPerRad = 57.29577951308232;

using Result = pvb::test::RunResult;

Result run(const std::string& env, const std::string& args) {
  return pvb::test::run_pvbench_from_source(env + " timeout 300", args);
}

std::string fakenect_env(const std::string& dump) {
  return "LD_LIBRARY_PATH=" + std::string(PVB_FAKENECT_LIBRARY_DIR) + " FAKENECT_PATH=" + dump;
}

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_kinect_accel_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + d + " && mkdir -p " + d).c_str());
  return d;
}

/// TUM lines "t tx ty tz qx qy qz qw": the rotation R_w_c by time (us).
std::map<long long, Eigen::Matrix3d> rotations(const std::string& path) {
  std::map<long long, Eigen::Matrix3d> out;
  for (const std::string& line : pvb::test::data_lines(path)) {
    std::istringstream f(line);
    double t, x, y, z, qx, qy, qz, qw;
    f >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
    out[std::llround(t * 1e6)] = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
  }
  return out;
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kDegPerRad;
}

}  // namespace

TEST(KinectAccelerometer, ADumpsTiltIsRecordedAndTheMapBeginsLevel) {
  const std::string dir = fresh("tilt");
  const std::string dump = dir + "/dump";
  // pv_station with an accelerometer without turn-on bias: what is read
  // back is gravity and the robot's own acceleration, nothing of the part.
  pvb::write_file(dir + "/station.yaml",
                  pvb::read_file(std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml") +
                      "imu: {accel: {turn_on_bias: 0}}\n");
  const Result rec = run("", "record --scenario " + dir + "/station.yaml --format fakenect --frames " +
                                 std::to_string(kFrames) + " --out " + dump);
  ASSERT_EQ(rec.code, 0) << rec.output;
  const Result cam = run(fakenect_env(dump),
                         "camera --uri freenect://0 --sync --sensors camera+accel --out " + dir + "/run");
  ASSERT_EQ(cam.code, 0) << cam.output;
  EXPECT_NE(cam.output.find("Kinect v1 accelerometer's description"), std::string::npos) << cam.output;

  // One reading a frame, in the Kinect's axes: read as TUM's, each is the
  // true gravity in the camera (the mean of the frame's IMU readings, so the
  // start's jolt tilts a few of them; measured: median 0.08 degrees).
  const std::vector<pvb::sensor::ImuSample> accel =
      pvb::dataset::read_tum_accelerometer(dir + "/run/accelerometer.txt");
  ASSERT_EQ(accel.size(), static_cast<std::size_t>(kFrames));
  const std::map<long long, Eigen::Matrix3d> truth = rotations(dir + "/run/groundtruth.txt");
  std::vector<double> off_deg;
  for (const pvb::sensor::ImuSample& s : accel) {
    const auto it = truth.find(s.t_ns / 1000);
    ASSERT_NE(it, truth.end()) << s.t_ns;
    off_deg.push_back(angle_deg(s.accel_mps2, it->second.transpose() * Eigen::Vector3d::UnitZ()));
  }
  std::sort(off_deg.begin(), off_deg.end());
  EXPECT_LT(off_deg[off_deg.size() / 2], 0.5) << "median of " << off_deg.size();
  // The camera looks 12 degrees down: gravity is that far from the image's -y.
  EXPECT_NEAR(angle_deg(accel.front().accel_mps2, -Eigen::Vector3d::UnitY()), 12.0, 1.0);

  // The map's first camera, levelled by them: its down is the true down.
  const std::map<long long, Eigen::Matrix3d> est = rotations(dir + "/run/CameraTrajectory.txt");
  ASSERT_FALSE(est.empty());
  const auto first = truth.find(est.begin()->first);
  ASSERT_NE(first, truth.end());
  const Eigen::Vector3d est_down_c = est.begin()->second.transpose() * -Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d true_down_c = first->second.transpose() * -Eigen::Vector3d::UnitZ();
  EXPECT_LT(angle_deg(est_down_c, true_down_c), 1.5);
  std::system(("rm -rf " + dir).c_str());
}

// A Kinect has an accelerometer and nothing else; a recording nothing.
TEST(KinectAccelerometer, SetupsTheSourceCannotFeedAreRefused) {
  const std::string dir = fresh("refused");
  const std::string settings =
      " --settings " + std::string(PVB_SOURCE_DIR) + "/configs/kinect/kinect_v1.yaml";
  const Result imu = run(fakenect_env(dir + "/none"), "camera --uri freenect://0 --sensors camera+imu" +
                                                          settings + " --out " + dir + "/a");
  pvb::test::expect_one_error_line(imu, "--sensors: expected camera or camera+accel for a Kinect v1");
  pvb::write_file(dir + "/x.oni", "not read: the setup is refused first");
  const Result oni =
      run("", "camera --oni " + dir + "/x.oni --sensors camera+accel" + settings + " --out " + dir + "/b");
  pvb::test::expect_one_error_line(oni, "--sensors: expected camera for an .oni recording");
  std::system(("rm -rf " + dir).c_str());
}

// A dump holds a Kinect v1's frames: a D435 scenario or another frame rate
// is refused before the output folder is made.
TEST(KinectAccelerometer, ADumpOfAnotherCameraIsRefused) {
  const std::string dir = fresh("dump_camera");
  const std::string route = "route: {waypoints_m: [[0, 0], [5, 0]]}\n";
  pvb::write_file(dir + "/d435.yaml", route + "camera: {model: d435}\n");
  pvb::write_file(dir + "/fast.yaml", route + "camera: {fps: 60}\n");
  const Result d435 =
      run("", "record --scenario " + dir + "/d435.yaml --format fakenect --out " + dir + "/a");
  pvb::test::expect_one_error_line(d435, "camera.model: expected kinect for --format fakenect");
  const Result fast =
      run("", "record --scenario " + dir + "/fast.yaml --format fakenect --out " + dir + "/b");
  pvb::test::expect_one_error_line(fast, "camera.fps: expected 30 for --format fakenect");
  EXPECT_FALSE(std::filesystem::exists(dir + "/a"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/b"));
  std::system(("rm -rf " + dir).c_str());
}
