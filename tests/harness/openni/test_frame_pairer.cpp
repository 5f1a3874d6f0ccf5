// Depth/colour pairing by nearest timestamp within half a frame.
#include <gtest/gtest.h>

#include "pvb/openni/frame_pairer.hpp"

using pvb::openni::FramePairer;
using pvb::openni::TimedImage;

namespace {
constexpr std::int64_t kPeriod = 33'333'333;  // 30 Hz
TimedImage img(std::int64_t t_ns, int tag) { return {t_ns, cv::Mat(1, 1, CV_32SC1, cv::Scalar(tag))}; }
int tag(const TimedImage& i) { return i.image.at<int>(0, 0); }
}  // namespace

TEST(FramePairer, PairsEqualStampsInEitherArrivalOrder) {
  FramePairer p(kPeriod / 2);
  p.push_depth(img(0, 10));
  EXPECT_FALSE(p.pop());
  p.push_colour(img(0, 20));
  auto pair = p.pop();
  ASSERT_TRUE(pair);
  EXPECT_EQ(tag(pair->depth), 10);
  EXPECT_EQ(tag(pair->colour), 20);
  p.push_colour(img(kPeriod, 21));
  EXPECT_FALSE(p.pop());  // no depth yet: wait
  p.push_depth(img(kPeriod, 11));
  pair = p.pop();
  ASSERT_TRUE(pair);
  EXPECT_EQ(tag(pair->depth), 11);
  EXPECT_EQ(p.dropped_colour() + p.dropped_depth(), 0u);
}

TEST(FramePairer, TakesTheNearestDepthAndWaitsUntilItIsDecided) {
  FramePairer p(kPeriod / 2);
  p.push_colour(img(1'000'000'000, 1));
  p.push_depth(img(1'000'000'000 - 10'000'000, 2));  // 10 ms early: within tolerance
  EXPECT_FALSE(p.pop());                             // a nearer one may still come
  p.push_depth(img(1'000'000'000 + 4'000'000, 3));   // 4 ms late: nearer, and decides
  auto pair = p.pop();
  ASSERT_TRUE(pair);
  EXPECT_EQ(tag(pair->depth), 3);
  EXPECT_EQ(p.dropped_depth(), 1u);
}

TEST(FramePairer, DropsColourWithoutDepthWithinHalfAFrame) {
  FramePairer p(kPeriod / 2);
  p.push_colour(img(0, 1));
  p.push_depth(img(kPeriod / 2 + 1, 2));  // just beyond tolerance
  EXPECT_FALSE(p.pop());
  EXPECT_EQ(p.dropped_colour(), 1u);
  p.push_colour(img(kPeriod, 3));
  EXPECT_FALSE(p.pop());  // depth 2 is within tolerance, but one at kPeriod would be nearer
  p.push_depth(img(2 * kPeriod, 4));
  auto pair = p.pop();
  ASSERT_TRUE(pair);
  EXPECT_EQ(tag(pair->colour), 3);
  EXPECT_EQ(tag(pair->depth), 2);
}

TEST(FramePairer, ExactlyHalfAFrameIsAccepted) {
  FramePairer p(kPeriod / 2);
  p.push_colour(img(0, 1));
  p.push_depth(img(kPeriod / 2, 2));
  ASSERT_TRUE(p.pop());
}

TEST(FramePairer, EndOfStreamSettlesTheLastPair) {
  FramePairer p(kPeriod / 2);
  p.push_colour(img(100, 1));
  p.push_depth(img(90, 2));
  EXPECT_FALSE(p.pop(false));
  auto pair = p.pop(true);
  ASSERT_TRUE(pair);
  EXPECT_EQ(tag(pair->depth), 2);
  p.push_colour(img(kPeriod, 3));
  EXPECT_FALSE(p.pop(true));  // no depth left: dropped
  EXPECT_EQ(p.dropped_colour(), 1u);
}

TEST(FramePairer, BoundsItsQueues) {
  FramePairer p(kPeriod / 2, 4);
  for (int i = 0; i < 10; ++i) p.push_colour(img(i * kPeriod, i));
  EXPECT_EQ(p.dropped_colour(), 6u);
  p.push_depth(img(6 * kPeriod, 100));
  auto pair = p.pop();
  ASSERT_TRUE(pair);
  EXPECT_EQ(tag(pair->colour), 6);
}
