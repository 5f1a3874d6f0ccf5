// A robot that starts outside its map (campaigns/outside.yaml, seed 1,
// about 6 minutes on 2 cores: label slow): the extending session begins a
// provisional map, merges it into the loaded map when it comes round to
// the mapped ground, and saves one map, in which a last session localises
// on ground that only the provisional map saw.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>

#include "pvb/common/text.hpp"
#include "campaign_session.hpp"
#include "run_pvbench.hpp"

using namespace pvb;

namespace {

using test::campaign_session;

TEST(MapMerge, AMapBegunOutsideTheLoadedOneIsMergedIntoItAndLocalisedIn) {
  const std::string d = ::testing::TempDir() + "pvb_map_merge_" + std::to_string(::getpid());
  std::system(("rm -rf " + d).c_str());
  const auto r = test::run_pvbench("campaign --campaign " + std::string(PVB_SOURCE_DIR) +
                                   "/campaigns/outside.yaml --sync --no-map-eval --seed 1 --out " + d);
  ASSERT_EQ(r.code, 0) << r.output;
  const YAML::Node c = YAML::Load(read_file(d + "/campaign.json"));
  const YAML::Node part = campaign_session(c, "part"), outside = campaign_session(c, "outside"),
                   merged = campaign_session(c, "merged");
  // Outside the map: lost, then a provisional map without poses in the
  // map's frame until the merge, and never a pose at the wrong place.
  const YAML::Node ext = outside["map_report"];
  EXPECT_EQ(ext["merges"].as<int>(), 1) << r.output;
  EXPECT_EQ(ext["localisation"]["wrong_place"].as<int>(), 0);
  EXPECT_GT(ext["localisation"]["first_pose_frame"].as<int>(), 30);
  EXPECT_EQ(ext["saved"]["sessions"].as<int>(), 2);
  EXPECT_EQ(ext["saved"]["unmerged_keyframes"].as<int>(), 0);
  EXPECT_GT(outside["keyframes"].as<int>(), part["keyframes"].as<int>());
  // The merged ground lies where the world has it, in the map's frame.
  const YAML::Node loc = merged["map_report"]["localisation"];
  EXPECT_EQ(loc["wrong_place"].as<int>(), 0);
  EXPECT_LE(loc["first_pose_frame"].as<int>(), 30);
  EXPECT_GE(loc["within"]["fine"]["share"].as<double>(), 0.95);
}

}  // namespace
