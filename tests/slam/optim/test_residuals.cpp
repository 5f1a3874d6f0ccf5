// project(), observation_chi2() on hand-computed cases, the Ceres cost
// functions (analytic Jacobians on the SE(3) manifold) against the
// plain-double helper and against numeric differentiation, and the
// pose-only normal equations of optimize_pose.
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


// The pose-only normal equations that optimize_pose's Levenberg-Marquardt
// builds: H and g against sums over reprojection()'s residuals and
// Jacobians, and g against the numeric gradient of the robust cost on the
// manifold (Huber active on some observations).
TEST(OptimPoseNormalEquations, MatchReprojectionAndNumericGradient) {
  const StereoIntrinsics K = hand_intrinsics();
  double pose[optim_detail::kPoseSize];
  optim_detail::pose_to_block(
      geom::make_se3(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, -0.4).normalized())),
                     Eigen::Vector3d(0.1, -0.2, 0.3)),
      pose);
  const geom::SE3d T_c_w = optim_detail::block_to_pose(pose);
  std::vector<Eigen::Vector3d> points;
  std::vector<Observation> obs;
  std::vector<std::size_t> active;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d p_c(-0.8 + 0.04 * i, 0.5 * std::sin(i), 1.5 + 0.05 * i);
    points.push_back(T_c_w.inverse() * p_c);
    Observation o;
    o.uv = project(K, p_c) + Eigen::Vector2d(0.7 * std::cos(3.0 * i), (i % 7 == 0) ? 9.0 : 0.4 * std::sin(i));
    o.u_right = (i % 3 == 0) ? -1.0 : o.uv.x() - K.bf / p_c.z() + 0.3;
    o.inv_sigma2 = 1.0 / std::pow(1.2, 2 * (i % 4));
    obs.push_back(o);
    active.push_back(static_cast<std::size_t>(i));
  }
  const PoseOptimizerOptions options;
  optim_detail::PoseNormalEquations ne;
  ASSERT_TRUE(optim_detail::pose_normal_equations<true>(K, points, obs, active, true, options, pose, &ne));

  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  double cost = 0.0;
  int robust_active = 0;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const bool stereo = optim_detail::is_stereo(obs[i]);
    double r[3] = {0, 0, 0};
    double J[3 * optim_detail::kPoseSize];
    ASSERT_TRUE(stereo ? optim_detail::reprojection<3>(K, obs[i], pose, points[i], r, J, nullptr)
                       : optim_detail::reprojection<2>(K, obs[i], pose, points[i], r, J, nullptr));
    const int rows = stereo ? 3 : 2;
    const double chi2 = stereo ? options.chi2_stereo : options.chi2_mono;
    double s = 0;
    for (int k = 0; k < rows; ++k) s += r[k] * r[k];
    const double w = s <= chi2 ? 1.0 : std::sqrt(chi2 / s);
    robust_active += s > chi2;
    cost += 0.5 * (s <= chi2 ? s : 2.0 * std::sqrt(chi2 * s) - chi2);
    for (int k = 0; k < rows; ++k) {
      const Eigen::Map<const Eigen::Matrix<double, 6, 1>> Jk(J + k * optim_detail::kPoseSize);
      H += w * Jk * Jk.transpose();
      g += w * r[k] * Jk;
    }
  }
  ASSERT_GT(robust_active, 3);  // the Huber branch is exercised
  EXPECT_NEAR(ne.cost, cost, 1e-9 * cost);
  EXPECT_LT((ne.H - H).norm(), 1e-9 * H.norm());
  EXPECT_LT((ne.g - g).norm(), 1e-9 * g.norm());

  // Numeric gradient of the cost through the manifold's Plus.
  optim_detail::SE3LeftManifold manifold;
  for (int c = 0; c < 6; ++c) {
    const double h = 1e-6;
    double delta[6] = {0, 0, 0, 0, 0, 0};
    double plus[optim_detail::kPoseSize], minus[optim_detail::kPoseSize];
    delta[c] = h;
    manifold.Plus(pose, delta, plus);
    delta[c] = -h;
    manifold.Plus(pose, delta, minus);
    optim_detail::PoseNormalEquations a, b;
    ASSERT_TRUE(optim_detail::pose_normal_equations<false>(K, points, obs, active, true, options, plus, &a));
    ASSERT_TRUE(optim_detail::pose_normal_equations<false>(K, points, obs, active, true, options, minus, &b));
    EXPECT_NEAR((a.cost - b.cost) / (2 * h), ne.g[c], 1e-4 * (1.0 + g.norm())) << "component " << c;
  }
}

}  // namespace
}  // namespace pvb::slam
