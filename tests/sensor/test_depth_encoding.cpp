#include <gtest/gtest.h>

#include <cstdint>

#include "pvb/sensor/depth_encoding.hpp"

using namespace pvb;

TEST(DepthEncoding, RoundsToTheNearestStepAndMarksInvalidAsZero) {
  cv::Mat d(1, 6, CV_32FC1);
  d.at<float>(0) = 1.00003f;  // 5000.15 steps
  d.at<float>(1) = 1.00013f;  // 5000.65 steps
  d.at<float>(2) = 0.0002f;   // one step
  d.at<float>(3) = 0.0f;      // invalid
  d.at<float>(4) = -1.0f;     // invalid
  d.at<float>(5) = 14.0f;     // 70000 steps: beyond 16 bits
  const cv::Mat u = sensor::depth_to_u16(d, sensor::kTumDepthFactor);
  ASSERT_EQ(u.type(), CV_16UC1);
  EXPECT_EQ(u.at<std::uint16_t>(0), 5000);
  EXPECT_EQ(u.at<std::uint16_t>(1), 5001);
  EXPECT_EQ(u.at<std::uint16_t>(2), 1);
  EXPECT_EQ(u.at<std::uint16_t>(3), 0);
  EXPECT_EQ(u.at<std::uint16_t>(4), 0);
  EXPECT_EQ(u.at<std::uint16_t>(5), 0);
  // OpenNI2 millimetres
  EXPECT_EQ(sensor::depth_to_u16(d, 1000.0).at<std::uint16_t>(0), 1000);
}

TEST(DepthEncoding, DecodesToMetres) {
  cv::Mat u(1, 3, CV_16UC1);
  u.at<std::uint16_t>(0) = 0;
  u.at<std::uint16_t>(1) = 5000;
  u.at<std::uint16_t>(2) = 65535;
  const cv::Mat d = sensor::depth_from_u16(u, sensor::kTumDepthFactor);
  ASSERT_EQ(d.type(), CV_32FC1);
  EXPECT_EQ(d.at<float>(0), 0.0f);
  EXPECT_FLOAT_EQ(d.at<float>(1), 1.0f);
  EXPECT_FLOAT_EQ(d.at<float>(2), 13.107f);
}

// What the simulator's sensor model relies on: snapped depth is a fixed
// point of the encode/decode round trip, so writing and reading a snapped
// frame gives it back bit for bit, and snapping moves depth by at most half
// a step.
TEST(DepthEncoding, SnappedDepthSurvivesTheRoundTripExactly) {
  cv::Mat d(64, 64, CV_32FC1);
  cv::RNG rng(3);
  rng.fill(d, cv::RNG::UNIFORM, 0.3, 12.0);
  d.at<float>(0, 0) = 0.0f;
  const cv::Mat s = sensor::snap_depth_to_u16_grid(d, sensor::kTumDepthFactor);
  const cv::Mat back =
      sensor::depth_from_u16(sensor::depth_to_u16(s, sensor::kTumDepthFactor), sensor::kTumDepthFactor);
  EXPECT_EQ(cv::norm(s, back, cv::NORM_INF), 0.0);
  EXPECT_EQ(s.at<float>(0, 0), 0.0f);
  cv::Mat diff;
  cv::absdiff(s, d, diff);
  double max_diff = 0;
  cv::minMaxLoc(diff, nullptr, &max_diff);
  EXPECT_LE(max_diff, 0.5 / sensor::kTumDepthFactor + 1e-6);
  EXPECT_GT(max_diff, 0.0);  // uniform random depth is not on the grid already
}
