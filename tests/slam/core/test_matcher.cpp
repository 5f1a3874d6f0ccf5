// Orientation histogram of the motion-model matcher (paper sec. 3 step 4).
#include <gtest/gtest.h>

#include "pvb/slam/core/matcher.hpp"

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

}  // namespace
}  // namespace pvb::slam

