#include <gtest/gtest.h>

#include "pvb/geometry/se3.hpp"
#include "pvb/geometry/stamped_pose.hpp"

using namespace pvb::geom;

TEST(SE3, ExpLogRoundTrip) {
  const Vec3d w(0.1, -0.4, 0.25);
  EXPECT_LT((so3_log(so3_exp(w)) - w).norm(), 1e-12);
  EXPECT_NEAR(rotation_angle_rad(so3_exp(w)), w.norm(), 1e-12);
}

TEST(SE3, SkewIsCrossProduct) {
  const Vec3d a(1, 2, 3), b(-2, 0.5, 4);
  EXPECT_LT((skew(a) * b - a.cross(b)).norm(), 1e-12);
}

TEST(SE3, BodyToOpticalConvention) {
  // The optical z axis (forward) is the body x axis; optical x (right) is
  // body -y; optical y (down) is body -z.
  const Mat3d R = R_body_optical();
  EXPECT_LT((R * Vec3d::UnitZ() - Vec3d::UnitX()).norm(), 1e-12);
  EXPECT_LT((R * Vec3d::UnitX() + Vec3d::UnitY()).norm(), 1e-12);
  EXPECT_LT((R * Vec3d::UnitY() + Vec3d::UnitZ()).norm(), 1e-12);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
}

TEST(SE3, TumLineUsesCanonicalQuaternionSign) {
  StampedPose p;
  p.t_ns = 1'500'000'000;
  p.T_w_c = make_se3(Quatd(-1, 0, 0, 0), Vec3d(1, 2, 3));
  EXPECT_EQ(format_tum_line(p),
            "1.500000 1.000000000 2.000000000 3.000000000 0.000000000 0.000000000 0.000000000 1.000000000");
}
