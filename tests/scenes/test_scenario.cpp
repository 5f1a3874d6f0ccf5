#include <gtest/gtest.h>

#include <string>

#include "pvb/common/error.hpp"
#include "pvb/scenes/scenario.hpp"

using namespace pvb::scenes;

namespace {
// Returns the error message parse_scenario gives for `yaml`, or "" if it parses.
std::string error_of(const std::string& yaml) {
  try {
    parse_scenario(yaml, "bad.yaml");
  } catch (const pvb::ConfigError& e) {
    return e.what();
  }
  return "";
}
const char* kMinimal = "route: {waypoints_m: [[0, 0], [5, 0]]}\n";
}  // namespace

TEST(Scenario, ShippedScenariosLoad) {
  for (const char* name : {"pv_station", "along_row", "lawnmower", "loop"}) {
    const Scenario s = load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + name + ".yaml");
    EXPECT_EQ(s.name, name);
    EXPECT_GE(s.duration_s, 20.0) << name;
    EXPECT_FALSE(s.pv_arrays.empty()) << name;
  }
}

TEST(Scenario, DefaultsAreKinectLike) {
  const Scenario s = parse_scenario(kMinimal, "min.yaml");
  EXPECT_EQ(s.camera.width, 640);
  EXPECT_EQ(s.camera.height, 480);
  EXPECT_DOUBLE_EQ(s.camera.fx, 525.0);
  EXPECT_DOUBLE_EQ(s.camera.fps, 30.0);
  EXPECT_DOUBLE_EQ(s.camera.depth_range_m.x(), 0.5);
  EXPECT_DOUBLE_EQ(s.camera.depth_range_m.y(), 4.5);
  EXPECT_DOUBLE_EQ(s.camera.cx(), 319.5);
  EXPECT_EQ(frame_count(s), 601);
  EXPECT_EQ(frame_count(s, 120), 120);
}

TEST(Scenario, UnknownKeyIsNamedWithFileAndLine) {
  const std::string msg = error_of(std::string(kMinimal) + "camera:\n  widht: 320\n");
  EXPECT_NE(msg.find("bad.yaml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("camera.widht"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown key"), std::string::npos) << msg;
}

TEST(Scenario, WrongTypeIsNamed) {
  const std::string msg = error_of(std::string(kMinimal) + "light:\n  shadows: maybe\n");
  EXPECT_NE(msg.find("light.shadows: expected true or false, got maybe"), std::string::npos) << msg;
  const std::string msg2 = error_of(std::string(kMinimal) + "duration_s: long\n");
  EXPECT_NE(msg2.find("duration_s: expected a number, got long"), std::string::npos) << msg2;
}

TEST(Scenario, OutOfRangeIsNamed) {
  const std::string msg = error_of(std::string(kMinimal) + "pv_arrays:\n  - tilt_deg: 75\n");
  EXPECT_NE(msg.find("pv_arrays[0].tilt_deg: expected a value in [0, 60], got 75"), std::string::npos) << msg;
  const std::string cells = error_of(std::string(kMinimal) + "pv_arrays:\n  - cells: 96\n");
  EXPECT_NE(cells.find("pv_arrays[0].cells: expected one of 60, 72, 144, got 96"), std::string::npos) << cells;
}

TEST(Scenario, BadEnumListsChoices) {
  const std::string msg = error_of(std::string(kMinimal) + "ground: {type: sand}\n");
  EXPECT_NE(msg.find("ground.type: expected one of soil, gravel, got sand"), std::string::npos) << msg;
}

TEST(Scenario, CrossFieldChecks) {
  EXPECT_NE(error_of("seed: 1\n").find("route.waypoints_m"), std::string::npos);
  EXPECT_NE(error_of("route: {pattern: loop}\n").find("no pv_arrays"), std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "camera: {fx: 500, fy: 525}\n").find("fx equal to fy"), std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "camera: {depth_range_m: [4, 1]}\n").find("min <= max"),
            std::string::npos);
  EXPECT_NE(error_of("seed: -3\n" + std::string(kMinimal)).find("seed: expected a non-negative integer"),
            std::string::npos);
}

TEST(Scenario, SyntaxErrorNamesLine) {
  const std::string msg = error_of("route: {waypoints_m: [[0, 0], [5, 0]]\nseed: [\n");
  EXPECT_NE(msg.find("bad.yaml:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("valid YAML"), std::string::npos) << msg;
}

TEST(Scenario, MissingFileIsAnIoError) { EXPECT_THROW(load_scenario("/nonexistent/x.yaml"), pvb::IoError); }
