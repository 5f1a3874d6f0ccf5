// Dashed polylines on a chart: the dashes' count and lengths along a line
// of known length, around a corner, other colours untouched.
#include <gtest/gtest.h>

#include <cmath>

#include "pvb/plot/dashes.hpp"

namespace pvb::plot {
namespace {

double length_px(const eval::FigPolyline& p) {
  double l = 0;
  for (std::size_t i = 0; i + 1 < p.points.size(); ++i)
    l += std::hypot(p.points[i + 1].first - p.points[i].first, p.points[i + 1].second - p.points[i].second);
  return l;
}

const eval::Rgb kRed{200, 30, 30}, kBlue{31, 90, 230};

TEST(Dashes, DashesOfKnownLengthAlongTheLine) {
  eval::Figure f;
  f.polylines.push_back({{{0, 10}, {100, 10}}, kRed, 2.0});
  f.polylines.push_back({{{0, 20}, {100, 20}}, kBlue, 2.0});
  dash_polylines(&f, kRed, 8, 5);
  // Dashes start every 13 px: 0, 13, ..., 91 -> 8 dashes of 8 px; the blue line last, as it was.
  ASSERT_EQ(f.polylines.size(), 9u);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_NEAR(length_px(f.polylines[i]), 8.0, 1e-9) << i;
    EXPECT_NEAR(f.polylines[i].points.front().first, 13.0 * i, 1e-9) << i;
    EXPECT_EQ(f.polylines[i].color.r, kRed.r);
    EXPECT_EQ(f.polylines[i].width_px, 2.0);
  }
  EXPECT_EQ(f.polylines[8].color.b, kBlue.b);
  EXPECT_EQ(f.polylines[8].points.size(), 2u);
}

TEST(Dashes, ADashFollowsTheLineAroundACorner) {
  eval::Figure f;
  f.polylines.push_back({{{0, 0}, {4, 0}, {4, 30}}, kRed, 1.0});  // 34 px
  dash_polylines(&f, kRed, 10, 5);
  // 0-10 (around the corner: 3 points), 15-25, 30-34.
  ASSERT_EQ(f.polylines.size(), 3u);
  EXPECT_EQ(f.polylines[0].points.size(), 3u);
  EXPECT_NEAR(length_px(f.polylines[0]), 10.0, 1e-9);
  EXPECT_NEAR(length_px(f.polylines[1]), 10.0, 1e-9);
  EXPECT_NEAR(length_px(f.polylines[2]), 4.0, 1e-9);
  EXPECT_NEAR(f.polylines[2].points.back().second, 30.0, 1e-9);
}

}  // namespace
}  // namespace pvb::plot
