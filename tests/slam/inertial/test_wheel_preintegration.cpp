// WheelPreintegration: straight, on the spot and on an arc against closed
// forms, the covariance's growth, the composition's Jacobians against
// numeric ones, the propagated covariance against Monte Carlo, append.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "pvb/slam/inertial/wheel_preintegration.hpp"

namespace pvb::slam {
namespace {

sensor::DriveDescription drive() {
  sensor::DriveDescription d;
  d.wheel_radius_m = 0.1;
  d.track_m = 0.4;
  d.ticks_per_rev = 1000;
  return d;
}

TEST(WheelPreintegration, ACalibrationScalesEachWheelAndTheTrack) {
  // Left wheel 1 % small, right 1 % large, track 10 % wide: on the spot the
  // counts of a described half turn turn the robot by pi (1 +- 0.01) / 1.1 on
  // average, and a straight run curves to the left.
  const WheelCalibration c{0.99, 1.01, 1.1};
  WheelPreintegration spot(drive(), WheelNoise{}, c), straight(drive(), WheelNoise{}, c);
  const double counts_half_turn = M_PI * 0.2 / (2 * M_PI * 0.1 / 1000);  // arc pi * track / 2 per wheel
  spot.add(-counts_half_turn, counts_half_turn);
  EXPECT_NEAR(spot.delta().z(), M_PI * (0.99 + 1.01) / 2 / 1.1, 1e-12);
  straight.add(1000, 1000);
  const double arc = 2 * M_PI * 0.1;
  EXPECT_NEAR(straight.delta().z(), arc * (1.01 - 0.99) / (0.4 * 1.1), 1e-12);
  // What the calibration is fitted to stays the described arcs.
  EXPECT_NEAR(straight.described_left_m(), arc, 1e-12);
  EXPECT_NEAR(straight.described_right_m(), arc, 1e-12);
  EXPECT_NEAR(spot.described_left_m(), -M_PI * 0.2, 1e-9);
  WheelPreintegration both(drive(), WheelNoise{}, c);
  both.append(spot);
  both.append(straight);
  EXPECT_NEAR(both.described_right_m(), M_PI * 0.2 + arc, 1e-9);
  EXPECT_THROW(WheelPreintegration(drive(), WheelNoise{}, WheelCalibration{0, 1, 1}), std::invalid_argument);
}

TEST(WheelPreintegration, StraightAhead) {
  WheelPreintegration pre(drive(), WheelNoise{});
  for (int k = 0; k < 100; ++k) pre.add(20, 20);
  const double d = 2000 * 2 * M_PI * 0.1 / 1000;  // 2000 counts of 0.628 mm
  EXPECT_NEAR(pre.delta().x(), d, 1e-12);
  EXPECT_NEAR(pre.delta().y(), 0.0, 1e-12);
  EXPECT_NEAR(pre.delta().z(), 0.0, 1e-12);
  EXPECT_NEAR(pre.distance_m(), d, 1e-12);
  EXPECT_NEAR(pre.turn_rad(), 0.0, 1e-12);
  // Straight ahead the along-track variance is sigma_t^2 d, the yaw's sigma_yaw_m^2 d.
  const WheelNoise n;
  EXPECT_NEAR(pre.covariance()(0, 0), n.translation_per_sqrt_m * n.translation_per_sqrt_m * d, 1e-12);
  EXPECT_NEAR(pre.covariance()(2, 2), n.yaw_per_sqrt_m * n.yaw_per_sqrt_m * d, 1e-12);
  // Across track the yaw's uncertainty adds to the translation's:
  // sigma_t^2 d + sigma_yaw_m^2 d^3 / 3 in the continuous limit.
  const double across = n.translation_per_sqrt_m * n.translation_per_sqrt_m * d +
                        n.yaw_per_sqrt_m * n.yaw_per_sqrt_m * d * d * d / 3;
  EXPECT_NEAR(pre.covariance()(1, 1), across, 0.03 * across);
}

TEST(WheelPreintegration, TurningOnTheSpot) {
  WheelPreintegration pre(drive(), WheelNoise{});
  for (int k = 0; k < 50; ++k) pre.add(-10, 10);
  const double arc = 500 * 2 * M_PI * 0.1 / 1000;
  const double yaw = 2 * arc / 0.4;
  EXPECT_NEAR(pre.delta().x(), 0.0, 1e-12);
  EXPECT_NEAR(pre.delta().y(), 0.0, 1e-12);
  EXPECT_NEAR(pre.delta().z(), yaw, 1e-12);
  EXPECT_NEAR(pre.turn_rad(), yaw, 1e-12);
  EXPECT_NEAR(pre.distance_m(), 0.0, 1e-12);
  const WheelNoise n;
  EXPECT_NEAR(pre.covariance()(2, 2), n.yaw_per_sqrt_rad * n.yaw_per_sqrt_rad * yaw, 1e-12);
  EXPECT_NEAR(pre.covariance()(0, 0), 0.0, 1e-15);  // no translation, no translation noise
}

TEST(WheelPreintegration, ArcMatchesTheCircle) {
  // Right wheel 12 counts, left 8 per interval: a circle of radius
  // track / 2 (r + l) / (r - l) = 1 m.
  WheelPreintegration pre(drive(), WheelNoise{});
  const int steps = 400;
  for (int k = 0; k < steps; ++k) pre.add(8, 12);
  const double mpt = 2 * M_PI * 0.1 / 1000;
  const double radius = 0.5 * 0.4 * (12 + 8) / (12 - 8);
  const double yaw = steps * (12 - 8) * mpt / 0.4;
  EXPECT_NEAR(pre.delta().z(), yaw, 1e-12);
  // Chords at the mean heading of arcs of 0.006 rad: relative error dyaw^2 / 24.
  EXPECT_NEAR(pre.delta().x(), radius * std::sin(yaw), 1e-5);
  EXPECT_NEAR(pre.delta().y(), radius * (1 - std::cos(yaw)), 1e-5);
  EXPECT_NEAR(pre.distance_m(), radius * yaw, 1e-12);
}

TEST(WheelPreintegration, CovarianceGrowsWithDistanceAndTurn) {
  WheelPreintegration straight(drive(), WheelNoise{}), turning(drive(), WheelNoise{});
  double last_straight = 0, last_turn = 0;
  for (int k = 0; k < 20; ++k) {
    straight.add(50, 50);
    turning.add(-30, 30);
    EXPECT_GT(straight.covariance().trace(), last_straight);
    EXPECT_GT(turning.covariance()(2, 2), last_turn);
    last_straight = straight.covariance().trace();
    last_turn = turning.covariance()(2, 2);
  }
  // Standing still adds nothing.
  const Eigen::Matrix3d before = straight.covariance();
  straight.add(0, 0);
  EXPECT_EQ(straight.covariance(), before);
  // The planar constraint loosens with distance, from the floor.
  const WheelNoise n;
  EXPECT_NEAR(WheelPreintegration(drive(), n).planar_sigma()[0], n.planar_floor, 1e-15);
  EXPECT_NEAR(straight.planar_sigma()[0], n.planar_floor + n.planar_z_per_m * straight.distance_m(), 1e-12);
  EXPECT_NEAR(straight.planar_sigma()[2], n.planar_floor + n.planar_tilt_per_m * straight.distance_m(), 1e-12);
}

TEST(WheelPreintegration, CompositionJacobiansMatchNumeric) {
  const Eigen::Vector3d a(0.7, -0.3, 0.9), b(0.4, 0.2, -0.5);
  Eigen::Matrix3d J_a, J_b, N_a, N_b;
  planar_compose(a, b, &J_a, &J_b);
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(k);
    N_a.col(k) = (planar_compose(a + e, b) - planar_compose(a - e, b)) / (2 * h);
    N_b.col(k) = (planar_compose(a, b + e) - planar_compose(a, b - e)) / (2 * h);
  }
  std::printf("planar composition Jacobians: max error %.3g / %.3g\n", (J_a - N_a).cwiseAbs().maxCoeff(),
              (J_b - N_b).cwiseAbs().maxCoeff());
  EXPECT_LT((J_a - N_a).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((J_b - N_b).cwiseAbs().maxCoeff(), 1e-9);
  ASSERT_GT(std::abs(J_a(0, 2)), 0.1);  // non-trivial
}

TEST(WheelPreintegration, CovarianceMatchesMonteCarlo) {
  // Perturb every interval's increment by noise of the model's variances
  // (isotropic translation sigma_t^2 ds, yaw sigma_m^2 ds + sigma_r^2 |dyaw|)
  // and compose: the spread must match the propagated covariance.
  const sensor::DriveDescription d = drive();
  const WheelNoise n;
  WheelPreintegration pre(d, n);
  const double mpt = 2 * M_PI * d.wheel_radius_m / d.ticks_per_rev;
  std::vector<std::pair<int, int>> counts;
  for (int k = 0; k < 60; ++k) counts.push_back({40 + (k % 7), 60 - (k % 5) * 3});
  for (const auto& c : counts) pre.add(c.first, c.second);
  std::mt19937 rng(11);
  std::normal_distribution<double> n01(0.0, 1.0);
  const int runs = 2000;
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (int run = 0; run < runs; ++run) {
    Eigen::Vector3d delta = Eigen::Vector3d::Zero();
    for (const auto& c : counts) {
      Eigen::Vector3d step = wheel_step(c.first * mpt, c.second * mpt, d.track_m);
      const double ds = std::abs(0.5 * (c.first + c.second) * mpt), dyaw = std::abs(step.z());
      const double st = n.translation_per_sqrt_m * std::sqrt(ds);
      const double sy = std::sqrt(n.yaw_per_sqrt_m * n.yaw_per_sqrt_m * ds + n.yaw_per_sqrt_rad * n.yaw_per_sqrt_rad * dyaw);
      const double n_yaw = n01(rng), n_y = n01(rng), n_x = n01(rng);  // last to first, as pinned
      step += Eigen::Vector3d(st * n_x, st * n_y, sy * n_yaw);
      delta = planar_compose(delta, step);
    }
    const Eigen::Vector3d e = delta - pre.delta();
    S += e * e.transpose();
  }
  S /= runs;
  std::printf("wheel covariance: Monte-Carlo / propagated diagonal %.3f %.3f %.3f\n", S(0, 0) / pre.covariance()(0, 0),
              S(1, 1) / pre.covariance()(1, 1), S(2, 2) / pre.covariance()(2, 2));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(S(k, k) / pre.covariance()(k, k), 1.0, 0.12) << k;
}

TEST(WheelPreintegration, AppendEqualsAddingEverything) {
  WheelPreintegration all(drive(), WheelNoise{}), a(drive(), WheelNoise{}), b(drive(), WheelNoise{});
  for (int k = 0; k < 30; ++k) {
    const int l = 20 + k, r = 35 - k / 2;
    all.add(l, r);
    (k < 12 ? a : b).add(l, r);
  }
  a.append(b);
  EXPECT_LT((a.delta() - all.delta()).norm(), 1e-12);
  EXPECT_LT((a.covariance() - all.covariance()).norm(), 1e-12 * all.covariance().norm());
  EXPECT_NEAR(a.distance_m(), all.distance_m(), 1e-12);
  EXPECT_NEAR(a.turn_rad(), all.turn_rad(), 1e-12);
}

TEST(WheelPreintegration, RejectsABadDrive) {
  sensor::DriveDescription d = drive();
  d.track_m = 0;
  EXPECT_THROW(WheelPreintegration(d, WheelNoise{}), std::invalid_argument);
  d = drive();
  d.ticks_per_rev = 0;
  EXPECT_THROW(WheelPreintegration(d, WheelNoise{}), std::invalid_argument);
  WheelNoise n;
  n.planar_floor = 0;
  EXPECT_THROW(WheelPreintegration(drive(), n), std::invalid_argument);
}

}  // namespace
}  // namespace pvb::slam
