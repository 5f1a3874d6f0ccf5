// project(), observation_chi2() on hand-computed cases, and the Ceres cost
// functions (analytic Jacobians on the SE(3) manifold) against the
// plain-double helper and against numeric differentiation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "pvb/slam/optim/optimizer.hpp"
#include "residuals.hpp"  // private to pvb_slam_optim; the test adds its src dir

namespace pvb::slam {
namespace {

StereoIntrinsics hand_intrinsics() {
  StereoIntrinsics K;
  K.fx = 500;
  K.fy = 400;
  K.cx = 320;
  K.cy = 240;
  K.bf = 40;
  return K;
}

TEST(OptimChi2Helper, ProjectHandComputed) {
  // u = 500 * 0.2 / 2 + 320 = 370, v = 400 * -0.1 / 2 + 240 = 220
  const Eigen::Vector2d uv = project(hand_intrinsics(), Eigen::Vector3d(0.2, -0.1, 2.0));
  EXPECT_DOUBLE_EQ(uv.x(), 370.0);
  EXPECT_DOUBLE_EQ(uv.y(), 220.0);
}

TEST(OptimChi2Helper, StereoAndMonoHandComputed) {
  // Camera 1 m behind the world origin along z: p_c = p_w + (0, 0, 1).
  const geom::SE3d T_c_w = geom::make_se3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 1));
  const Eigen::Vector3d p_w(0.2, -0.1, 1.0);  // p_c = (0.2, -0.1, 2): u 370, v 220, u_r 370 - 40 / 2 = 350
  Observation o;
  o.uv = {371.0, 218.0};  // errors 1, -2 ... sign does not matter for chi2
  o.u_right = 353.0;      // error 3
  o.inv_sigma2 = 0.5;
  EXPECT_DOUBLE_EQ(observation_chi2(hand_intrinsics(), T_c_w, p_w, o), 0.5 * (1 + 4 + 9));  // 7
  o.u_right = -1.0;  // monocular: u_right ignored
  EXPECT_DOUBLE_EQ(observation_chi2(hand_intrinsics(), T_c_w, p_w, o), 0.5 * (1 + 4));  // 2.5
}

TEST(OptimChi2Helper, RotatedCamera) {
  // 90 deg about z: R maps x to y.  p_w (0.1, 0, 2) -> p_c (0, 0.1, 2): u 320, v 260.
  const geom::SE3d T_c_w = geom::make_se3(geom::so3_exp(Eigen::Vector3d(0, 0, std::acos(-1.0) / 2)), Eigen::Vector3d::Zero());
  Observation o;
  o.uv = {320.0, 263.0};
  o.inv_sigma2 = 1.0 / (1.2 * 1.2);
  EXPECT_NEAR(observation_chi2(hand_intrinsics(), T_c_w, Eigen::Vector3d(0.1, 0, 2), o), 9.0 / 1.44, 1e-9);
}

TEST(OptimChi2Helper, BehindCameraIsInfinite) {
  Observation o;
  o.uv = {320, 240};
  const double chi2 =
      observation_chi2(hand_intrinsics(), geom::SE3d::Identity(), Eigen::Vector3d(0, 0, -2), o);
  EXPECT_EQ(chi2, std::numeric_limits<double>::infinity());
  EXPECT_EQ(observation_chi2(hand_intrinsics(), geom::SE3d::Identity(), Eigen::Vector3d(0, 0, 0), o),
            std::numeric_limits<double>::infinity());
}

struct FunctorCase {
  StereoIntrinsics K = hand_intrinsics();
  geom::SE3d T_c_w = geom::make_se3(geom::so3_exp(Eigen::Vector3d(0.1, -0.2, 0.05)), Eigen::Vector3d(0.3, 0.1, 0.5));
  Eigen::Vector3d p_w{0.4, -0.3, 3.0};
  Observation obs;
  double pose[optim_detail::kPoseSize];
  explicit FunctorCase(bool stereo) {
    obs.uv = {352.5, 201.0};
    obs.u_right = stereo ? 345.0 : -1.0;
    obs.inv_sigma2 = 0.7;
    optim_detail::pose_to_block(T_c_w, pose);
  }
};

