// The inertial report's gravity against the ground truth
// (gravity_error_at_deg): the figure the map's own tilt cannot give, which
// sees a map levelled upside down.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "pvb/run/inertial_eval.hpp"

namespace pvb::run {
namespace {

/// A level camera looking along the world's x (optical z forward, y down).
geom::Mat3d level_camera() {
  geom::Mat3d R_w_c;
  R_w_c.col(0) = geom::Vec3d(0, -1, 0);  // x right
  R_w_c.col(1) = geom::Vec3d(0, 0, -1);  // y down
  R_w_c.col(2) = geom::Vec3d(1, 0, 0);   // z forward
  return R_w_c;
}

eval::Trajectory three_poses(const geom::Mat3d& R_w_c, std::int64_t t_ns) {
  eval::Trajectory t;
  for (int i = 0; i < 3; ++i)
    t.poses.push_back({t_ns + i * 33'333'333LL, geom::make_se3(R_w_c, geom::Vec3d(0.1 * i, 0, 0))});
  return t;
}

}  // namespace

TEST(GravityTruth, AMapLevelledUpsideDownIsOneHundredEightyDegreesOff) {
  const geom::Mat3d R_true = level_camera();
  const eval::Trajectory gt = three_poses(R_true, 0);
  // The map's first camera as the core levelled it from a flipped
  // accelerometer: its y axis up (+0.989 map-z); the core's gravity is the
  // map's -z, so against itself it is 0 degrees off.
  const geom::Mat3d R_flip = Eigen::AngleAxisd(M_PI, geom::Vec3d::UnitX()).toRotationMatrix() * R_true;
  const Eigen::Vector3d g_map(0, 0, -9.81);
  EXPECT_NEAR(gravity_tilt_deg(g_map), 0.0, 1e-9);
  const eval::GravityEstimates estimates = {{33'333'333LL, g_map}};
  const std::optional<double> flipped =
      gravity_error_at_deg(gt, three_poses(R_flip, 0), geom::Vec3d(0, 0, -1), estimates, 33'333'333LL);
  ASSERT_TRUE(flipped.has_value());
  EXPECT_NEAR(*flipped, 180.0, 1e-6);
  const std::optional<double> right =
      gravity_error_at_deg(gt, three_poses(R_true, 0), geom::Vec3d(0, 0, -1), estimates, 33'333'333LL);
  ASSERT_TRUE(right.has_value());
  EXPECT_NEAR(*right, 0.0, 1e-6);
  // No pose at or after the time: no figure.
  EXPECT_FALSE(
      gravity_error_at_deg(gt, three_poses(R_true, 0), geom::Vec3d(0, 0, -1), estimates, 5'000'000'000LL));
}

}  // namespace pvb::run
