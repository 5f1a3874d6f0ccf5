#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "pvb/scenes/tracker.hpp"

using namespace pvb::scenes;

namespace {

// pvlib prints its expected rotations to 4 or more decimals and computes
// them with the same equations; the NREL report's table has 3 decimals and
// its axis and cross-axis tilts are given to 3 decimals.
constexpr double kPvlibTolDeg = 1e-3;
constexpr double kReportTolDeg = 0.01;

SingleAxisTracker tracker(double axis_tilt_deg, double axis_azimuth_deg, double max_angle_deg, bool backtrack,
                          double gcr = 2.0 / 7.0, double cross_axis_tilt_deg = 0.0) {
  SingleAxisTracker t;
  t.axis_tilt_deg = axis_tilt_deg;
  t.axis_azimuth_deg = axis_azimuth_deg;
  t.max_angle_deg = max_angle_deg;
  t.backtrack = backtrack;
  t.gcr = gcr;
  t.cross_axis_tilt_deg = cross_axis_tilt_deg;
  return t;
}

double rotation(double zenith_deg, double azimuth_deg, const SingleAxisTracker& t) {
  const auto r = tracker_rotation(zenith_deg, azimuth_deg, t);
  EXPECT_TRUE(r.has_value()) << "zenith " << zenith_deg << " azimuth " << azimuth_deg;
  return r ? r->rotation_deg : NAN;
}

}  // namespace

// pvlib tests/test_tracking.py: test_solar_noon, test_azimuth_north_south,
// test_axis_azimuth (horizontal axis, max_angle 90, gcr 2/7).
TEST(Tracker, PvlibHorizontalAxis) {
  EXPECT_NEAR(rotation(10, 180, tracker(0, 0, 90, true)), 0.0, kPvlibTolDeg);
  EXPECT_NEAR(rotation(60, 90, tracker(0, 180, 90, true)), -60.0, kPvlibTolDeg);
  EXPECT_NEAR(rotation(60, 90, tracker(0, 0, 90, true)), 60.0, kPvlibTolDeg);
  EXPECT_NEAR(rotation(30, 90, tracker(0, 90, 90, true)), 0.0, kPvlibTolDeg);
  EXPECT_NEAR(rotation(30, 90, tracker(0, 180, 90, true)), -30.0, kPvlibTolDeg);
  EXPECT_NEAR(rotation(30, 180, tracker(0, 90, 90, true)), 30.0, kPvlibTolDeg);
}

// pvlib tests/test_tracking.py, test_max_angle: zenith 60, azimuth 90, axis
// azimuth 0, max_angle 45: 45 (the ideal 60 is clipped).
TEST(Tracker, PvlibMaxAngle) {
  const auto r = tracker_rotation(60, 90, tracker(0, 0, 45, true));
  ASSERT_TRUE(r);
  EXPECT_NEAR(r->rotation_deg, 45.0, kPvlibTolDeg);
  EXPECT_NEAR(r->ideal_deg, 60.0, kPvlibTolDeg);
  EXPECT_TRUE(r->clipped);
  EXPECT_FALSE(r->backtracking);
}

// pvlib tests/test_tracking.py, test_backtrack: zenith 80, azimuth 90, axis
// azimuth 0, gcr 2/7: 80 without backtracking, 27.4283 with it
// (80 - acos(3.5 cos 80) by Anderson and Mikofski 2020, eq. 14).
TEST(Tracker, PvlibBacktrack) {
  EXPECT_NEAR(rotation(80, 90, tracker(0, 0, 90, false)), 80.0, kPvlibTolDeg);
  const auto r = tracker_rotation(80, 90, tracker(0, 0, 90, true));
  ASSERT_TRUE(r);
  EXPECT_NEAR(r->rotation_deg, 27.4283, kPvlibTolDeg);
  EXPECT_NEAR(r->ideal_deg, 80.0, kPvlibTolDeg);
  EXPECT_TRUE(r->backtracking);
  EXPECT_FALSE(r->clipped);
}