TEST(OptimCostFunctions, ResidualNormMatchesChi2Helper) {
  for (bool stereo : {false, true}) {
    FunctorCase s(stereo);
    const int rows = stereo ? 3 : 2;
    const double expected = observation_chi2(s.K, s.T_c_w, s.p_w, s.obs);
    ASSERT_GT(expected, 1.0);  // a non-trivial residual

    std::unique_ptr<ceres::CostFunction> pose_only(optim_detail::make_pose_only_cost(s.K, s.obs, s.p_w));
    ASSERT_EQ(pose_only->num_residuals(), rows);
    double r[3];
    const double* pose_params[] = {s.pose};
    ASSERT_TRUE(pose_only->Evaluate(pose_params, r, nullptr));
    double sq = 0;
    for (int i = 0; i < rows; ++i) sq += r[i] * r[i];
    EXPECT_NEAR(sq, expected, 1e-9 * expected) << "stereo " << stereo;

    std::unique_ptr<ceres::CostFunction> ba(optim_detail::make_ba_cost(s.K, s.obs));
    ASSERT_EQ(ba->num_residuals(), rows);
    const double* ba_params[] = {s.pose, s.p_w.data()};
    ASSERT_TRUE(ba->Evaluate(ba_params, r, nullptr));
    sq = 0;
    for (int i = 0; i < rows; ++i) sq += r[i] * r[i];
    EXPECT_NEAR(sq, expected, 1e-9 * expected) << "stereo " << stereo;
  }
}

// The residual as a plain function of (pose block, point), for numeric differences.
Eigen::Vector3d residual_of(const FunctorCase& s, const double* pose, const Eigen::Vector3d& p_w) {
  std::unique_ptr<ceres::CostFunction> ba(optim_detail::make_ba_cost(s.K, s.obs));
  const double* params[] = {pose, p_w.data()};
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  EXPECT_TRUE(ba->Evaluate(params, r.data(), nullptr));
  return r;
}

