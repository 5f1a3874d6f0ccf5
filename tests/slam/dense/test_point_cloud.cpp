// Back-projection against known intrinsics, the voxel-grid filter (counts,
// averaging, determinism) and rigid transformation of clouds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <tuple>

#include "pvb/common/error.hpp"
#include "pvb/slam/dense/point_cloud.hpp"

namespace {

using pvb::slam::dense::back_project;
using pvb::slam::dense::BackProjectionParams;
using pvb::slam::dense::CloudPoint;
using pvb::slam::dense::PointCloud;
using pvb::slam::dense::transform;
using pvb::slam::dense::voxel_filter;

pvb::geom::PinholeIntrinsics camera() {
  pvb::geom::PinholeIntrinsics K;
  K.fx = 500.0;
  K.fy = 400.0;
  K.cx = 10.25;
  K.cy = 7.75;
  K.width = 20;
  K.height = 15;
  return K;
}

TEST(BackProjection, EveryPixelMatchesThePinholeModel) {
  const auto K = camera();
  cv::Mat depth(K.height, K.width, CV_32FC1), rgb(K.height, K.width, CV_8UC3);
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      depth.at<float>(v, u) = 1.0f + 0.1f * static_cast<float>(u) + 0.01f * static_cast<float>(v);
      rgb.at<cv::Vec3b>(v, u) = cv::Vec3b(static_cast<unsigned char>(u), static_cast<unsigned char>(v), 200);
    }
  BackProjectionParams p;
  p.stride_px = 1;
  p.min_depth_m = 0.0;
  p.max_depth_m = 100.0;
  const PointCloud cloud = back_project(rgb, depth, K, p);
  ASSERT_EQ(cloud.size(), static_cast<std::size_t>(K.width * K.height));
  for (const CloudPoint& q : cloud) {
    // the colour says which pixel it came from
    const int u = q.r, v = q.g;
    EXPECT_EQ(q.b, 200);
    const double z = depth.at<float>(v, u);
    EXPECT_FLOAT_EQ(q.z, static_cast<float>(z));
    EXPECT_NEAR(q.x, (u - 10.25) * z / 500.0, 1e-6);
    EXPECT_NEAR(q.y, (v - 7.75) * z / 400.0, 1e-6);
    // and it projects back onto that pixel
    const auto uv = K.project(Eigen::Vector3d(q.x, q.y, q.z));
    ASSERT_TRUE(uv);
    EXPECT_NEAR(uv->x(), u, 1e-4);
    EXPECT_NEAR(uv->y(), v, 1e-4);
  }
}

TEST(BackProjection, StrideAndDepthLimits) {
  const auto K = camera();
  cv::Mat depth(K.height, K.width, CV_32FC1, cv::Scalar(2.0f)),
      rgb(K.height, K.width, CV_8UC3, cv::Scalar(1, 2, 3));
  depth.at<float>(0, 0) = 0.0f;   // invalid
  depth.at<float>(0, 3) = 0.05f;  // too close
  depth.at<float>(3, 3) = 9.0f;   // too far
  depth.at<float>(6, 6) = std::numeric_limits<float>::quiet_NaN();
  depth.at<float>(1, 1) = 0.05f;  // skipped by the stride anyway
  BackProjectionParams p;
  p.stride_px = 3;
  p.min_depth_m = 0.1;
  p.max_depth_m = 4.0;
  const PointCloud cloud = back_project(rgb, depth, K, p);
  const std::size_t sampled = static_cast<std::size_t>(((K.width + 2) / 3) * ((K.height + 2) / 3));  // 7 x 5
  EXPECT_EQ(cloud.size(), sampled - 4);
  for (const CloudPoint& q : cloud) {
    EXPECT_FLOAT_EQ(q.z, 2.0f);
    EXPECT_EQ(q.r, 1);
    EXPECT_EQ(q.g, 2);
    EXPECT_EQ(q.b, 3);
    // only pixels on the stride lattice
    const double u = q.x / q.z * K.fx + K.cx, v = q.y / q.z * K.fy + K.cy;
    EXPECT_NEAR(std::fmod(std::round(u), 3.0), 0.0, 1e-9);
    EXPECT_NEAR(std::fmod(std::round(v), 3.0), 0.0, 1e-9);
  }
}

