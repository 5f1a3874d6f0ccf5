#pragma once
// A contact sheet: a grid of labelled thumbnails of camera frames, so a
// person can see at a glance what a sequence looks like.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace pvb::plot {

struct Thumbnail {
  cv::Mat rgb;        ///< CV_8UC3, R, G, B order
  std::string label;  ///< drawn in the top-left corner
};

/// Lays thumbnails out `cols` per row, each scaled to `thumb_width` pixels
/// wide, and returns the sheet (CV_8UC3, R, G, B order).
cv::Mat make_contact_sheet(const std::vector<Thumbnail>& thumbs, int cols = 4, int thumb_width = 320);

/// Writes an RGB image as PNG; throws pvb::IoError when it cannot.
void write_rgb_png(const cv::Mat& rgb, const std::string& path);

/// Indices of `count` frames spread evenly over [0, n) (first and last included).
std::vector<int> spread_indices(int n, int count);

}  // namespace pvb::plot