// pvlib tests/test_tracking.py, test_axis_tilt: zenith 30, azimuth 135, axis
// tilt 30: -20.88121 for axis azimuth 180, 31.6655 for axis azimuth 0; and
// test_low_sun_angles: zenith 80, azimuth 338, axis tilt 30, axis azimuth
// 180, max_angle 60, gcr 0.35: 60.
TEST(Tracker, PvlibTiltedAxis) {
  EXPECT_NEAR(rotation(30, 135, tracker(30, 180, 90, true)), -20.88121, kPvlibTolDeg);
  EXPECT_NEAR(rotation(30, 135, tracker(30, 0, 90, true)), 31.6655, kPvlibTolDeg);
  EXPECT_NEAR(rotation(80, 338, tracker(30, 180, 60, true, 0.35)), 60.0, kPvlibTolDeg);
}

// pvlib tests/test_tracking.py, test_horizon_flat and test_horizon_tilted
// (backtrack off, max_angle 180): below the horizon there is no rotation;
// a vertical axis (tilt 90) pointing south, sun at zenith 45: azimuth 180
// gives 0, azimuth 359 gives 179, azimuth 0 gives -180 (the same as 180).
TEST(Tracker, PvlibHorizon) {
  EXPECT_FALSE(tracker_rotation(100, 0, tracker(0, 180, 180, false)).has_value());
  EXPECT_FALSE(tracker_rotation(90.01, 180, tracker(0, 180, 180, false)).has_value());
  EXPECT_NEAR(rotation(45, 180, tracker(0, 180, 180, false)), 0.0, kPvlibTolDeg);
  EXPECT_NEAR(rotation(45, 180, tracker(90, 180, 180, false)), 0.0, kPvlibTolDeg);
  EXPECT_NEAR(rotation(45, 359, tracker(90, 180, 180, false)), 179.0, kPvlibTolDeg);
  EXPECT_NEAR(std::abs(rotation(45, 0, tracker(90, 180, 180, false))), 180.0, kPvlibTolDeg);
}

// Anderson and Mikofski, "Slope-Aware Backtracking for Single-Axis
// Trackers", NREL/TP-5K00-76626 (2020), validation table, as in pvlib
// tests/test_tracking.py, test_slope_aware_backtracking: slope 10 degree
// facing south, axis azimuth 195, axis tilt 9.666, cross-axis tilt -2.576,
// gcr 0.5, max_angle 90; 2019-01-01 08:00..17:00 UTC-5.
TEST(Tracker, SlopeAwareBacktrackingReportTable) {
  struct Row {
    double apparent_elevation_deg, azimuth_deg, true_tracking_deg, backtracking_deg;
  };
  const Row rows[] = {
      {2.404287, 122.79177, -84.440, -10.899},   {11.263058, 133.288729, -72.604, -25.747},
      {18.733558, 145.285552, -59.861, -59.861}, {24.109076, 158.939435, -45.578, -45.578},
      {26.810735, 173.931802, -28.764, -28.764}, {26.482495, 189.371536, -8.475, -8.475},
      {23.170447, 204.13681, 15.120, 15.120},    {17.296785, 217.446538, 39.562, 39.562},
      {9.461862, 229.102218, 61.587, 32.339},    {0.524817, 239.330401, 79.530, 5.490},
  };
  const SingleAxisTracker backtracking = tracker(9.666, 195, 90, true, 0.5, -2.576);
  const SingleAxisTracker true_tracking = tracker(9.666, 195, 90, false, 0.5, -2.576);
  for (const Row& row : rows) {
    SCOPED_TRACE(row.azimuth_deg);
    const double zenith = 90.0 - row.apparent_elevation_deg;
    EXPECT_NEAR(rotation(zenith, row.azimuth_deg, backtracking), row.backtracking_deg, kReportTolDeg);
    EXPECT_NEAR(rotation(zenith, row.azimuth_deg, true_tracking), row.true_tracking_deg, kReportTolDeg);
  }
}

