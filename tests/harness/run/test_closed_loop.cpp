// The closed loop's geometry (harness/run/src/closed_loop.cpp): the robot pose a
// SLAM camera pose implies, from the camera's mount measured at the start.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "pvb/run/run.hpp"

namespace pvb::run {
namespace {

// The closed loop turns a SLAM camera pose into the robot pose it steers
// from; the mount measured at the start must give back the robot pose for
// any later pose of the same rigid robot.
TEST(ClosedLoop, RobotPoseFromCameraPoseRoundTrip) {
  // Camera 0.15 m ahead, 0.05 m left, 1.1 m up, yawed 12 deg left and pitched 12 deg down.
  const double yaw_c = 12 * M_PI / 180, pitch = -12 * M_PI / 180;
  Eigen::Matrix3d R_b_c;  // optical: x right, y down, z forward
  const Eigen::Matrix3d R_b_fwd = (Eigen::AngleAxisd(yaw_c, Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()))
                                      .toRotationMatrix();
  R_b_c = R_b_fwd * (Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished();
  const Eigen::Vector3d t_b_c(0.15, 0.05, 1.1);
  auto camera_of = [&](const sim::Pose2d& b) {
    geom::SE3d T_w_b = geom::SE3d::Identity();
    T_w_b.linear() = Eigen::AngleAxisd(b.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T_w_b.translation() = Eigen::Vector3d(b.x, b.y, 0.1);
    geom::SE3d T_b_c = geom::SE3d::Identity();
    T_b_c.linear() = R_b_c;
    T_b_c.translation() = t_b_c;
    return T_w_b * T_b_c;
  };
  const sim::Pose2d start{-0.5, -3.1, 0.3};
  const CameraMount mount = measure_mount(start, camera_of(start));
  EXPECT_NEAR(mount.yaw_offset, yaw_c, 1e-9);
  EXPECT_NEAR(mount.offset_b.x(), 0.15, 1e-9);
  EXPECT_NEAR(mount.offset_b.y(), 0.05, 1e-9);
  for (const sim::Pose2d& b : {sim::Pose2d{4.0, -2.0, -2.5}, sim::Pose2d{10, 3, 3.1}, start}) {
    const sim::Pose2d got = base_from_camera(camera_of(b), mount);
    EXPECT_NEAR(got.x, b.x, 1e-9);
    EXPECT_NEAR(got.y, b.y, 1e-9);
    EXPECT_NEAR(std::remainder(got.yaw - b.yaw, 2 * M_PI), 0.0, 1e-9);
  }
}

}  // namespace
}  // namespace pvb::run
