// Localisation against ground truth in the map's frame, on synthetic
// trajectories: no alignment, every ground-truth frame counts, a pose in
// the wrong aisle is a wrong-place pose.
#include <gtest/gtest.h>

#include <cmath>

#include "pvb/eval/localisation.hpp"

using namespace pvb;

namespace {

geom::SE3d pose(double x, double y, double yaw_deg) {
  geom::SE3d T = geom::SE3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.5);
  return T;
}

/// 10 frames, 0.1 s apart, driving 0.1 m each along x in the world.
eval::Trajectory drive() {
  eval::Trajectory t;
  for (int i = 0; i < 10; ++i) t.poses.push_back({i * 100'000'000LL, pose(0.1 * i, 2.0, 0)});
  return t;
}

}  // namespace

TEST(Localisation, PosesInTheMapFrameAreJudgedWithoutAlignment) {
  const eval::Trajectory gt = drive();
  const geom::SE3d T_world_map = pose(-3.0, 1.0, 30);  // the mapping session's first camera
  eval::Trajectory est;
  // Frames 0-1: no pose (relocalising); 2-7 exact; 8: 0.1 m off; 9: the
  // wrong aisle, 6 m to the side.
  for (int i = 2; i < 10; ++i) {
    geom::SE3d T_map_c = T_world_map.inverse() * gt.poses[i].T_w_c;
    if (i == 8) T_map_c.translation() += Eigen::Vector3d(0.1, 0, 0);
    if (i == 9) T_map_c.translation() += Eigen::Vector3d(0, 6.0, 0);
    est.poses.push_back({gt.poses[i].t_ns, T_map_c});
  }
  const eval::LocalisationScores s = eval::score_localisation(gt, est, T_world_map);
  EXPECT_EQ(s.frames, 10u);
  EXPECT_EQ(s.posed, 8u);
  ASSERT_EQ(s.share_within.size(), 4u);
  EXPECT_DOUBLE_EQ(s.share_within[0], 0.6);  // fine: frames 2-7 of 10
  EXPECT_DOUBLE_EQ(s.share_within[1], 0.7);  // high: and frame 8
  EXPECT_DOUBLE_EQ(s.share_within[3], 0.7);  // coarse: not the wrong aisle (6 m > 5 m)
  EXPECT_EQ(s.wrong_place, 1u);
  ASSERT_TRUE(s.first_pose_frame.has_value());
  EXPECT_EQ(*s.first_pose_frame, 2u);
  EXPECT_NEAR(s.metres_to_first_pose, 0.2, 1e-12);
  EXPECT_NEAR(s.translation_max_m, 6.0, 1e-9);
  EXPECT_DOUBLE_EQ(s.translation_error_m[0], -1);
  // The same estimate judged in the world frame (a wrong T_world_map) is off everywhere.
  const eval::LocalisationScores wrong = eval::score_localisation(gt, est, geom::SE3d::Identity());
  EXPECT_EQ(wrong.share_within[1], 0.0);
  EXPECT_EQ(wrong.wrong_place, 8u);
}

TEST(Localisation, RotationAloneCanMakeAWrongPlacePose) {
  const eval::Trajectory gt = drive();
  eval::Trajectory est = gt;
  for (auto& p : est.poses) p.T_w_c = p.T_w_c * pose(0, 0, 12).inverse() * pose(0, 0, 0);  // 12 deg yaw off
  for (auto& p : est.poses) p.T_w_c.translation() = gt.poses[&p - &est.poses[0]].T_w_c.translation();
  const eval::LocalisationScores s = eval::score_localisation(gt, est, geom::SE3d::Identity());
  EXPECT_EQ(s.wrong_place, 10u);
  EXPECT_EQ(s.share_within[3], 0.0);
  EXPECT_NEAR(s.rotation_median_deg, 12.0, 1e-9);
}

TEST(Localisation, NoPoseAtAllIsNoLocalisation) {
  const eval::LocalisationScores s = eval::score_localisation(drive(), eval::Trajectory{}, geom::SE3d::Identity());
  EXPECT_EQ(s.posed, 0u);
  EXPECT_FALSE(s.first_pose_frame.has_value());
  EXPECT_EQ(s.share_within[0], 0.0);
  const std::string js = eval::localisation_json(s);
  EXPECT_NE(js.find("\"first_pose_frame\": null"), std::string::npos) << js;
  EXPECT_NE(js.find("\"translation_median_m\": null"), std::string::npos) << js;
}