// pvlib tests/test_tracking.py, test__unit_normal: (axis azimuth, axis tilt,
// rotation) -> unit normal in ENU.
TEST(Tracker, NormalMatchesPvlibUnitNormal) {
  struct Case {
    double azimuth, tilt, theta;
    Eigen::Vector3d normal;
  };
  const Case cases[] = {
      {180, 45, 45, {-std::sqrt(2.0) / 2, -0.5, 0.5}},
      {0, 30, 0, {0, 0.5, 0.8660254}},
      {90, 30, 0, {0.5, 0, 0.8660254}},
      {180, 0, -30, {0.5, 0, 0.8660254}},
      {180, 0, 30, {-0.5, 0, 0.8660254}},
      {180, 0, -90, {1, 0, 0}},
      {0, 30, 30, {0.5, 0.4330127, 0.75}},
      {90, 30, 30, {0.4330127, -0.5, 0.75}},
      {270, 30, 30, {-0.4330127, 0.5, 0.75}},
  };
  for (const Case& c : cases) {
    SingleAxisTracker t;
    t.axis_azimuth_deg = c.azimuth, t.axis_tilt_deg = c.tilt;
    EXPECT_LT((tracker_normal_enu(c.theta, t) - c.normal).norm(), 1e-6)
        << c.azimuth << " " << c.tilt << " " << c.theta;
  }
}

// What a scene builder does: turn the flat panel (rotation 0) about the axis
// vector, right-handed, by the rotation; it must land on the normal.
TEST(Tracker, RotationIsRightHandedAboutTheAxisVector) {
  for (double azimuth : {0.0, 90.0, 180.0, 200.0}) {
    for (double tilt : {0.0, 20.0, -15.0}) {
      SingleAxisTracker t;
      t.axis_azimuth_deg = azimuth, t.axis_tilt_deg = tilt;
      const Eigen::Vector3d axis = tracker_axis_enu(t);
      EXPECT_NEAR(axis.norm(), 1.0, 1e-12);
      EXPECT_NEAR(axis.dot(tracker_normal_enu(0, t)), 0.0, 1e-12);
      EXPECT_GE(tracker_normal_enu(0, t).z(), 0.0);  // flat: facing up
      for (double theta : {-50.0, 10.0, 35.0}) {
        const Eigen::Vector3d turned = Eigen::AngleAxisd(theta * M_PI / 180, axis) * tracker_normal_enu(0, t);
        EXPECT_LT((turned - tracker_normal_enu(theta, t)).norm(), 1e-12)
            << azimuth << " " << tilt << " " << theta;
      }
    }
  }
  SingleAxisTracker south;  // axis_azimuth 180, tilt 0: the axis points south
  EXPECT_LT((tracker_axis_enu(south) - Eigen::Vector3d(0, -1, 0)).norm(), 1e-12);
}

TEST(Tracker, AfternoonPanelsFaceWestOnANorthSouthAxis) {
  const SingleAxisTracker t = tracker(0, 180, 55, true);
  const double r = rotation(40, 250, t);  // afternoon sun in the south-west
  EXPECT_GT(r, 0.0);
  EXPECT_LT(tracker_normal_enu(r, t).x(), 0.0);  // normal towards -east = west
  EXPECT_LT(rotation(40, 110, t), 0.0);          // morning: east
}

TEST(Tracker, MorningAndAfternoonAreSymmetric) {
  for (bool backtrack : {false, true}) {
    const SingleAxisTracker t = tracker(0, 180, 55, backtrack, 0.4);
    for (double zenith = 0; zenith <= 89; zenith += 7) {
      for (double d = 5; d < 180; d += 11) {
        EXPECT_NEAR(rotation(zenith, 180 - d, t), -rotation(zenith, 180 + d, t), 1e-9) << zenith << " " << d;
      }
    }
  }
}

