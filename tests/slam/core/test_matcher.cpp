// Orientation histogram of the motion-model matcher (paper sec. 3 step 4),
// the tracking scratch marks (IdMarks) and the frame grid search.
#include <gtest/gtest.h>

#include "pvb/slam/core/matcher.hpp"
#include "pvb/slam/core/tracking.hpp"

namespace pvb::slam {
namespace {

TEST(OrientationHistogram, KeepsTheThreeLargestBins) {
  std::vector<float> d;
  for (int i = 0; i < 50; ++i) d.push_back(1.0f);    // bin 0
  for (int i = 0; i < 20; ++i) d.push_back(13.0f);   // bin 1 (12 deg per bin)
  for (int i = 0; i < 10; ++i) d.push_back(-5.0f);   // 355 deg: bin 29
  for (int i = 0; i < 4; ++i) d.push_back(100.0f);   // bin 8: fourth largest
  const auto ok = orientation_consistent(d);
  for (std::size_t i = 0; i < 80; ++i) EXPECT_TRUE(ok[i]) << i;
  for (std::size_t i = 80; i < 84; ++i) EXPECT_FALSE(ok[i]) << i;
}

TEST(OrientationHistogram, SmallBinsBelowTenPercentOfTheLargestAreDropped) {
  std::vector<float> d(100, 0.5f);
  d.push_back(180.0f);  // a lone bin with 1 % of the largest
  d.push_back(90.0f);
  const auto ok = orientation_consistent(d);
  EXPECT_TRUE(ok[0]);
  EXPECT_FALSE(ok[100]);
  EXPECT_FALSE(ok[101]);
}

TEST(OrientationHistogram, EmptyInput) { EXPECT_TRUE(orientation_consistent({}).empty()); }


TEST(IdMarks, EachIdIsNewOncePerPass) {
  IdMarks marks;
  marks.new_pass();
  EXPECT_TRUE(marks.mark(5));
  EXPECT_FALSE(marks.mark(5));
  EXPECT_TRUE(marks.marked(5));
  EXPECT_FALSE(marks.marked(4));
  EXPECT_FALSE(marks.marked(1000000));  // beyond the stamps allocated so far
  EXPECT_TRUE(marks.mark(1000000));
  const std::uint64_t vo_id = std::uint64_t(1) << 62;  // visual-odometry point ids
  EXPECT_TRUE(marks.mark(vo_id));
  EXPECT_FALSE(marks.mark(vo_id));
  marks.new_pass();
  for (std::uint64_t id : {std::uint64_t(5), std::uint64_t(1000000), vo_id}) {
    EXPECT_FALSE(marks.marked(id)) << id;
    EXPECT_TRUE(marks.mark(id)) << id;
    EXPECT_TRUE(marks.marked(id)) << id;
  }
}

TEST(FrameGrid, BufferedAreaSearchEqualsTheReturningOne) {
  auto cam = std::make_shared<const CameraModel>(CameraModel::make(StereoIntrinsics{}, 640, 480, {}, 3.0, 1.2, 8));
  OrbFeatures feats;
  cv::RNG rng(7);
  for (int i = 0; i < 500; ++i) {
    const double y = rng.uniform(0.0, 480.0), x = rng.uniform(0.0, 640.0);
    cv::KeyPoint k(static_cast<float>(x), static_cast<float>(y), 31.0f);
    k.octave = rng.uniform(0, 8);
    feats.keypoints.push_back(k);
  }
  feats.descriptors = cv::Mat::zeros(500, 32, CV_8U);
  const Frame f(0, 0, feats, cv::Mat(480, 640, CV_32F, cv::Scalar(1.0f)), cam);
  std::vector<std::size_t> buf = {12345};  // stale content must go
  int nonempty = 0;
  for (int q = 0; q < 200; ++q) {
    const double u = rng.uniform(-20.0, 660.0), v = rng.uniform(-20.0, 500.0), r = rng.uniform(1.0, 60.0);
    const int lo = rng.uniform(-1, 4), hi = rng.uniform(-1, 8);
    const std::vector<std::size_t> expected = f.features_in_area(u, v, r, lo, hi);
    f.features_in_area(u, v, r, lo, hi, &buf);
    ASSERT_EQ(buf, expected) << "query " << q;
    nonempty += !expected.empty();
    for (std::size_t i : expected) {
      EXPECT_LT(std::abs(f.keys_un[i].pt.x - u), r);
      EXPECT_LT(std::abs(f.keys_un[i].pt.y - v), r);
    }
  }
  EXPECT_GT(nonempty, 50);
}

}  // namespace
}  // namespace pvb::slam

