// The Ceres cost functions of the inertial and wheel factors
// (slam/optim/src/inertial_costs.hpp): residuals equal to the plain-double
// ones of inertial_residuals.hpp, Jacobians against central differences
// on the lifted SE(3) manifold (pose blocks) and in the Euclidean blocks.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "inertial_cost_functions.hpp"  // private to pvb_slam_optim; the test adds its src dir
#include "pvb/slam/inertial/inertial_residuals.hpp"
#include "residuals.hpp"
#include "pvb/slam/optim/synthetic.hpp"
#include "pvb/slam/optim/synthetic_inertial.hpp"

namespace pvb::slam {
namespace {

using Blocks = std::vector<std::vector<double>>;

std::vector<double> pose_block(const geom::SE3d& T_c_w) {
  std::vector<double> b(7);
  optim_detail::pose_to_block(T_c_w, b.data());
  return b;
}

Eigen::VectorXd evaluate(const ceres::CostFunction& cost, const Blocks& blocks) {
  std::vector<const double*> params;
  for (const auto& b : blocks) params.push_back(b.data());
  Eigen::VectorXd r(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(params.data(), r.data(), nullptr));
  return r;
}

/// Largest |analytic - numeric| over all blocks (tangent columns for poses,
/// which must also have a zero 7th column); prints and checks it.
double max_jacobian_error(const ceres::CostFunction& cost, const Blocks& blocks, const char* name) {
  const optim_detail::SE3LeftManifold manifold;
  const int rows = cost.num_residuals();
  std::vector<const double*> params;
  std::vector<std::vector<double>> J(blocks.size());
  std::vector<double*> jac;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    params.push_back(blocks[b].data());
    J[b].assign(rows * blocks[b].size(), -1.0);
    jac.push_back(J[b].data());
  }
  Eigen::VectorXd r(rows);
  EXPECT_TRUE(cost.Evaluate(params.data(), r.data(), jac.data()));
  EXPECT_LT((r - evaluate(cost, blocks)).norm(), 1e-12) << name;
  double worst = 0, largest = 0;
  const double h = 1e-6;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const int size = static_cast<int>(blocks[b].size());
    const bool pose = size == 7;
    const int tangent = pose ? 6 : size;
    for (int c = 0; c < tangent; ++c) {
      Blocks plus = blocks, minus = blocks;
      if (pose) {
        double d[6] = {0, 0, 0, 0, 0, 0};
        d[c] = h;
        manifold.Plus(blocks[b].data(), d, plus[b].data());
        d[c] = -h;
        manifold.Plus(blocks[b].data(), d, minus[b].data());
      } else {
        plus[b][c] += h;
        minus[b][c] -= h;
      }
      const Eigen::VectorXd num = (evaluate(cost, plus) - evaluate(cost, minus)) / (2 * h);
      for (int row = 0; row < rows; ++row) {
        const double a = J[b][row * size + c];
        worst = std::max(worst, std::abs(a - num[row]) / (1.0 + std::abs(num[row])));
        largest = std::max(largest, std::abs(num[row]));
      }
    }
    if (pose) {
      for (int row = 0; row < rows; ++row) EXPECT_EQ(J[b][row * 7 + 6], 0.0) << name << " lifted column";
    }
  }
  std::printf("%s: max relative Jacobian error %.3g (largest derivative %.3g)\n", name, worst, largest);
  EXPECT_GT(largest, 1.0) << name;  // non-trivial
  EXPECT_LT(worst, 1e-5) << name;
  return worst;
}

struct Scene {
  testing::BodyMotion m;
  testing::ImuRig imu;
  geom::SE3d T_base_c = testing::default_T_base_camera();
  geom::SE3d T_b_c;
  std::mt19937 rng{3};
  Scene() {
    m.speed_mps.c0 = 0.8;
    m.yaw_rad.waves.push_back({0.5, 0.7, 0.0});
    m.pitch_rad.waves.push_back({0.04, 1.5, 0.3});
    imu.R_base_imu = testing::default_R_base_imu();
    T_b_c = imu.T_base_imu().inverse() * T_base_c;
  }
  /// A pose off the truth, so that every residual row is non-zero.
  geom::SE3d off(double t, unsigned seed) const {
    std::mt19937 r(seed);
    return testing::perturb(testing::camera_pose(m, T_base_c, t), 0.03, 1.0, r);
  }
};