// Over the sky: the rotation stays within max_angle, backtracking only turns
// back towards flat, and the ideal angle is the best one: the sun lies in the
// plane of the normal and the axis, and turning either way lowers the cosine
// of incidence.
TEST(Tracker, RotationIsBoundedAndIdealFacesTheSun) {
  for (double tilt : {0.0, 10.0}) {
    const SingleAxisTracker t = tracker(tilt, 170, 55, true, 0.45);
    for (double zenith = 0; zenith <= 90; zenith += 5) {
      for (double az = 0; az < 360; az += 10) {
        const auto r = tracker_rotation(zenith, az, t);
        ASSERT_TRUE(r);
        EXPECT_LE(std::abs(r->rotation_deg), t.max_angle_deg + 1e-12);
        if (!r->sun_behind) {
          EXPECT_LE(std::abs(r->rotation_deg), std::abs(r->ideal_deg) + 1e-9);
        }
        const Eigen::Vector3d s = sun_direction_enu(zenith, az);
        const Eigen::Vector3d n = tracker_normal_enu(r->ideal_deg, t);
        EXPECT_NEAR(s.dot(tracker_axis_enu(t).cross(n)), 0.0, 1e-9);
        EXPECT_GE(s.dot(n) + 1e-12, s.dot(tracker_normal_enu(r->ideal_deg + 1, t)));
        EXPECT_GE(s.dot(n) + 1e-12, s.dot(tracker_normal_enu(r->ideal_deg - 1, t)));
      }
    }
  }
}

// Backtracking keeps the rows out of each other's shadow: seen along the
// sun's rays, row 0 (width gcr * pitch, turned to the rotation) and row 1
// (one pitch across, horizontal offset) must not overlap, within 1e-9 of the
// pitch where backtracking puts the shadow's edge exactly on the next row.
// Without backtracking low sun does make them overlap.
TEST(Tracker, BacktrackingAvoidsRowToRowShade) {
  const double gcr = 0.4, pitch_m = 5.0, width_m = gcr * pitch_m;
  int shaded_without_backtracking = 0;
  for (bool backtrack : {true, false}) {
    const SingleAxisTracker t = tracker(0, 180, 90, backtrack, gcr);
    const Eigen::Vector3d axis = tracker_axis_enu(t);
    const Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(axis).normalized() * -1.0;  // tracker x
    for (double zenith = 0; zenith < 90; zenith += 3) {
      for (double az = 0; az < 360; az += 15) {
        const auto r = tracker_rotation(zenith, az, t);
        ASSERT_TRUE(r);
        const Eigen::Vector3d s = sun_direction_enu(zenith, az);
        const Eigen::Vector3d n = tracker_normal_enu(r->rotation_deg, t);
        const Eigen::Vector3d module_dir = axis.cross(n);  // across the module, in its plane
        const Eigen::Vector3d perp = s.cross(axis);        // across the rays, in the cross-section
        if (perp.norm() < 1e-9) continue;                  // sun along the axis: no row shades another
        const double half_extent = 0.5 * width_m * std::abs(module_dir.dot(perp.normalized()));
        const double centre_gap = std::abs((pitch_m * across).dot(perp.normalized()));
        const bool shaded = 2 * half_extent > centre_gap + 1e-9 * pitch_m;
        if (backtrack) {
          EXPECT_FALSE(shaded) << "zenith " << zenith << " azimuth " << az;
        }
        if (!backtrack && shaded) ++shaded_without_backtracking;
      }
    }
  }
  EXPECT_GT(shaded_without_backtracking, 0);
}

TEST(Tracker, InvalidTrackerHasAReason) {
  EXPECT_FALSE(tracker_error(SingleAxisTracker{}).has_value());
  SingleAxisTracker t;
  t.gcr = 1.5;
  EXPECT_EQ(tracker_error(t).value_or(""), "ground coverage ratio 1.5 is outside (0, 1]");
  EXPECT_FALSE(tracker_rotation(30, 120, t).has_value());
  t = SingleAxisTracker{};
  t.max_angle_deg = 0;
  EXPECT_EQ(tracker_error(t).value_or(""), "max angle 0 deg is outside (0, 180]");
  t = SingleAxisTracker{};
  t.axis_tilt_deg = 95;
  EXPECT_EQ(tracker_error(t).value_or(""), "axis tilt 95 deg is outside [-90, 90]");
}
