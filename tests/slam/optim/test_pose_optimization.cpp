// optimize_pose(): ORB-SLAM2's PoseOptimization on synthetic correspondences
// with a known camera pose.
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>

#include "pvb/slam/optim/optimizer.hpp"
#include "pvb/slam/optim/synthetic.hpp"

namespace pvb::slam {
namespace {

using testing::make_pose_scene;
using testing::perturb;
using testing::position_error_m;
using testing::rotation_error_deg;

TEST(PoseOptimization, RecoversPoseFromNoisyStereoObservations) {
  const auto s = make_pose_scene(300, 1.0, /*stereo=*/true, 0.0, 1);
  std::mt19937 rng(2);
  const geom::SE3d T_init = perturb(s.T_c_w_gt, 0.10, 5.0, rng);
  ASSERT_GT(position_error_m(T_init, s.T_c_w_gt), 0.09);
  ASSERT_GT(rotation_error_deg(T_init, s.T_c_w_gt), 4.9);

  const auto r = optimize_pose(T_init, s.points_w, s.obs, testing::default_intrinsics());
  EXPECT_LT(position_error_m(r.T_c_w, s.T_c_w_gt), 0.01);
  EXPECT_LT(rotation_error_deg(r.T_c_w, s.T_c_w_gt), 0.2);
  ASSERT_EQ(r.inlier.size(), s.obs.size());
  int count = 0;
  for (auto f : r.inlier) count += f;
  EXPECT_EQ(count, r.num_inliers);
  // Noise matches the model (sigma 1 px): the 95 % chi2 gate keeps most.
  EXPECT_GT(r.num_inliers, 0.85 * 300);
}

TEST(PoseOptimization, RejectsGrossOutliers) {
  // 0.5 px noise against a model sigma of 1 px: with noise exactly at the
  // model sigma the 95 % chi2 gate rejects ~5 % of true inliers by design,
  // so "keeps >= 95 % of inliers" would be a coin toss.
  const auto s = make_pose_scene(300, 0.5, /*stereo=*/true, 0.30, 3);
  std::mt19937 rng(4);
  const geom::SE3d T_init = perturb(s.T_c_w_gt, 0.10, 5.0, rng);

  const auto r = optimize_pose(T_init, s.points_w, s.obs, testing::default_intrinsics());
  EXPECT_LT(position_error_m(r.T_c_w, s.T_c_w_gt), 0.01);
  EXPECT_LT(rotation_error_deg(r.T_c_w, s.T_c_w_gt), 0.2);

  int outliers = 0, outliers_flagged = 0, inliers = 0, inliers_kept = 0;
  for (std::size_t i = 0; i < s.obs.size(); ++i) {
    if (s.is_outlier[i]) {
      ++outliers;
      outliers_flagged += r.inlier[i] ? 0 : 1;
    } else {
      ++inliers;
      inliers_kept += r.inlier[i] ? 1 : 0;
    }
  }
  ASSERT_GT(outliers, 60);  // the scene really has ~30 % outliers
  EXPECT_GE(outliers_flagged, 0.95 * outliers);
  EXPECT_GE(inliers_kept, 0.95 * inliers);
}

TEST(PoseOptimization, MonocularObservationsOnly) {
  const auto s = make_pose_scene(300, 1.0, /*stereo=*/false, 0.0, 5);
  for (const auto& o : s.obs) ASSERT_LT(o.u_right, 0.0);
  std::mt19937 rng(6);
  const geom::SE3d T_init = perturb(s.T_c_w_gt, 0.10, 5.0, rng);

  const auto r = optimize_pose(T_init, s.points_w, s.obs, testing::default_intrinsics());
  EXPECT_LT(position_error_m(r.T_c_w, s.T_c_w_gt), 0.01);
  EXPECT_LT(rotation_error_deg(r.T_c_w, s.T_c_w_gt), 0.2);
  EXPECT_GT(r.num_inliers, 0.85 * 300);
}

TEST(PoseOptimization, MixedMonoAndStereoWithOutliers) {
  auto s = make_pose_scene(300, 0.5, /*stereo=*/true, 0.30, 7);
  for (std::size_t i = 0; i < s.obs.size(); i += 2) s.obs[i].u_right = -1.0;  // half monocular
  std::mt19937 rng(8);
  const auto r = optimize_pose(perturb(s.T_c_w_gt, 0.10, 5.0, rng), s.points_w, s.obs, testing::default_intrinsics());
  EXPECT_LT(position_error_m(r.T_c_w, s.T_c_w_gt), 0.01);
  EXPECT_LT(rotation_error_deg(r.T_c_w, s.T_c_w_gt), 0.2);
}

TEST(PoseOptimization, SameInputGivesBitIdenticalOutput) {
  const auto s = make_pose_scene(300, 1.0, true, 0.30, 9);
  std::mt19937 rng(10);
  const geom::SE3d T_init = perturb(s.T_c_w_gt, 0.10, 5.0, rng);
  const auto a = optimize_pose(T_init, s.points_w, s.obs, testing::default_intrinsics());
  const auto b = optimize_pose(T_init, s.points_w, s.obs, testing::default_intrinsics());
  EXPECT_EQ(0, std::memcmp(a.T_c_w.matrix().data(), b.T_c_w.matrix().data(), sizeof(double) * 16));
  EXPECT_EQ(a.inlier, b.inlier);
  EXPECT_EQ(a.num_inliers, b.num_inliers);
  EXPECT_EQ(0, std::memcmp(&a.final_cost, &b.final_cost, sizeof(double)));
}

TEST(PoseOptimization, PointBehindCameraIsAnOutlier) {
  auto s = make_pose_scene(50, 0.5, true, 0.0, 11);
  // Move point 0 behind the camera (mirror through the optical centre).
  const geom::SE3d T_w_c = s.T_c_w_gt.inverse();
  s.points_w[0] = T_w_c * (-(s.T_c_w_gt * s.points_w[0]));
  const auto r = optimize_pose(s.T_c_w_gt, s.points_w, s.obs, testing::default_intrinsics());
  EXPECT_EQ(r.inlier[0], 0);
  EXPECT_LT(position_error_m(r.T_c_w, s.T_c_w_gt), 0.01);
}

TEST(PoseOptimization, TooFewObservationsKeepsInitialPose) {
  const auto s = make_pose_scene(2, 0.5, true, 0.0, 12);
  std::mt19937 rng(13);
  const geom::SE3d T_init = perturb(s.T_c_w_gt, 0.10, 5.0, rng);
  const auto r = optimize_pose(T_init, s.points_w, s.obs, testing::default_intrinsics());
  EXPECT_TRUE(r.T_c_w.isApprox(T_init, 0.0));
  EXPECT_EQ(r.inlier.size(), 2u);

  const auto empty = optimize_pose(T_init, {}, {}, testing::default_intrinsics());
  EXPECT_EQ(empty.num_inliers, 0);
  EXPECT_TRUE(empty.inlier.empty());
}

TEST(PoseOptimization, MismatchedSizesThrow) {
  const auto s = make_pose_scene(10, 0.5, true, 0.0, 14);
  auto points = s.points_w;
  points.pop_back();
  EXPECT_THROW(optimize_pose(s.T_c_w_gt, points, s.obs, testing::default_intrinsics()), std::invalid_argument);
}

}  // namespace
}  // namespace pvb::slam