TEST(OptimCostFunctions, AnalyticJacobiansMatchNumericOnTheManifold) {
  // Tangent columns: central differences of r(Plus(x, h e_k)) at h = 0, the
  // derivative Ceres needs (J * PlusJacobian).  Point columns: central
  // differences in p_w.  Mono and stereo, pose-only and BA cost functions.
  const optim_detail::SE3LeftManifold manifold;
  const double h = 1e-6;
  for (bool stereo : {false, true}) {
    FunctorCase s(stereo);
    const int rows = stereo ? 3 : 2;
    Eigen::Matrix<double, 3, 6> J_num_pose = Eigen::Matrix<double, 3, 6>::Zero();
    for (int k = 0; k < 6; ++k) {
      double delta[6] = {0, 0, 0, 0, 0, 0};
      double plus[7], minus[7];
      delta[k] = h;
      ASSERT_TRUE(manifold.Plus(s.pose, delta, plus));
      delta[k] = -h;
      ASSERT_TRUE(manifold.Plus(s.pose, delta, minus));
      J_num_pose.col(k) = (residual_of(s, plus, s.p_w) - residual_of(s, minus, s.p_w)) / (2 * h);
    }
    Eigen::Matrix3d J_num_point = Eigen::Matrix3d::Zero();
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d e = Eigen::Vector3d::Zero();
      e[k] = h;
      J_num_point.col(k) = (residual_of(s, s.pose, s.p_w + e) - residual_of(s, s.pose, s.p_w - e)) / (2 * h);
    }

    // BA cost function: pose (rows x 7, row-major) and point (rows x 3).
    double r[3], J_pose[3 * 7], J_point[3 * 3];
    double* jac[] = {J_pose, J_point};
    std::unique_ptr<ceres::CostFunction> ba(optim_detail::make_ba_cost(s.K, s.obs));
    const double* ba_params[] = {s.pose, s.p_w.data()};
    ASSERT_TRUE(ba->Evaluate(ba_params, r, jac));
    // Pose-only cost function: the same pose Jacobian.
    double J_pose_only[3 * 7];
    double* jac_pose_only[] = {J_pose_only};
    std::unique_ptr<ceres::CostFunction> pose_only(optim_detail::make_pose_only_cost(s.K, s.obs, s.p_w));
    const double* pose_params[] = {s.pose};
    ASSERT_TRUE(pose_only->Evaluate(pose_params, r, jac_pose_only));

    ASSERT_GT(J_num_pose.norm(), 10.0);  // a non-trivial derivative to compare
    ASSERT_GT(J_num_point.norm(), 10.0);
    for (int i = 0; i < rows; ++i) {
      for (int k = 0; k < 6; ++k) {
        const double a = J_pose[i * 7 + k], n = J_num_pose(i, k);
        EXPECT_NEAR(a, n, 1e-5 * (1.0 + std::abs(n))) << "stereo " << stereo << " pose row " << i << " col " << k;
        EXPECT_EQ(J_pose_only[i * 7 + k], a) << "stereo " << stereo << " row " << i << " col " << k;
      }
      EXPECT_EQ(J_pose[i * 7 + 6], 0.0);  // lifted: the 7th column is unused
      EXPECT_EQ(J_pose_only[i * 7 + 6], 0.0);
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(J_point[i * 3 + k], J_num_point(i, k), 1e-5 * (1.0 + std::abs(J_num_point(i, k))))
            << "stereo " << stereo << " point row " << i << " col " << k;
      }
    }
  }
}

TEST(OptimSE3Manifold, PlusIsTheLeftUpdateAndMinusItsInverse) {
  const optim_detail::SE3LeftManifold manifold;
  FunctorCase s(true);
  const double delta[6] = {0.3, -0.2, 0.4, 0.05, -0.1, 0.2};
  double x_plus[7];
  ASSERT_TRUE(manifold.Plus(s.pose, delta, x_plus));
  // Expected: T <- [Exp(omega) | rho] * T.
  const geom::SE3d T_update =
      geom::make_se3(geom::so3_exp(Eigen::Vector3d(delta[0], delta[1], delta[2])), Eigen::Vector3d(delta[3], delta[4], delta[5]));
  const geom::SE3d expected = T_update * s.T_c_w;
  const geom::SE3d got = optim_detail::block_to_pose(x_plus);
  EXPECT_LT((got.matrix() - expected.matrix()).norm(), 1e-12);
  EXPECT_NEAR(Eigen::Map<const Eigen::Quaterniond>(x_plus).norm(), 1.0, 1e-15);

  double back[6];
  ASSERT_TRUE(manifold.Minus(x_plus, s.pose, back));
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(back[k], delta[k], 1e-12) << k;

  const double zero[6] = {0, 0, 0, 0, 0, 0};
  double same[7];
  ASSERT_TRUE(manifold.Plus(s.pose, zero, same));
  for (int k = 0; k < 7; ++k) EXPECT_NEAR(same[k], s.pose[k], 1e-15) << k;
}

TEST(OptimCostFunctions, PointBehindCameraIsRejected) {
  FunctorCase s(false);
  const Eigen::Vector3d behind = s.T_c_w.inverse() * Eigen::Vector3d(0.1, 0.1, -1.0);
  std::unique_ptr<ceres::CostFunction> ba(optim_detail::make_ba_cost(s.K, s.obs));
  const double* params[] = {s.pose, behind.data()};
  double r[2];
  EXPECT_FALSE(ba->Evaluate(params, r, nullptr));
}

}  // namespace
}  // namespace pvb::slam
