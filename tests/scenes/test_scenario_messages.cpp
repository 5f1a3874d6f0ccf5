// What a scenario's mistakes say: the lists of known keys, a null or empty
// section, the key a derived file wrote, sizes just over a limit, and
// ranges that would crash a library later.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/scenario.hpp"

using namespace pvb;
using namespace pvb::scenes;

namespace {

const char* kRouteOnly = "route: {waypoints_m: [[0, 0], [5, 0]]}\n";

std::string scenario_error(const std::string& yaml) {
  try {
    parse_scenario(yaml, "bad.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string fresh_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_scen_msg_" + name + "_" + std::to_string(::getpid());
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace

// A key read only when given (has()) is in the list an unknown key's error
// gives: a misspelt friction used to list every ground key but friction.
TEST(ScenarioMessages, KnownKeysListTheKeysReadOnlyWhenGiven) {
  const std::string ground = scenario_error(std::string(kRouteOnly) + "ground: {frction: 0.8}\n");
  EXPECT_NE(ground.find("ground.frction: expected a known key ("), std::string::npos) << ground;
  EXPECT_NE(ground.find("friction"), std::string::npos) << ground;
  const std::string robot = scenario_error(std::string(kRouteOnly) + "robot: {max_wheel_accel: 20}\n");
  EXPECT_NE(robot.find("robot.max_wheel_accel: expected a known key ("), std::string::npos) << robot;
  EXPECT_NE(robot.find("max_wheel_accel_radps2"), std::string::npos) << robot;
}

// An empty physics section, or a null rate, is the default rate (it used
// to read as "got 0").
TEST(ScenarioMessages, EmptyPhysicsOrANullRateIsTheDefault) {
  const Scenario plain = parse_scenario(kRouteOnly, "a.yaml");
  for (const char* physics : {"physics: {}\n", "physics: {rate_hz: null}\n", "physics: {rate_hz: ~}\n"}) {
    SCOPED_TRACE(physics);
    const Scenario s = parse_scenario(std::string(kRouteOnly) + physics, "a.yaml");
    EXPECT_FALSE(s.physics.rate_hz.has_value());
    EXPECT_EQ(physics_rate_hz(s), physics_rate_hz(plain));
  }
  EXPECT_NE(scenario_error(std::string(kRouteOnly) + "physics: {rate_hz: 0}\n")
                .find("physics.rate_hz: expected a value in [100, 10000], got 0"),
            std::string::npos);
}

// A relief under a varied soil is the relief under a repeated one, drawn
// tile by tile; a day file keeps its station's tiling.
TEST(ScenarioMessages, AReliefUnderAVariedSoilIsTheSameReliefTiled) {
  const std::string d = fresh_dir("tiling");
  const std::string station =
      "name: station\nseed: 7\npv_arrays:\n  - {rows: 2, tables_per_row: 2, panels_per_table: 4}\n"
      "route: {pattern: along_row, aisle: 1}\nground: {";
  write_file(d + "/repeat.yaml", station + "relief: {amplitude_cm: 1}}\n");
  write_file(d + "/varied.yaml", station + "tiling: varied, relief: {amplitude_cm: 1}}\n");
  const Scenario repeat = load_scenario(d + "/repeat.yaml"), varied = load_scenario(d + "/varied.yaml");
  EXPECT_EQ(repeat.ground.tiling, GroundTiling::kRepeat);
  EXPECT_EQ(varied.ground.tiling, GroundTiling::kVaried);
  EXPECT_TRUE(GroundRelief(varied).tiled());
  EXPECT_FALSE(GroundRelief(repeat).tiled());
  EXPECT_NEAR(GroundRelief(varied).height_m(1.3, -2.1), GroundRelief(repeat).height_m(1.3, -2.1), 1e-9);
  write_file(d + "/day.yaml", "base: repeat.yaml\nname: day\nground: {tiling: varied}\n");
  std::string e;
  try {
    load_scenario(d + "/day.yaml");
  } catch (const ConfigError& err) {
    e = err.what();
  }
  EXPECT_NE(e.find(d + "/day.yaml:3: ground.tiling: expected a key a derived file may change"),
            std::string::npos)
      << e;
}

// A file just over the size limit says its size in bytes: "at most 1024
// KiB, got 1024 KiB" said nothing.
TEST(ScenarioMessages, AFileJustOverTheSizeLimitGivesItsBytes) {
  std::string text = std::string(kRouteOnly) + "description: \"";
  text += std::string(1024 * 1024 + 1 - text.size() - 2, 'x') + "\"\n";
  ASSERT_EQ(text.size(), 1024u * 1024u + 1u);
  const std::string e = scenario_error(text);
  EXPECT_NE(e.find("(file): expected a scenario file of at most 1024 KiB (1048576 bytes)"), std::string::npos)
      << e;
  EXPECT_NE(e.find("got 1048577 bytes"), std::string::npos) << e;
  const std::string d = fresh_dir("size");
  write_file(d + "/big.yaml", text);
  std::string loaded;
  try {
    load_scenario(d + "/big.yaml");
  } catch (const ConfigError& err) {
    loaded = err.what();
  }
  EXPECT_NE(loaded.find("got 1048577 bytes"), std::string::npos) << loaded;
}

// A D435 whose disparity range is as wide as its infrared image made
// OpenCV's matcher throw from a destructor (abort, exit 134, a half-written
// recording): refused when the file is read, at the key given.
TEST(ScenarioMessages, ADisparityRangeAsWideAsTheInfraredImageIsRefused) {
  const std::string narrow = scenario_error(std::string(kRouteOnly) +
                                      "camera: {model: d435, stereo: {ir_width: 32, ir_height: 32}}\n");
  EXPECT_NE(narrow.find("bad.yaml:2: camera.stereo.ir_width: expected a disparity range narrower than the "
                        "infrared image"),
            std::string::npos)
      << narrow;
  EXPECT_NE(narrow.find("got disparities 128, ir_width 32"), std::string::npos) << narrow;
  const std::string wide =
      scenario_error(std::string(kRouteOnly) + "camera: {model: d435, stereo: {disparities: 64, ir_width: 64}}\n");
  EXPECT_NE(wide.find("camera.stereo.disparities: expected a disparity range narrower"), std::string::npos)
      << wide;
  const Scenario s =
      parse_scenario(std::string(kRouteOnly) + "camera: {model: d435, stereo: {disparities: 64, ir_width: 80}}\n",
                     "ok.yaml");
  EXPECT_EQ(s.camera.stereo.ir_width, 80);
}
