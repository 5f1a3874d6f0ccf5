// Gravity error and keyframe tilt drift on synthetic trajectories with a
// known tilt.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <optional>

#include "pvb/eval/gravity.hpp"

using namespace pvb;

namespace {
constexpr double kPi = 3.14159265358979323846;
double rad(double deg) { return deg * kPi / 180.0; }

/// A camera driving along world x, looking along it: optical z = world x,
/// x = -world y (right), y = -world z (down).
geom::Mat3d level_camera() {
  geom::Mat3d R;
  R.col(0) = geom::Vec3d(0, -1, 0);
  R.col(1) = geom::Vec3d(0, 0, -1);
  R.col(2) = geom::Vec3d(1, 0, 0);
  return R;
}

/// Ground truth and an estimate whose pitch (about the camera's x) grows by
/// `pitch_step_deg` and roll (about its z) by `roll_step_deg` per pose.
void drifting(int n, double pitch_step_deg, double roll_step_deg, eval::Trajectory* gt, eval::Trajectory* est) {
  for (int i = 0; i < n; ++i) {
    const std::int64_t t_ns = 1'000'000'000 + i * 100'000'000LL;
    const geom::SE3d T_true = geom::make_se3(level_camera(), geom::Vec3d(0.1 * i, 0, 0.5));
    const geom::Mat3d R_err = (Eigen::AngleAxisd(rad(pitch_step_deg * i), geom::Vec3d::UnitX()) *
                               Eigen::AngleAxisd(rad(roll_step_deg * i), geom::Vec3d::UnitZ()))
                                  .toRotationMatrix();
    gt->poses.push_back({t_ns, T_true});
    est->poses.push_back({t_ns, geom::make_se3(level_camera() * R_err, T_true.translation())});
  }
}
}  // namespace

TEST(Gravity, APitchDriftIsTheGravityErrorInAGravityAlignedMap) {
  eval::Trajectory gt, est;
  drifting(11, 0.5, 0.0, &gt, &est);  // 0, 0.5, ..., 5 degrees
  const eval::GravityError g = eval::gravity_error(gt, est, geom::Vec3d(0, 0, -2), "gravity_aligned");
  ASSERT_EQ(g.angle_deg.size(), 11u);
  EXPECT_NEAR(g.angle_deg[4], 2.0, 1e-9);
  EXPECT_NEAR(g.median_deg, 2.5, 1e-9);
  EXPECT_NEAR(g.p95_deg, 4.75, 1e-9);  // between 4.5 and 5
  EXPECT_NEAR(g.final_deg, 5.0, 1e-9);
  EXPECT_NEAR(g.t_s.back(), 1.0, 1e-12);
  EXPECT_EQ(g.map_frame, "gravity_aligned");
}

