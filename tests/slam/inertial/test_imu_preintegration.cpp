// ImuPreintegration (Forster et al. 2017): bias Jacobians against numeric
// ones from re-integration, the covariance against Monte Carlo, predict()
// against an analytic trajectory, append and reintegrate, the SO(3) right
// Jacobian.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/inertial/imu_preintegration.hpp"
#include "pvb/slam/optim/synthetic_inertial.hpp"

namespace pvb::slam {
namespace {

using testing::BodyMotion;
using testing::ImuRig;
using testing::Signal;

/// Random readings of a moving IMU: rates up to ~1 rad/s, forces around gravity.
/// (x, y, z) drawn z first: the order the pinned readings were drawn in,
/// whichever compiler builds the test.
Eigen::Vector3d normal_zyx(std::normal_distribution<double>& d, std::mt19937& rng) {
  const double z = d(rng), y = d(rng), x = d(rng);
  return {x, y, z};
}

std::vector<ImuPreintegration::Reading> random_readings(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<ImuPreintegration::Reading> out;
  for (int k = 0; k < n; ++k) {
    ImuPreintegration::Reading r;
    r.gyro_radps = 0.6 * normal_zyx(n01, rng);
    r.accel_mps2 = Eigen::Vector3d(0, 0, 9.81) + 2.0 * normal_zyx(n01, rng);
    r.dt_s = 0.005;
    out.push_back(r);
  }
  return out;
}

ImuPreintegration integrate_all(const std::vector<ImuPreintegration::Reading>& readings, const ImuBias& b,
                                const sensor::ImuNoise& noise = {}) {
  ImuPreintegration pre(b, noise);
  for (const auto& r : readings) pre.integrate(r.gyro_radps, r.accel_mps2, r.dt_s);
  return pre;
}

ImuBias some_bias() {
  ImuBias b;
  b.gyro_radps = {0.01, -0.02, 0.005};
  b.accel_mps2 = {0.1, 0.05, -0.08};
  return b;
}

TEST(ImuPreintegration, BiasJacobiansMatchNumericReintegration) {
  const auto readings = random_readings(100, 1);  // 0.5 s
  const ImuBias b0 = some_bias();
  const ImuPreintegration pre = integrate_all(readings, b0);
  const double h = 1e-6;
  Eigen::Matrix<double, 9, 6> J_num, J_ana;
  for (int k = 0; k < 6; ++k) {
    ImuBias bp = b0, bm = b0;
    if (k < 3) {
      bp.gyro_radps[k] += h;
      bm.gyro_radps[k] -= h;
    } else {
      bp.accel_mps2[k - 3] += h;
      bm.accel_mps2[k - 3] -= h;
    }
    const ImuPreintegration p = integrate_all(readings, bp), m = integrate_all(readings, bm);
    J_num.block<3, 1>(0, k) =
        (geom::so3_log(pre.delta_R().transpose() * p.delta_R()) - geom::so3_log(pre.delta_R().transpose() * m.delta_R())) /
        (2 * h);
    J_num.block<3, 1>(3, k) = (p.delta_v() - m.delta_v()) / (2 * h);
    J_num.block<3, 1>(6, k) = (p.delta_p() - m.delta_p()) / (2 * h);
  }
  J_ana.setZero();
  J_ana.block<3, 3>(0, 0) = pre.J_R_bg();
  J_ana.block<3, 3>(3, 0) = pre.J_v_bg();
  J_ana.block<3, 3>(3, 3) = pre.J_v_ba();
  J_ana.block<3, 3>(6, 0) = pre.J_p_bg();
  J_ana.block<3, 3>(6, 3) = pre.J_p_ba();
  ASSERT_GT(J_num.norm(), 0.3);
  const double err = (J_num - J_ana).cwiseAbs().maxCoeff();
  std::printf("bias Jacobians: max |numeric - analytic| = %.3g (largest entry %.3g)\n", err,
              J_num.cwiseAbs().maxCoeff());
  EXPECT_LT(err, 1e-6);
}

TEST(ImuPreintegration, FirstOrderBiasCorrectionIsSecondOrderAccurate) {
  const auto readings = random_readings(100, 2);
  const ImuBias b0 = some_bias();
  const ImuPreintegration pre = integrate_all(readings, b0);
  double prev_err = 0;
  for (double scale : {1e-2, 1e-3}) {
    ImuBias b = b0;
    b.gyro_radps += scale * Eigen::Vector3d(1, -1, 0.5);
    b.accel_mps2 += scale * Eigen::Vector3d(-2, 1, 3);
    const ImuPreintegration exact = integrate_all(readings, b);
    const double err = geom::so3_log(exact.delta_R().transpose() * pre.delta_R(b)).norm() +
                       (exact.delta_v() - pre.delta_v(b)).norm() + (exact.delta_p() - pre.delta_p(b)).norm();
    const double err0 = geom::so3_log(exact.delta_R().transpose() * pre.delta_R()).norm() +
                        (exact.delta_v() - pre.delta_v()).norm() + (exact.delta_p() - pre.delta_p()).norm();
    EXPECT_LT(err, 0.05 * err0) << "scale " << scale;  // the correction removes the first-order error
    if (prev_err > 0) {
      EXPECT_LT(err, 0.03 * prev_err);  // 10x smaller step: ~100x smaller error
    }
    prev_err = err;
  }
}

TEST(ImuPreintegration, CovarianceMatchesMonteCarlo) {
  const auto readings = random_readings(60, 3);  // 0.3 s
  sensor::ImuNoise noise;
  noise.gyro_noise_density = 2e-3;
  noise.accel_noise_density = 2e-2;
  const ImuBias b0;
  const ImuPreintegration ref = integrate_all(readings, b0, noise);
  const Eigen::Matrix<double, 9, 9> P = ref.covariance();
  const Eigen::Matrix<double, 9, 9> P_inv = P.inverse();
  std::mt19937 rng(4);
  std::normal_distribution<double> n01(0.0, 1.0);
  const int runs = 500;
  Eigen::Matrix<double, 9, 9> S = Eigen::Matrix<double, 9, 9>::Zero();
  double chi2_sum = 0;
  for (int run = 0; run < runs; ++run) {
    ImuPreintegration noisy(b0, noise);
    for (const auto& r : readings) {
      const double sg = noise.gyro_noise_density / std::sqrt(r.dt_s), sa = noise.accel_noise_density / std::sqrt(r.dt_s);
      const Eigen::Vector3d accel_noise = sa * normal_zyx(n01, rng), gyro_noise = sg * normal_zyx(n01, rng);
      noisy.integrate(r.gyro_radps + gyro_noise, r.accel_mps2 + accel_noise, r.dt_s);
    }
    Eigen::Matrix<double, 9, 1> e;
    e << geom::so3_log(ref.delta_R().transpose() * noisy.delta_R()), noisy.delta_v() - ref.delta_v(),
        noisy.delta_p() - ref.delta_p();
    S += e * e.transpose();
    chi2_sum += e.dot(P_inv * e);
  }
  S /= runs;
  const double chi2_mean = chi2_sum / runs;
  std::printf("covariance: Monte-Carlo mean chi2 %.3f (expected 9), diag ratios", chi2_mean);
  for (int k = 0; k < 9; ++k) std::printf(" %.3f", S(k, k) / P(k, k));
  std::printf("\n");
  // Mean of 500 chi2(9) draws: 9 +- 0.19 (1 sigma).
  EXPECT_NEAR(chi2_mean, 9.0, 1.0);
  // Sample variances: relative standard error sqrt(2 / 500) = 6 %.
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(S(k, k) / P(k, k), 1.0, 0.25) << "diagonal " << k;
}

/// A body on a circle of radius 2 m at 1 m/s with a sinusoidal pitch and a
/// bobbing height: the analytic motion the readings are taken from.
BodyMotion circle_with_pitch() {
  BodyMotion m;
  m.speed_mps.c0 = 1.0;
  m.yaw_rad.c1 = 0.5;  // 1 m/s on a 2 m circle
  m.pitch_rad.waves.push_back({0.1, 3.0, 0.2});
  m.roll_rad.waves.push_back({0.05, 2.0, 0.0});
  m.z_m.waves.push_back({0.05, 4.0, 0.0});
  return m;
}

NavState true_state(const BodyMotion& m, const ImuRig& rig, double t) {
  NavState s;
  s.R_w_b = m.R_w_base(t) * rig.R_base_imu;
  s.v_w_mps = m.v_w(t);  // the IMU sits at the base's origin
  s.p_w_m = m.p_w(t);
  return s;
}

TEST(ImuPreintegration, PredictFollowsAnAnalyticTrajectory) {
  const BodyMotion m = circle_with_pitch();
  ImuRig rig;
  rig.R_base_imu = testing::default_R_base_imu();
  rig.white_noise = false;
  rig.true_bias = some_bias();
  std::mt19937 rng(5);
  const double t0 = 0.3, t1 = 2.3;
  // Linearised at the true bias, and at zero bias corrected to first order.
  const auto pre_true = rig.preintegrate(m, t0, t1, rig.true_bias, &rng);
  const auto pre_zero = rig.preintegrate(m, t0, t1, ImuBias{}, &rng);
  ASSERT_EQ(pre_true->size(), 400u);
  const NavState start = true_state(m, rig, t0), truth = true_state(m, rig, t1);
  for (const auto& pre : {pre_true, pre_zero}) {
    const NavState end = pre->predict(start, rig.g_w, rig.true_bias);
    const double rot_err = geom::so3_log(truth.R_w_b.transpose() * end.R_w_b).norm();
    const double vel_err = (truth.v_w_mps - end.v_w_mps).norm(), pos_err = (truth.p_w_m - end.p_w_m).norm();
    std::printf("predict over 2 s at 200 Hz (%s bias): rotation %.3g rad, velocity %.3g m/s, position %.3g m\n",
                pre == pre_true ? "true" : "zero + correction", rot_err, vel_err, pos_err);
    if (pre == pre_true) {  // only the discretisation
      EXPECT_LT(rot_err, 2e-6);
      EXPECT_LT(vel_err, 1e-4);
      EXPECT_LT(pos_err, 1e-4);
    } else {  // plus the second-order error of a 0.02 rad/s, 0.14 m/s^2 bias correction over 2 s
      EXPECT_LT(rot_err, 1e-3);
      EXPECT_LT(vel_err, 1e-2);
      EXPECT_LT(pos_err, 1e-2);
    }
  }
  // The uncorrected increments at the wrong bias are far off: the check above can fail.
  const NavState wrong = pre_zero->predict(start, rig.g_w, ImuBias{});
  EXPECT_GT((truth.p_w_m - wrong.p_w_m).norm(), 0.1);
}

TEST(ImuPreintegration, AppendEqualsIntegratingEverythingAtOnce) {
  const auto readings = random_readings(90, 6);
  const ImuBias b = some_bias();
  const ImuPreintegration all = integrate_all(readings, b);
  const std::vector<ImuPreintegration::Reading> first(readings.begin(), readings.begin() + 40),
      second(readings.begin() + 40, readings.end());
  ImuPreintegration a = integrate_all(first, b);
  const ImuPreintegration next = integrate_all(second, ImuBias{});  // another bias: re-integrated at a's
  a.append(next);
  EXPECT_EQ(a.size(), all.size());
  EXPECT_NEAR(a.dt_s(), all.dt_s(), 1e-15);
  EXPECT_LT((a.delta_R() - all.delta_R()).norm(), 1e-12);
  EXPECT_LT((a.delta_v() - all.delta_v()).norm(), 1e-12);
  EXPECT_LT((a.delta_p() - all.delta_p()).norm(), 1e-12);
  EXPECT_LT((a.J_p_bg() - all.J_p_bg()).norm(), 1e-12);
  EXPECT_LT((a.covariance() - all.covariance()).norm(), 1e-12 * all.covariance().norm());
}

TEST(ImuPreintegration, ReintegrateEqualsAFreshIntegration) {
  const auto readings = random_readings(50, 7);
  ImuPreintegration pre = integrate_all(readings, ImuBias{});
  const ImuBias b = some_bias();
  pre.reintegrate(b);
  const ImuPreintegration fresh = integrate_all(readings, b);
  EXPECT_EQ(pre.size(), fresh.size());
  EXPECT_EQ(pre.bias().gyro_radps, b.gyro_radps);
  EXPECT_LT((pre.delta_R() - fresh.delta_R()).norm(), 1e-14);
  EXPECT_LT((pre.delta_p() - fresh.delta_p()).norm(), 1e-14);
  EXPECT_LT((pre.J_v_ba() - fresh.J_v_ba()).norm(), 1e-14);
  EXPECT_LT((pre.covariance() - fresh.covariance()).norm(), 1e-14);
  // At its own bias the corrected increments are the plain ones.
  EXPECT_LT((pre.delta_v(b) - pre.delta_v()).norm(), 1e-15);
}

/// Largest difference between two preintegrations' increments, bias
/// Jacobians and covariance, each relative to the size of `ref`'s.
double largest_relative_difference(const ImuPreintegration& a, const ImuPreintegration& ref) {
  const auto rel = [](const auto& x, const auto& y) { return (x - y).norm() / std::max(1.0, y.norm()); };
  return std::max({rel(a.delta_R(), ref.delta_R()), rel(a.delta_v(), ref.delta_v()),
                   rel(a.delta_p(), ref.delta_p()), rel(a.J_R_bg(), ref.J_R_bg()),
                   rel(a.J_v_bg(), ref.J_v_bg()), rel(a.J_v_ba(), ref.J_v_ba()),
                   rel(a.J_p_bg(), ref.J_p_bg()), rel(a.J_p_ba(), ref.J_p_ba()),
                   rel(a.covariance(), ref.covariance()), std::abs(a.dt_s() - ref.dt_s())});
}

TEST(ImuPreintegration, FoldsTheOldestReadingsPastTheCap) {
  const int n = 2 * static_cast<int>(ImuPreintegration::kFoldAt) + 100;
  const auto readings = random_readings(n, 8);
  const ImuPreintegration pre = integrate_all(readings, some_bias());
  EXPECT_EQ(pre.size(), static_cast<std::size_t>(n));
  EXPECT_LT(pre.readings().size(), ImuPreintegration::kFoldAt);
  EXPECT_GT(pre.folded_count(), 0u);
  EXPECT_EQ(pre.folded_count() + pre.readings().size(), static_cast<std::size_t>(n));
  EXPECT_EQ(pre.readings().back().gyro_radps, readings.back().gyro_radps);  // the newest are kept
  EXPECT_EQ(pre.readings().front().gyro_radps, readings[pre.folded_count()].gyro_radps);
}

TEST(ImuPreintegration, ReintegratingFoldedReadingsAtTheirBiasChangesNothing) {
  const auto readings = random_readings(static_cast<int>(ImuPreintegration::kFoldAt) + 700, 9);
  const ImuBias b = some_bias();
  ImuPreintegration pre = integrate_all(readings, b);
  ASSERT_GT(pre.folded_count(), 0u);
  const ImuPreintegration before = pre;
  pre.reintegrate(b);
  EXPECT_EQ(pre.size(), before.size());
  EXPECT_EQ(pre.folded_count(), before.folded_count());
  EXPECT_LT(largest_relative_difference(pre, before), 1e-12);
}

TEST(ImuPreintegration, ReintegratingFoldedReadingsIsSecondOrderAccurate) {
  const auto readings = random_readings(static_cast<int>(ImuPreintegration::kFoldAt) + 700, 10);
  const ImuBias b0 = some_bias();
  const ImuPreintegration at_b0 = integrate_all(readings, b0);
  ASSERT_GT(at_b0.folded_count(), 0u);
  double prev_err = 0;
  for (double scale : {1e-3, 1e-4}) {
    ImuBias b = b0;
    b.gyro_radps += scale * Eigen::Vector3d(1, -1, 0.5);
    b.accel_mps2 += scale * Eigen::Vector3d(-2, 1, 3);
    ImuPreintegration pre = at_b0;
    pre.reintegrate(b);
    const ImuPreintegration exact = integrate_all(readings, b);  // folds at b: exact
    const double err = geom::so3_log(exact.delta_R().transpose() * pre.delta_R()).norm() +
                       (exact.delta_v() - pre.delta_v()).norm() + (exact.delta_p() - pre.delta_p()).norm();
    const double err0 = geom::so3_log(exact.delta_R().transpose() * at_b0.delta_R()).norm() +
                        (exact.delta_v() - at_b0.delta_v()).norm() +
                        (exact.delta_p() - at_b0.delta_p()).norm();
    EXPECT_LT(err, 0.05 * err0) << "scale " << scale;
    if (prev_err > 0) {
      EXPECT_LT(err, 0.03 * prev_err);  // 10x smaller step: ~100x smaller error
    }
    prev_err = err;
  }
}

TEST(ImuPreintegration, AppendingAFoldedIntervalEqualsIntegratingEverything) {
  const int n_first = 1000, n_next = static_cast<int>(ImuPreintegration::kFoldAt) + 300;
  const auto readings = random_readings(n_first + n_next, 11);
  const ImuBias b = some_bias();
  const ImuPreintegration all = integrate_all(readings, b);
  const std::vector<ImuPreintegration::Reading> first(readings.begin(), readings.begin() + n_first),
      second(readings.begin() + n_first, readings.end());
  ImuPreintegration a = integrate_all(first, b);
  const ImuPreintegration next = integrate_all(second, b);
  ASSERT_GT(next.folded_count(), 0u);
  a.append(next);
  EXPECT_EQ(a.size(), all.size());
  EXPECT_EQ(a.readings().size(), next.readings().size());
  EXPECT_LT(largest_relative_difference(a, all), 1e-9);
  // What is left can still be integrated again at another bias.
  ImuBias b1 = b;
  b1.gyro_radps.x() += 1e-4;
  a.reintegrate(b1);
  EXPECT_LT(largest_relative_difference(a, integrate_all(readings, b1)), 1e-3);
}

TEST(ImuPreintegration, RejectsNonPositiveDt) {
  ImuPreintegration pre(ImuBias{}, sensor::ImuNoise{});
  EXPECT_THROW(pre.integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.0), std::invalid_argument);
  EXPECT_THROW(pre.integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), -1e-3), std::invalid_argument);
  EXPECT_EQ(pre.size(), 0u);
}

TEST(So3RightJacobian, MatchesNumericAndItsInverse) {
  for (const Eigen::Vector3d& phi : {Eigen::Vector3d(0.3, -0.5, 0.8), Eigen::Vector3d(1e-7, 2e-7, -1e-7),
                                     Eigen::Vector3d(2.0, 0.5, -1.0)}) {
    const Eigen::Matrix3d Jr = so3_right_jacobian(phi);
    // Exp(phi + d) = Exp(phi) Exp(Jr d) to first order.
    Eigen::Matrix3d J_num;
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = h * Eigen::Vector3d::Unit(k);
      J_num.col(k) = (geom::so3_log(geom::so3_exp(phi).transpose() * geom::so3_exp(phi + d)) -
                      geom::so3_log(geom::so3_exp(phi).transpose() * geom::so3_exp(phi - d))) /
                     (2 * h);
    }
    EXPECT_LT((J_num - Jr).norm(), 1e-8) << phi.transpose();
    EXPECT_LT((so3_right_jacobian_inverse(phi) * Jr - Eigen::Matrix3d::Identity()).norm(), 1e-12) << phi.transpose();
  }
}

}  // namespace
}  // namespace pvb::slam
