// The SE(3) pose graph (optimize_pose_graph): the relative-pose residual's
// jet Jacobians against numeric differentiation on the manifold, and a
// synthetic loop whose odometry carries injected drift, closed by one loop
// edge.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "pvb/slam/optim/optimizer.hpp"
#include "residuals.hpp"  // private to pvb_slam_optim; the test adds its src dir

namespace pvb::slam {
namespace {

using optim_detail::kPoseSize;
using optim_detail::kPoseTangent;

geom::SE3d pose_from(const Eigen::Vector3d& omega, const Eigen::Vector3d& t) {
  return geom::make_se3(geom::so3_exp(omega), t);
}

TEST(PoseGraphResidual, ZeroAtTheMeasurementAndJacobiansMatchNumeric) {
  const geom::SE3d T_iw = pose_from({0.1, -0.3, 0.2}, {0.5, -0.2, 1.0});
  const geom::SE3d T_jw = pose_from({-0.2, 0.1, 0.4}, {-0.3, 0.4, 0.2});
  double x_i[kPoseSize], x_j[kPoseSize];
  optim_detail::pose_to_block(T_iw, x_i);
  optim_detail::pose_to_block(T_jw, x_j);

  // Exact measurement: zero residual.
  {
    optim_detail::RelativePoseError exact(T_iw * T_jw.inverse(), 2.0);
    const double* params[2] = {x_i, x_j};
    double r[6];
    ASSERT_TRUE(exact.Evaluate(params, r, nullptr));
    for (double v : r) EXPECT_NEAR(v, 0.0, 1e-12);
  }

  // Perturbed measurement: compare the lifted Jacobians with central differences of
  // r(Plus(x, delta)) at delta = 0.
  const geom::SE3d T_meas = pose_from({0.03, -0.02, 0.05}, {0.02, 0.01, -0.03}) * T_iw * T_jw.inverse();
  optim_detail::RelativePoseError cost(T_meas, 1.5);
  optim_detail::SE3LeftManifold manifold;
  const double* params[2] = {x_i, x_j};
  double r0[6], J_i[6 * kPoseSize], J_j[6 * kPoseSize];
  double* jac[2] = {J_i, J_j};
  ASSERT_TRUE(cost.Evaluate(params, r0, jac));
  double r_plain[6];
  ASSERT_TRUE(cost.Evaluate(params, r_plain, nullptr));
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(r0[k], r_plain[k], 1e-14);
  bool nonzero = false;
  for (double v : r0) nonzero = nonzero || std::abs(v) > 1e-3;
  EXPECT_TRUE(nonzero);

  const double h = 1e-6;
  for (int b = 0; b < 2; ++b) {
    for (int c = 0; c < kPoseTangent; ++c) {
      double delta[kPoseTangent] = {0, 0, 0, 0, 0, 0};
      double xp[kPoseSize], xm[kPoseSize];
      const double* x = b == 0 ? x_i : x_j;
      delta[c] = h;
      manifold.Plus(x, delta, xp);
      delta[c] = -h;
      manifold.Plus(x, delta, xm);
      const double* pp[2] = {b == 0 ? xp : x_i, b == 1 ? xp : x_j};
      const double* pm[2] = {b == 0 ? xm : x_i, b == 1 ? xm : x_j};
      double rp[6], rm[6];
      cost.Evaluate(pp, rp, nullptr);
      cost.Evaluate(pm, rm, nullptr);
      const double* J = b == 0 ? J_i : J_j;
      for (int row = 0; row < 6; ++row)
        EXPECT_NEAR(J[row * kPoseSize + c], (rp[row] - rm[row]) / (2 * h), 1e-6) << "block " << b << " col " << c;
      for (int row = 0; row < 6; ++row) EXPECT_EQ(J[row * kPoseSize + 6], 0.0);
    }
  }
}

/// Ground truth: 40 camera poses on a circle of radius 3 m, looking outward,
/// as T_c_w.  Odometry measurements are exact; the initial values integrate
/// odometry corrupted by a small constant bias (drift), so the last pose is
/// centimetres and degrees off; one loop edge (exact) joins the last pose
/// to the first.
struct SyntheticLoop {
  std::vector<geom::SE3d> truth;
  PoseGraphProblem problem;
};

SyntheticLoop make_loop(bool with_loop_edge) {
  SyntheticLoop s;
  const int n = 40;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    const Eigen::Vector3d c_w(3 * std::cos(a), 0.1 * std::sin(3 * a), 3 * std::sin(a));
    const Eigen::Matrix3d R_w_c = geom::so3_exp(Eigen::Vector3d(0, -a, 0));
    s.truth.push_back(geom::make_se3(R_w_c, c_w).inverse());
  }
  const geom::SE3d bias = pose_from({0.004, -0.006, 0.003}, {0.008, -0.005, 0.006});
  geom::SE3d T_c_w = s.truth[0];
  for (int k = 0; k < n; ++k) {
    if (k > 0) {
      const geom::SE3d T_k_prev = s.truth[k] * s.truth[k - 1].inverse();
      T_c_w = bias * T_k_prev * T_c_w;  // drifting odometry
    }
    s.problem.nodes.push_back({static_cast<std::uint64_t>(k), T_c_w, k == 0});
  }
  for (int k = 1; k < n; ++k) s.problem.edges.push_back({static_cast<std::size_t>(k - 1), static_cast<std::size_t>(k),
                                                          s.truth[k - 1] * s.truth[k].inverse(), 1.0});
  if (with_loop_edge) s.problem.edges.push_back({static_cast<std::size_t>(n - 1), 0, s.truth[n - 1] * s.truth[0].inverse(), 1.0});
  return s;
}

double max_position_error_m(const SyntheticLoop& s) {
  double e = 0;
  for (std::size_t k = 0; k < s.truth.size(); ++k)
    e = std::max(e, (s.problem.nodes[k].T_c_w.inverse().translation() - s.truth[k].inverse().translation()).norm());
  return e;
}

TEST(PoseGraph, LoopEdgeRemovesInjectedDrift) {
  SyntheticLoop s = make_loop(true);
  const double before = max_position_error_m(s);
  ASSERT_GT(before, 0.2);  // the injected drift is large enough to matter
  const PoseGraphResult r = optimize_pose_graph(&s.problem);
  EXPECT_LT(r.final_cost, 1e-10 * std::max(1.0, r.initial_cost));
  EXPECT_LT(max_position_error_m(s), 1e-5);
  EXPECT_EQ(s.problem.nodes[0].T_c_w.matrix(), s.truth[0].matrix());  // fixed node untouched
}

TEST(PoseGraph, ExactOdometryAloneAndAWrongLoopEdge) {
  // Exact odometry from the fixed first pose is the truth, so the drifted
  // start is pulled onto it; a loop edge with a wrong measurement (0.5 m
  // off) bends the whole chain: why a false loop is worse than none.
  SyntheticLoop s = make_loop(false);
  optimize_pose_graph(&s.problem);
  EXPECT_LT(max_position_error_m(s), 1e-5);
  SyntheticLoop wrong = make_loop(false);
  const geom::SE3d off = pose_from({0, 0, 0}, {0.5, 0, 0});
  wrong.problem.edges.push_back({39, 0, off * wrong.truth[39] * wrong.truth[0].inverse(), 1.0});
  optimize_pose_graph(&wrong.problem);
  EXPECT_GT(max_position_error_m(wrong), 0.1);
}

TEST(PoseGraph, NoisyOdometryWithLoopIsBetterThanIntegration) {
  // Noisy odometry edges (seeded), drifted start; the loop edge spreads the
  // accumulated error so the worst position error drops.
  SyntheticLoop s = make_loop(true);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.003);
  for (auto& e : s.problem.edges) {
    if (e.j == 0) continue;  // the loop edge stays exact
    const Eigen::Vector3d t{noise(rng), noise(rng), noise(rng)};  // the second drawn first, as pinned
    e.T_i_j = pose_from({noise(rng), noise(rng), noise(rng)}, t) * e.T_i_j;
  }
  SyntheticLoop chain = s;
  chain.problem.edges.pop_back();  // the same noisy odometry without the loop
  optimize_pose_graph(&chain.problem);
  optimize_pose_graph(&s.problem);
  EXPECT_LT(max_position_error_m(s), 0.5 * max_position_error_m(chain));
}

TEST(PoseGraph, RejectsEdgeToMissingNode) {
  PoseGraphProblem p;
  p.nodes.push_back({0, geom::SE3d::Identity(), true});
  p.edges.push_back({0, 3, geom::SE3d::Identity(), 1.0});
  EXPECT_THROW(optimize_pose_graph(&p), std::invalid_argument);
}

}  // namespace
}  // namespace pvb::slam
