// WheelCalibrator: recovers each wheel's radius and the track from
// intervals of straights and turns, stays as described for what the drive
// has not shown it, refuses an interval that slipped, and goes on from a
// saved fit as if it had never stopped.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "pvb/slam/inertial/wheel_calibration.hpp"

namespace pvb::slam {
namespace {

constexpr double kTrackM = 0.42;

/// Feeds intervals of the described arcs (left, right) with the base's
/// true motion for calibration `c`, plus Gaussian noise of the map's poses.
struct Drive {
  WheelCalibration c;
  double arc_sigma_m = 0, yaw_sigma_rad = 0;
  std::mt19937 rng{7};
  int refused = 0;

  void interval(WheelCalibrator* cal, double left_m, double right_m) {
    std::normal_distribution<double> n(0, 1);
    const double arc = 0.5 * (c.left_scale * left_m + c.right_scale * right_m) + arc_sigma_m * n(rng);
    const double yaw = (c.right_scale * right_m - c.left_scale * left_m) / (kTrackM * c.track_scale) +
                       yaw_sigma_rad * n(rng);
    if (!cal->add(left_m, right_m, arc, yaw)) ++refused;
  }
  /// Straight for `metres` in steps of 0.25 m, then a U-turn of radius
  /// `radius_m` (both wheels forward) in steps of 0.25 m of the centre.
  void aisle(WheelCalibrator* cal, double metres, double radius_m) {
    for (double d = 0; d < metres; d += 0.25) interval(cal, 0.25, 0.25);
    const double step_rad = 0.25 / radius_m;
    for (double a = 0; a < M_PI; a += step_rad)
      interval(cal, step_rad * (radius_m - 0.5 * kTrackM), step_rad * (radius_m + 0.5 * kTrackM));
  }
};

TEST(WheelCalibrator, RecoversTheRadiiAndTheTrackFromAislesAndUTurns) {
  // Radii 1 % apart about a 0.3 % small mean, the track 8 % wide (tyres
  // scrub in a turn), the map's poses 2 mm and 1 mrad off per interval.
  // Bounds are 3 sigma of the fit: the mean radius 2 mm / sqrt(sum m^2 = 45
  // m^2) = 3e-4; the ratio 2 x 1 mrad x 0.42 m / sqrt(sum (L + R)^2 = 180 m^2)
  // = 6e-5; the track from four U-turns, 1 mrad in each of 112 turn rows.
  Drive drive{{0.992, 1.002, 1.08}, 0.002, 0.001};
  WheelCalibrator cal(kTrackM);
  for (int k = 0; k < 4; ++k) drive.aisle(&cal, 40, 2.2);
  ASSERT_TRUE(cal.radii_known());
  ASSERT_TRUE(cal.track_known());
  const WheelCalibration e = cal.estimate();
  EXPECT_NEAR(e.left_scale, 0.992, 1e-3);
  EXPECT_NEAR(e.right_scale, 1.002, 1e-3);
  // The ratio is what a straight's heading needs: to 2e-4 (a heading
  // error of 0.5 mrad a metre at this track).
  EXPECT_NEAR(e.right_scale / e.left_scale, 1.002 / 0.992, 2e-4);
  EXPECT_NEAR(e.track_scale, 1.08, 0.005);
  EXPECT_EQ(drive.refused, 0);
  EXPECT_EQ(cal.intervals(), static_cast<int>(4 * (160 + std::ceil(M_PI * 2.2 / 0.25))));
}

TEST(WheelCalibrator, StaysAsDescribedForWhatTheDriveHasNotShown) {
  Drive drive{{0.99, 1.01, 1.1}};
  WheelCalibrator cal(kTrackM);
  for (int k = 0; k < 40; ++k) drive.interval(&cal, 0.25, 0.25);  // 10 m straight: under min_rolled_m
  EXPECT_FALSE(cal.radii_known());
  EXPECT_EQ(cal.estimate(), WheelCalibration{});
  for (int k = 0; k < 60; ++k) drive.interval(&cal, 0.25, 0.25);  // 25 m in all, still no turn
  ASSERT_TRUE(cal.radii_known());
  EXPECT_FALSE(cal.track_known());
  const WheelCalibration e = cal.estimate();
  EXPECT_EQ(e.track_scale, 1.0);
  // Without a turn the ratio is read against the described track: a
  // straight's turn is (r - l) / (k b), so rho comes out k times small.
  EXPECT_NEAR(e.right_scale / e.left_scale, 1 + (1.01 / 0.99 - 1) / 1.1, 2e-4);
  EXPECT_NEAR(0.5 * (e.left_scale + e.right_scale), 1.0, 1e-3);
}

TEST(WheelCalibrator, RefusesAnIntervalThatSlipped) {
  Drive drive{{1.0, 1.0, 1.05}, 0.002, 0.0005};
  WheelCalibrator cal(kTrackM);
  drive.aisle(&cal, 30, 2.0);
  drive.aisle(&cal, 30, 2.0);
  const WheelCalibration before = cal.estimate();
  // The left wheel spins 0.3 m on wet ground while the robot moves 0.25 m straight.
  EXPECT_FALSE(cal.add(0.55, 0.25, 0.25, 0.0));
  EXPECT_EQ(cal.refused(), 1);
  EXPECT_EQ(cal.estimate(), before);
  EXPECT_FALSE(cal.add(0.25, 0.25, std::nan(""), 0.0));
  EXPECT_NEAR(cal.estimate().track_scale, 1.05, 0.005);
  EXPECT_THROW(WheelCalibrator(0.0), std::invalid_argument);
}

// A calibrator resumed from another's fit (as a map file carries it) gives
// exactly what one calibrator fed every interval gives, and a fit taken
// with another described track, or not finite, is not taken.
TEST(WheelCalibrator, GoesOnFromASavedFitAsIfItHadNeverStopped) {
  Drive whole{{0.995, 1.003, 1.06}, 0.002, 0.001}, first = whole;
  WheelCalibrator all(kTrackM), before(kTrackM);
  for (int k = 0; k < 2; ++k) {
    whole.aisle(&all, 30, 2.2);
    first.aisle(&before, 30, 2.2);
  }
  const WheelFit saved = before.fit();
  EXPECT_EQ(saved.described_track_m, kTrackM);
  EXPECT_EQ(saved.intervals, before.intervals());
  WheelCalibrator after(kTrackM);
  ASSERT_TRUE(after.resume(saved));
  EXPECT_EQ(after.fit().calibration, saved.calibration);
  for (int k = 0; k < 2; ++k) {
    whole.aisle(&all, 30, 2.2);
    first.aisle(&after, 30, 2.2);
  }
  EXPECT_EQ(after.estimate(), all.estimate());
  EXPECT_EQ(after.intervals(), all.intervals());
  EXPECT_EQ(after.rolled_m(), all.rolled_m());
  EXPECT_TRUE(after.fit().sums == all.fit().sums);

  WheelCalibrator wider(kTrackM + 0.01);
  EXPECT_FALSE(wider.resume(saved));
  EXPECT_EQ(wider.intervals(), 0);
  WheelFit broken = saved;
  broken.sums.am = std::nan("");
  WheelCalibrator fresh(kTrackM);
  EXPECT_FALSE(fresh.resume(broken));
  EXPECT_EQ(fresh.estimate(), WheelCalibration{});
}

}  // namespace
}  // namespace pvb::slam
