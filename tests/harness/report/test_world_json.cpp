// The world a run was made in (meta.json's and metrics.json's "world"):
// the ground appears only when it is uneven or its friction is the day's.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <string>

#include "pvb/report/world_json.hpp"

using namespace pvb;

namespace {

YAML::Node world_of(const std::string& file) {
  return YAML::Load(run::world_json(scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + file)));
}

}  // namespace

TEST(WorldJson, TheGroundIsThereOnlyWhenItIsNotTheFlatDefault) {
  EXPECT_FALSE(world_of("pv_station.yaml")["ground"].IsDefined());
  const YAML::Node rough = world_of("rough_station.yaml")["ground"];
  ASSERT_TRUE(rough.IsMap());
  EXPECT_DOUBLE_EQ(rough["relief"]["amplitude_cm"].as<double>(), 2.0);
  EXPECT_DOUBLE_EQ(rough["relief"]["slope_percent"].as<double>(), 3.0);
  EXPECT_TRUE(rough["friction"].IsNull());
  const YAML::Node wet = world_of("days/rough_station_wet.yaml")["ground"];
  EXPECT_DOUBLE_EQ(wet["friction"].as<double>(), 0.4);
  EXPECT_DOUBLE_EQ(wet["relief"]["scale_m"].as<double>(), 1.0);
}
