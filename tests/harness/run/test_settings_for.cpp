// The ORB-SLAM2 settings a scenario run writes (camera.yaml) and reads back:
// the scenario's camera and its `slam:` section reach the SLAM settings.
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/run/run.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/slam/core/settings.hpp"

namespace pvb::run {
namespace {

/// Writes the scenario's settings file as a run does, then reads it back.
slam::Settings written_and_read(const scenes::Scenario& s, const std::string& name) {
  const std::string path =
      ::testing::TempDir() + "pvb_settings_for_" + name + "_" + std::to_string(::getpid()) + ".yaml";
  dataset::write_orbslam_settings(path, orbslam_settings_for(s));
  return slam::read_settings(path);
}

TEST(SettingsFor, ScenarioWithoutSlamSectionGetsTheDefaults) {
  const scenes::Scenario s = scenes::parse_scenario("route: {waypoints_m: [[0, 0], [5, 0]]}\n", "min.yaml");
  const slam::Settings st = written_and_read(s, "default");
  EXPECT_TRUE(st.warnings.empty());
  EXPECT_EQ(st.orb.num_features, 1000);
  EXPECT_EQ(st.keyframe.min_tracked_close, slam::KeyFrameSettings{}.min_tracked_close);
  EXPECT_EQ(st.keyframe.ref_overlap, 0.0);
  EXPECT_DOUBLE_EQ(st.K.fx, 525.0);
  // ThDepth in baselines: the depth range's far end is the close/far threshold.
  EXPECT_NEAR(st.th_depth_m(), 4.5, 1e-9);
}

TEST(SettingsFor, SlamSectionReachesTheSettings) {
  const scenes::Scenario s = scenes::parse_scenario(
      "route: {waypoints_m: [[0, 0], [5, 0]]}\n"
      "slam: {orb_features: 2000, keyframe_min_tracked_close: 400, keyframe_ref_overlap: 0.4}\n",
      "tuned.yaml");
  const slam::Settings st = written_and_read(s, "tuned");
  EXPECT_TRUE(st.warnings.empty());
  EXPECT_EQ(st.orb.num_features, 2000);
  EXPECT_EQ(st.keyframe.min_tracked_close, 400);
  EXPECT_DOUBLE_EQ(st.keyframe.ref_overlap, 0.4);
}

TEST(SettingsFor, ShippedLawnmowerAsksForItsOwnSettings) {
  const scenes::Scenario s = scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/lawnmower.yaml");
  const slam::Settings st = written_and_read(s, "lawnmower");
  EXPECT_EQ(st.orb.num_features, s.slam.orb_features);
  ASSERT_TRUE(s.slam.keyframe_min_tracked_close);
  EXPECT_EQ(st.keyframe.min_tracked_close, *s.slam.keyframe_min_tracked_close);
  ASSERT_TRUE(s.slam.keyframe_ref_overlap);
  EXPECT_NEAR(st.keyframe.ref_overlap, *s.slam.keyframe_ref_overlap, 1e-9);
}

}  // namespace
}  // namespace pvb::run
