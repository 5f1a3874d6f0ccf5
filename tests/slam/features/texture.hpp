#pragma once
// Synthetic test texture for the feature tests.
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace pvb::slam {

/// A 4x-oversampled test texture: 2500 anti-aliased grey rectangles at
/// random positions, sizes and angles (box-filtering it down gives views
/// whose pixel mapping is known exactly).
inline cv::Mat random_rectangles(int width, int height, std::uint64_t seed) {
  cv::Mat master(height, width, CV_8U, cv::Scalar(128));
  cv::RNG rng(seed);
  for (int i = 0; i < 2500; ++i) {
    // Each pair drawn second coordinate first: the pinned textures' order.
    const float y = rng.uniform(0.f, static_cast<float>(master.rows));
    const float x = rng.uniform(0.f, static_cast<float>(master.cols));
    const float h = rng.uniform(12.f, 160.f), w = rng.uniform(12.f, 160.f);
    const cv::Point2f c(x, y);
    const cv::Size2f sz(w, h);
    cv::Point2f corners[4];
    cv::RotatedRect(c, sz, rng.uniform(0.f, 180.f)).points(corners);
    std::vector<cv::Point> poly;
    for (const auto& p : corners) poly.emplace_back(cvRound(p.x * 16), cvRound(p.y * 16));
    cv::fillConvexPoly(master, poly, cv::Scalar(rng.uniform(0, 256)), cv::LINE_AA, 4);
  }
  return master;
}

}  // namespace pvb::slam
