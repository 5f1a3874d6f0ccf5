// project(), observation_chi2() on hand-computed cases, and the Ceres cost
// functors (automatic derivatives) against the plain-double helper and
// against numeric differentiation.
#include <gtest/gtest.h>

#include <ceres/numeric_diff_cost_function.h>

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
  double q[4], t[3];
  explicit FunctorCase(bool stereo) {
    obs.uv = {352.5, 201.0};
    obs.u_right = stereo ? 345.0 : -1.0;
    obs.inv_sigma2 = 0.7;
    Eigen::Map<Eigen::Quaterniond>{q} = Eigen::Quaterniond(T_c_w.linear()).normalized();
    Eigen::Map<Eigen::Vector3d>{t} = T_c_w.translation();
  }
};

TEST(OptimCostFunctors, ResidualNormMatchesChi2Helper) {
  for (bool stereo : {false, true}) {
    FunctorCase s(stereo);
    const int rows = stereo ? 3 : 2;
    const double expected = observation_chi2(s.K, s.T_c_w, s.p_w, s.obs);
    ASSERT_GT(expected, 1.0);  // a non-trivial residual

    std::unique_ptr<ceres::CostFunction> pose_only(optim_detail::make_pose_only_cost(s.K, s.obs, s.p_w));
    ASSERT_EQ(pose_only->num_residuals(), rows);
    double r[3];
    const double* pose_params[] = {s.q, s.t};
    ASSERT_TRUE(pose_only->Evaluate(pose_params, r, nullptr));
    double sq = 0;
    for (int i = 0; i < rows; ++i) sq += r[i] * r[i];
    EXPECT_NEAR(sq, expected, 1e-9 * expected) << "stereo " << stereo;

    std::unique_ptr<ceres::CostFunction> ba(optim_detail::make_ba_cost(s.K, s.obs));
    ASSERT_EQ(ba->num_residuals(), rows);
    const double* ba_params[] = {s.q, s.t, s.p_w.data()};
    ASSERT_TRUE(ba->Evaluate(ba_params, r, nullptr));
    sq = 0;
    for (int i = 0; i < rows; ++i) sq += r[i] * r[i];
    EXPECT_NEAR(sq, expected, 1e-9 * expected) << "stereo " << stereo;
  }
}

TEST(OptimCostFunctors, AutomaticJacobianMatchesNumeric) {
  // The functors use automatic derivatives; this guards the Jet code path
  // (e.g. a stray cast to double) against central differences.
  FunctorCase s(true);
  std::unique_ptr<ceres::CostFunction> autodiff(optim_detail::make_ba_cost(s.K, s.obs));
  ceres::NumericDiffCostFunction<optim_detail::BaReprojection<3>, ceres::CENTRAL, 3, 4, 3, 3> numeric(
      new optim_detail::BaReprojection<3>(s.K, s.obs));
  const double* params[] = {s.q, s.t, s.p_w.data()};
  double r_a[3], r_n[3], J_a[3][3 * 4], J_n[3][3 * 4];
  double* jac_a[] = {J_a[0], J_a[1], J_a[2]};
  double* jac_n[] = {J_n[0], J_n[1], J_n[2]};
  ASSERT_TRUE(autodiff->Evaluate(params, r_a, jac_a));
  ASSERT_TRUE(numeric.Evaluate(params, r_n, jac_n));
  const int sizes[] = {4, 3, 3};
  for (int b = 0; b < 3; ++b) {
    for (int i = 0; i < 3 * sizes[b]; ++i) {
      EXPECT_NEAR(J_a[b][i], J_n[b][i], 1e-5 * (1.0 + std::abs(J_a[b][i]))) << "block " << b << " entry " << i;
    }
  }
}

TEST(OptimCostFunctors, PointBehindCameraIsRejected) {
  FunctorCase s(false);
  const Eigen::Vector3d behind = s.T_c_w.inverse() * Eigen::Vector3d(0.1, 0.1, -1.0);
  std::unique_ptr<ceres::CostFunction> ba(optim_detail::make_ba_cost(s.K, s.obs));
  const double* params[] = {s.q, s.t, behind.data()};
  double r[2];
  EXPECT_FALSE(ba->Evaluate(params, r, nullptr));
}

}  // namespace
}  // namespace pvb::slam