TEST(Gravity, TheCoresOwnGravityCountsWhereItHasOne) {
  // A map tilted 3 degrees about world y: its -z is 3 degrees off, but a
  // core that estimated gravity in that map is judged by its estimate.
  eval::Trajectory gt, est;
  drifting(4, 0.0, 0.0, &gt, &est);
  const geom::Mat3d R_map_w = Eigen::AngleAxisd(rad(3.0), geom::Vec3d::UnitY()).toRotationMatrix();
  for (auto& p : est.poses) p.T_w_c.linear() = R_map_w * p.T_w_c.linear();
  eval::GravityEstimates g_map;
  const geom::Vec3d true_down_map = R_map_w * geom::Vec3d(0, 0, -9.81);
  g_map[est.poses[2].t_ns + 400'000] = true_down_map;  // within a millisecond: a trajectory file's rounding
  g_map[est.poses[3].t_ns] = Eigen::AngleAxisd(rad(0.5), geom::Vec3d::UnitY()) * true_down_map;
  const eval::GravityError g = eval::gravity_error(gt, est, geom::Vec3d(0, 0, -1), "gravity_aligned", g_map);
  ASSERT_EQ(g.angle_deg.size(), 4u);
  EXPECT_NEAR(g.angle_deg[0], 3.0, 1e-9);  // no estimate yet: the map's -z
  EXPECT_NEAR(g.angle_deg[1], 3.0, 1e-9);
  EXPECT_NEAR(g.angle_deg[2], 0.0, 1e-6);
  EXPECT_NEAR(g.angle_deg[3], 0.5, 1e-9);
}

TEST(Gravity, EstimatesRecordedWhereTheyChangeHoldUntilTheNextChange) {
  // Frames 0-1 untrusted, 2-4 one estimate, 5-6 a refined one, 7-8 none
  // again (a provisional map): three changes, so three entries, and each
  // frame judged by the estimate the core held for it.
  eval::Trajectory gt, est;
  drifting(9, 0.0, 0.0, &gt, &est);
  const geom::Mat3d R_map_w = Eigen::AngleAxisd(rad(3.0), geom::Vec3d::UnitY()).toRotationMatrix();
  for (auto& p : est.poses) p.T_w_c.linear() = R_map_w * p.T_w_c.linear();
  const geom::Vec3d first = R_map_w * geom::Vec3d(0, 0, -9.81);
  const geom::Vec3d refined = Eigen::AngleAxisd(rad(1.0), geom::Vec3d::UnitX()) * first;
  eval::GravityEstimates recorded;
  for (int i = 0; i < 9; ++i) {
    std::optional<geom::Vec3d> g;
    if (i >= 2 && i <= 4) g = first;
    if (i == 5 || i == 6) g = refined;
    eval::record_gravity(&recorded, est.poses[i].t_ns, g);
  }
  EXPECT_EQ(recorded.size(), 3u);
  const eval::GravityError g =
      eval::gravity_error(gt, est, geom::Vec3d(0, 0, -1), "gravity_aligned", recorded);
  // The refined estimate is off the true down by the angle between the two.
  const double refined_deg = std::atan2(first.cross(refined).norm(), first.dot(refined)) * 180.0 / kPi;
  const double expected[] = {3,           3,           0, 0, 0,
                             refined_deg, refined_deg, 3, 3};  // untrusted or none: the map's -z
  ASSERT_EQ(g.angle_deg.size(), 9u);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(g.angle_deg[i], expected[i], 1e-6) << "frame " << i;
}

TEST(Gravity, AMapInTheFirstCameraFrameIsNinetyDegreesOffForALevelCamera) {
  eval::Trajectory gt, est;
  drifting(3, 0.0, 0.0, &gt, &est);
  for (auto& p : est.poses) p.T_w_c.linear() = geom::Mat3d::Identity();  // map = first camera
  const eval::GravityError g = eval::gravity_error(gt, est, geom::Vec3d(0, 0, -1), "first_camera");
  EXPECT_NEAR(g.median_deg, 90.0, 1e-9);
}

TEST(Tilt, AKnownPitchAndRollDriftGivesItsSlopeAndSign) {
  eval::Trajectory gt, est;
  drifting(21, 0.1, -0.05, &gt, &est);
  const eval::TiltDrift t = eval::tilt_drift(gt, est, eval::Sim3Transform{});
  ASSERT_EQ(t.pitch_deg.size(), 21u);
  EXPECT_NEAR(t.pitch_deg[10], 1.0, 1e-3);  // the rotation vector of Rx * Rz: second order off
  EXPECT_NEAR(t.roll_deg[10], -0.5, 1e-3);
  EXPECT_NEAR(t.pitch_slope_deg_per_kf, 0.1, 1e-4);
  EXPECT_NEAR(t.roll_slope_deg_per_kf, -0.05, 1e-4);
  EXPECT_EQ(t.pitch_slope_sign, 1);
  EXPECT_EQ(t.roll_slope_sign, -1);
  EXPECT_NEAR(t.pitch_mean_deg, 1.0, 1e-3);
}

TEST(Tilt, PositivePitchTurnsTheOpticalAxisUp) {
  const geom::Mat3d R_true = level_camera();
  const geom::Mat3d R_est = R_true * Eigen::AngleAxisd(rad(2.0), geom::Vec3d::UnitX()).toRotationMatrix();
  EXPECT_GT((R_est.col(2)).z(), 0.0);  // the estimated optical axis points up in the world
  const auto [pitch, roll] = eval::pitch_roll_error_deg(R_true, R_est);
  EXPECT_NEAR(pitch, 2.0, 1e-9);
  EXPECT_NEAR(roll, 0.0, 1e-9);
}

TEST(Tilt, SlopeOfAFewValues) {
  EXPECT_EQ(eval::slope_per_index({}), 0.0);
  EXPECT_EQ(eval::slope_per_index({3.0}), 0.0);
  EXPECT_NEAR(eval::slope_per_index({1, 3, 5, 7}), 2.0, 1e-12);
}