TEST(BackProjection, GreyImagesAndBadTypes) {
  const auto K = camera();
  cv::Mat depth(K.height, K.width, CV_32FC1, cv::Scalar(1.0f)),
      grey(K.height, K.width, CV_8UC1, cv::Scalar(77));
  const PointCloud cloud = back_project(grey, depth, K, BackProjectionParams{});
  ASSERT_FALSE(cloud.empty());
  EXPECT_EQ(cloud[0].r, 77);
  EXPECT_EQ(cloud[0].g, 77);
  EXPECT_EQ(cloud[0].b, 77);
  cv::Mat depth16(K.height, K.width, CV_16UC1, cv::Scalar(1000));
  EXPECT_THROW(back_project(grey, depth16, K, BackProjectionParams{}), pvb::Error);
  cv::Mat small(3, 3, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(back_project(small, depth, K, BackProjectionParams{}), pvb::Error);
}

TEST(VoxelFilter, CountsAndAverages) {
  // Two points in voxel (0,0,0), three in (1,0,0), one in (-1,-1,-1), leaf 0.1.
  const PointCloud in = {{0.01f, 0.02f, 0.03f, 10, 20, 30}, {0.15f, 0.05f, 0.05f, 0, 0, 0},
                         {0.09f, 0.08f, 0.07f, 20, 41, 50}, {0.11f, 0.01f, 0.01f, 3, 3, 3},
                         {-0.05f, -0.01f, -0.09f, 9, 9, 9}, {0.19f, 0.09f, 0.09f, 6, 6, 6}};
  const PointCloud out = voxel_filter(in, 0.1);
  ASSERT_EQ(out.size(), 3u);
  // sorted by voxel index: (-1,-1,-1), (0,0,0), (1,0,0)
  EXPECT_FLOAT_EQ(out[0].x, -0.05f);
  EXPECT_EQ(out[0].r, 9);
  EXPECT_NEAR(out[1].x, 0.05, 1e-6);
  EXPECT_NEAR(out[1].y, 0.05, 1e-6);
  EXPECT_NEAR(out[1].z, 0.05, 1e-6);
  EXPECT_EQ(out[1].r, 15);
  EXPECT_EQ(out[1].g, 31);  // 30.5 rounds up
  EXPECT_EQ(out[1].b, 40);
  EXPECT_NEAR(out[2].x, (0.15 + 0.11 + 0.19) / 3, 1e-6);
  EXPECT_NEAR(out[2].y, (0.05 + 0.01 + 0.09) / 3, 1e-6);
  EXPECT_EQ(out[2].r, 3);
}

TEST(VoxelFilter, OnePointPerOccupiedVoxelAndDeterministic) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  PointCloud in(20000);
  for (CloudPoint& p : in) p = {u(rng), u(rng), u(rng), static_cast<std::uint8_t>(rng() % 256), 0, 0};
  in.push_back({std::numeric_limits<float>::infinity(), 0, 0, 0, 0, 0});  // dropped
  const double leaf = 0.25;
  const PointCloud a = voxel_filter(in, leaf);
  // 8 x 8 x 8 voxels in [-1, 1)^3, all occupied at this density
  EXPECT_EQ(a.size(), 512u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_GE(a[i].x, -1.0f);
    EXPECT_LT(a[i].x, 1.0f);
    if (i > 0) {  // strictly increasing voxel index
      const auto key = [&](const CloudPoint& p) {
        return std::make_tuple(std::floor(p.x / leaf), std::floor(p.y / leaf), std::floor(p.z / leaf));
      };
      EXPECT_LT(key(a[i - 1]), key(a[i]));
    }
  }
  const PointCloud b = voxel_filter(in, leaf);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b);  // bit-identical
  // a permutation of the input gives the same voxels and (to rounding) the same means
  PointCloud shuffled = in;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  const PointCloud c = voxel_filter(shuffled, leaf);
  ASSERT_EQ(c.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a[i].x, c[i].x, 1e-6);
    EXPECT_NEAR(a[i].z, c[i].z, 1e-6);
    EXPECT_NEAR(a[i].r, c[i].r, 1);
  }
  // a leaf of 0 keeps the finite points
  EXPECT_EQ(voxel_filter(in, 0.0).size(), in.size() - 1);
}

TEST(Transform, MovesPointsByTheGivenPose) {
  const pvb::geom::SE3d T_a_b =
      pvb::geom::make_se3(pvb::geom::so3_exp(Eigen::Vector3d(0.1, -0.2, 0.3)), Eigen::Vector3d(1, 2, 3));
  const PointCloud b = {{1, 0, 0, 1, 2, 3}, {0, 2, 5, 4, 5, 6}};
  const PointCloud a = transform(b, T_a_b);
  ASSERT_EQ(a.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const Eigen::Vector3d expect = T_a_b * Eigen::Vector3d(b[i].x, b[i].y, b[i].z);
    EXPECT_NEAR(a[i].x, expect.x(), 1e-6);
    EXPECT_NEAR(a[i].y, expect.y(), 1e-6);
    EXPECT_NEAR(a[i].z, expect.z(), 1e-6);
    EXPECT_EQ(a[i].r, b[i].r);
  }
}

}  // namespace
