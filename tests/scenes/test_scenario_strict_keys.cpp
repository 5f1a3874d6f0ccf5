// Scenario keys that fooled the user: an accelerometer whose range gravity
// saturates, a camera model's keys under the other model, quoted numbers
// read as numbers, a relief the route drives off.  Each is one error line
// naming the file, the line and the key.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/scenario.hpp"

using namespace pvb::scenes;

namespace {

std::string strict_error(const std::string& yaml) {
  try {
    parse_scenario(yaml, "bad.yaml");
  } catch (const pvb::ConfigError& e) {
    return e.what();
  }
  return "";
}

const std::string kRoute = "route: {waypoints_m: [[0, 0], [5, 0]]}\n";

}  // namespace

TEST(ScenarioStrictKeys, AnAccelerometerRangeBelowTwoGIsRefused) {
  EXPECT_EQ(strict_error(kRoute + "imu: {accel: {range: 5}}\n"),
            "bad.yaml:2: imu.accel.range: expected a value in [19.6133, 2000], got 5");
  EXPECT_EQ(strict_error(kRoute + "imu: {accel: {range: 19.6133}}\n"), "");
  EXPECT_EQ(strict_error(kRoute + "imu: {gyro: {range: 0.5}}\n"), "");  // a gyroscope's may be small
}

TEST(ScenarioStrictKeys, DepthNoiseUnderAD435IsRefusedAsStereoUnderAKinect) {
  EXPECT_NE(
      strict_error(kRoute + "camera:\n  model: d435\n  depth_noise: {sunlight: off}\n")
          .find("bad.yaml:4: camera.depth_noise: expected no depth_noise: section unless model is kinect"),
      std::string::npos);
  EXPECT_NE(
      strict_error(kRoute + "camera:\n  stereo: {dots: 10}\n").find("camera.stereo: expected no stereo"),
      std::string::npos);
  EXPECT_EQ(strict_error(kRoute + "camera:\n  model: d435\n  stereo: {dots: 10}\n"), "");
}

// A day file may make its base's Kinect a d435 (or a d435 base a Kinect):
// the base's section of the other model is then unused, not refused.
TEST(ScenarioStrictKeys, ADayFileMayChangeTheModelOfItsBasesCamera) {
  const std::string dir = ::testing::TempDir() + "pvb_strict_keys_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  pvb::write_file(dir + "/kinect.yaml", kRoute + "camera:\n  depth_noise: {sunlight: off}\n");
  pvb::write_file(dir + "/d435_day.yaml", "base: kinect.yaml\ncamera: {model: d435}\n");
  EXPECT_EQ(load_scenario(dir + "/d435_day.yaml").camera.model, CameraKind::kD435);
  pvb::write_file(dir + "/d435.yaml", kRoute + "camera:\n  model: d435\n  stereo: {dots: 10}\n");
  pvb::write_file(dir + "/kinect_day.yaml", "base: d435.yaml\ncamera: {model: kinect}\n");
  EXPECT_EQ(load_scenario(dir + "/kinect_day.yaml").camera.model, CameraKind::kKinect);
  // Written with the model in one file, as above: refused.
  pvb::write_file(dir + "/both_day.yaml", "base: kinect.yaml\ncamera: {model: d435, depth_noise: {sunlight: on}}\n");
  EXPECT_THROW(load_scenario(dir + "/both_day.yaml"), pvb::ConfigError);
}

TEST(ScenarioStrictKeys, AQuotedNumberIsAString) {
  EXPECT_EQ(strict_error(kRoute + "camera: {fps: \"2\"}\n"),
            "bad.yaml:2: camera.fps: expected a number, got the string \"2\"");
  EXPECT_EQ(strict_error(kRoute + "wheels: {ticks_per_rev: '512'}\n"),
            "bad.yaml:2: wheels.ticks_per_rev: expected an integer, got the string \"512\"");
  EXPECT_EQ(strict_error(kRoute + "camera: {rgb: {auto_exposure: \"true\"}}\n"),
            "bad.yaml:2: camera.rgb.auto_exposure: expected true or false, got the string \"true\"");
  EXPECT_EQ(strict_error(kRoute + "camera: {fps: 2}\n"), "");
}

// A 12 m route on a 10 m relief: the robot fell off the edge (camera z
// 0.81 -> -1.47 m) and the recording was kept.
TEST(ScenarioStrictKeys, AReliefTheRouteLeavesIsRefused) {
  const std::string relief = "ground:\n  size_m: [10, 10]\n  relief: {amplitude_cm: 1, slope_percent: 0}\n";
  const std::string e = strict_error("route: {waypoints_m: [[-6, 0], [6, 0]]}\n" + relief);
  EXPECT_NE(e.find("bad.yaml:3: ground.size_m: expected a relief that holds the route with 1.0 m to spare"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("at least [14.0, 2.0]"), std::string::npos) << e;
  EXPECT_NE(e.find("the route reaches (x, y) = (-6.00, 0.00) m"), std::string::npos) << e;
  EXPECT_EQ(strict_error("route: {waypoints_m: [[-3, 0], [3, 0]]}\n" + relief), "");
}
