#include <gtest/gtest.h>

#include "pvb/geometry/pinhole.hpp"

using pvb::geom::PinholeIntrinsics;

TEST(Pinhole, ProjectUnprojectRoundTrip) {
  const PinholeIntrinsics cam{520.9, 521.0, 325.1, 249.7, 640, 480};
  const Eigen::Vector3d p(0.3, -0.2, 2.5);
  const auto uv = cam.project(p);
  ASSERT_TRUE(uv.has_value());
  EXPECT_NEAR(uv->x(), 520.9 * 0.3 / 2.5 + 325.1, 1e-12);
  EXPECT_LT((cam.unproject(uv->x(), uv->y(), 2.5) - p).norm(), 1e-12);
  EXPECT_FALSE(cam.project({0, 0, -1}).has_value());
}

TEST(Pinhole, InImageUsesPixelCentreConvention) {
  const PinholeIntrinsics cam;
  EXPECT_TRUE(cam.in_image({0, 0}));
  EXPECT_TRUE(cam.in_image({639.4, 479.4}));
  EXPECT_FALSE(cam.in_image({639.6, 10}));
  EXPECT_FALSE(cam.in_image({-0.6, 10}));
}
