// The physics:, imu:, wheels: sections and the robot's calibration keys:
// rates that fit the physics, the parts' figures, and one error line for
// each kind of bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/scenes/scenario.hpp"

using namespace pvb::scenes;

namespace {

std::string body_error_of(const std::string& yaml) {
  try {
    parse_scenario("route: {waypoints_m: [[0, 0], [5, 0]]}\n" + yaml, "body.yaml");
  } catch (const pvb::ConfigError& e) {
    return e.what();
  }
  return "";
}

Scenario parse_body(const std::string& yaml) {
  return parse_scenario("route: {waypoints_m: [[0, 0], [5, 0]]}\n" + yaml, "body.yaml");
}

}  // namespace

TEST(ScenarioBody, DefaultsFollowThePhysicsRate) {
  const Scenario legacy = parse_body("");
  EXPECT_EQ(physics_substeps(legacy), 17);  // 510 Hz at 30 fps, as every file without physics: had
  EXPECT_DOUBLE_EQ(imu_rate_hz(legacy), 170.0);
  EXPECT_DOUBLE_EQ(wheel_rate_hz(legacy), 51.0);
  const Scenario s = parse_body("physics: {rate_hz: 600}\n");
  EXPECT_EQ(physics_substeps(s), 20);
  EXPECT_DOUBLE_EQ(imu_rate_hz(s), 200.0);
  EXPECT_DOUBLE_EQ(wheel_rate_hz(s), 50.0);
  EXPECT_DOUBLE_EQ(imu_rate_hz(parse_body("physics: {rate_hz: 3000}\nimu: {rate_hz: 1000}\n")), 1000.0);
  EXPECT_DOUBLE_EQ(nearest_divisor_rate(510, 200), 170.0);
  EXPECT_DOUBLE_EQ(nearest_divisor_rate(510, 250), 255.0);
  EXPECT_TRUE(divides(200, 600));
  EXPECT_FALSE(divides(200, 510));
}

TEST(ScenarioBody, PartsGiveTheirDatasheetFiguresAndKeysOverrideThem) {
  const Scenario a = parse_body("imu: {part: bmi055, accel: {noise_density: 0.002}}\n");
  EXPECT_EQ(a.imu.part, ImuPart::kBmi055);
  EXPECT_DOUBLE_EQ(a.imu.accel.noise_density, 0.002);
  EXPECT_DOUBLE_EQ(a.imu.accel.turn_on_bias, 0.070 * 9.80665);
  EXPECT_EQ(a.imu.accel.bits, 12);
  EXPECT_NEAR(a.imu.gyro.noise_density, 0.014 * M_PI / 180, 1e-12);
  const Scenario b = parse_body("");
  EXPECT_NEAR(b.imu.accel.noise_density, 160e-6 * 9.80665, 1e-12);
}

TEST(ScenarioBody, BadInputIsOneLineNamingFileLineAndKey) {
  std::string e = body_error_of("imu: {rate_hz: 200}\n");
  EXPECT_NE(e.find("body.yaml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("imu.rate_hz"), std::string::npos) << e;
  EXPECT_NE(e.find("divides the physics rate of 510 Hz"), std::string::npos) << e;
  e = body_error_of("imu:\n  gyro: {noise_density: -0.1}\n");
  EXPECT_NE(e.find("body.yaml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("imu.gyro.noise_density"), std::string::npos) << e;
  e = body_error_of("imu: {accel: {random_walk: 5}}\n");
  EXPECT_NE(e.find("imu.accel.random_walk"), std::string::npos) << e;
  EXPECT_NE(e.find("[0, 1]"), std::string::npos) << e;
  e = body_error_of("imu: {p_c_i_m: [0.5, 0, 0]}\n");
  EXPECT_NE(e.find("imu.p_c_i_m"), std::string::npos) << e;
  EXPECT_NE(e.find("a place on the robot"), std::string::npos) << e;
  e = body_error_of("wheels: {ticks_per_rev: 0}\n");
  EXPECT_NE(e.find("wheels.ticks_per_rev"), std::string::npos) << e;
  e = body_error_of("physics: {rate_hz: 500}\n");
  EXPECT_NE(e.find("physics.rate_hz"), std::string::npos) << e;
  EXPECT_NE(e.find("multiple of the camera's 30 frames/s"), std::string::npos) << e;
  e = body_error_of("wheels: {rate_hz: 50}\n");
  EXPECT_NE(e.find("wheels.rate_hz"), std::string::npos) << e;
  e = body_error_of("robot: {radius_error: 0.5}\n");
  EXPECT_NE(e.find("robot.radius_error"), std::string::npos) << e;
  e = body_error_of("robot: {radius_difference: 0.1}\n");
  EXPECT_NE(e.find("robot.radius_difference"), std::string::npos) << e;
  EXPECT_NE(e.find("[-0.05, 0.05]"), std::string::npos) << e;
  e = body_error_of("imu: {part: mpu6050}\n");
  EXPECT_NE(e.find("bmi088"), std::string::npos) << e;
  EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 0) << e;
}
