// The map's top view: where each point lands, which colour its error gets,
// and which point wins a pixel.
#include <gtest/gtest.h>

#include <stdexcept>

#include "pvb/plot/map_view.hpp"

namespace {

using pvb::plot::make_map_error_top_view;

// The pixel of world (x, y) in a view whose points span [0, 1] x [0, 1] m at
// 1 cm per pixel, 10 px margin, +y up.
cv::Vec3b at(const cv::Mat& img, double x, double y) {
  const int c = static_cast<int>(x / 0.01), r = 100 - static_cast<int>(y / 0.01);
  return img.at<cv::Vec3b>(r + 10, c + 10);
}

TEST(MapView, PointsLandWhereTheyAreColouredByError) {
  const std::vector<Eigen::Vector3d> p = {{0, 0, 0}, {1, 1, 0}, {0.5, 0.25, 0}, {0.5, 0.25, 1.0}};
  const std::vector<double> e = {0.0, 0.05, 0.0, 0.10};  // 0, the top of the scale, beyond it
  const cv::Mat img = make_map_error_top_view(p, e, "test");
  EXPECT_EQ(img.type(), CV_8UC3);
  EXPECT_EQ(img.cols, 420);       // at least wide enough for the colour bar
  EXPECT_EQ(img.rows, 101 + 20 + 70);  // 101 rows of map, margins, footer
  const cv::Vec3b low = at(img, 0, 0), high = at(img, 1, 1);
  EXPECT_NE(low, cv::Vec3b(255, 255, 255));
  EXPECT_NE(low, high);
  EXPECT_GT(low[2], low[0]);   // turbo starts dark blue (B > R) ...
  EXPECT_GT(high[0], high[2]);  // ... and ends dark red (R > B)
  EXPECT_EQ(at(img, 0.5, 0.25), high);  // the higher point (clipped error) covers the lower one
  EXPECT_EQ(at(img, 0.25, 0.75), cv::Vec3b(255, 255, 255));  // nothing there
}

TEST(MapView, EmptyMapAndMismatchedInput) {
  EXPECT_FALSE(make_map_error_top_view({}, {}, "empty").empty());
  EXPECT_THROW(make_map_error_top_view({{0, 0, 0}}, {}, "bad"), std::invalid_argument);
}

}  // namespace