TEST(InertialCostFunctions, ImuJacobiansMatchNumeric) {
  Scene s;
  ImuBias lin;
  lin.gyro_radps = {0.002, 0.001, -0.003};
  const auto pre = s.imu.preintegrate(s.m, 1.0, 1.4, lin, &s.rng);
  const auto cost = optim_detail::make_imu_cost(*pre, s.T_b_c, s.imu.g_w);
  const Eigen::Vector3d vi = s.m.v_w(1.0) + Eigen::Vector3d(0.02, -0.01, 0.03), vj = s.m.v_w(1.4);
  const Blocks blocks = {pose_block(s.off(1.0, 1)), {vi.x(), vi.y(), vi.z()}, {0.004, -0.002, 0.001, 0.05, -0.03, 0.02},
                         pose_block(s.off(1.4, 2)), {vj.x(), vj.y(), vj.z()}};
  // The cost's residual is the factor's.
  const ImuFactor f(*pre, s.T_b_c);
  Eigen::Matrix<double, 9, 1> r;
  f.residual(blocks[0].data(), blocks[1].data(), blocks[2].data(), blocks[3].data(), blocks[4].data(), s.imu.g_w.data(),
             r.data());
  EXPECT_LT((evaluate(*cost, blocks) - r).norm(), 1e-12 * r.norm());
  ASSERT_GT(r.norm(), 10.0);
  max_jacobian_error(*cost, blocks, "IMU cost");
}

TEST(InertialCostFunctions, BiasWalkJacobiansMatchNumeric) {
  Scene s;
  const auto pre = s.imu.preintegrate(s.m, 0.0, 0.5, ImuBias{}, &s.rng);
  const auto cost = optim_detail::make_bias_walk_cost(*pre);
  max_jacobian_error(*cost, {{0.001, 0.002, 0.0, 0.01, 0.0, -0.02}, {0.0, 0.0, 0.003, 0.0, 0.05, 0.0}}, "bias walk cost");
}

TEST(InertialCostFunctions, WheelJacobiansMatchNumeric) {
  Scene s;
  testing::WheelRig wheels;
  const auto pre = wheels.preintegrate(s.m, 2.0, 3.0);
  const auto planar = optim_detail::make_wheel_planar_cost(*pre, s.T_base_c);
  const auto tilt = optim_detail::make_wheel_tilt_cost(*pre, s.T_base_c);
  const Blocks blocks = {pose_block(s.off(2.0, 4)), pose_block(s.off(3.0, 5))};
  const WheelFactor f(*pre, s.T_base_c);
  Eigen::Matrix<double, 6, 1> r;
  f.residual(blocks[0].data(), blocks[1].data(), r.data());
  EXPECT_LT((evaluate(*planar, blocks) - r.head<3>()).norm(), 1e-12 * r.norm());
  EXPECT_LT((evaluate(*tilt, blocks) - r.tail<3>()).norm(), 1e-12 * r.norm());
  max_jacobian_error(*planar, blocks, "wheel planar cost");
  max_jacobian_error(*tilt, blocks, "wheel tilt cost");
}

TEST(InertialCostFunctions, GravityJacobiansMatchNumeric) {
  Scene s;
  const geom::SE3d T_c_w = testing::camera_pose(s.m, s.T_base_c, 0.7);
  const Eigen::Vector3d f_c = T_c_w.linear() * Eigen::Vector3d(0.1, 0.2, 9.81);
  const auto cost = optim_detail::make_gravity_cost(f_c, s.imu.g_w, 0.01);
  max_jacobian_error(*cost, {pose_block(s.off(0.7, 6))}, "gravity cost");
}

}  // namespace
}  // namespace pvb::slam
