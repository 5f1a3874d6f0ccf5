#include "pvb/plot/map_view.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace pvb::plot {
namespace {

constexpr int kMarginPx = 10;
constexpr int kFooterPx = 70;

/// OpenCV's turbo colour map as 256 R, G, B entries.
cv::Mat turbo_table() {
  cv::Mat grey(1, 256, CV_8UC1), bgr, rgb;
  for (int i = 0; i < 256; ++i) grey.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
  cv::applyColorMap(grey, bgr, cv::COLORMAP_TURBO);
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

/// Turbo colour (R, G, B) of v in [0, 1] (clipped).
cv::Vec3b turbo(double v) {
  static const cv::Mat table = turbo_table();
  const int i = static_cast<int>(std::lround(std::clamp(std::isfinite(v) ? v : 1.0, 0.0, 1.0) * 255.0));
  return table.at<cv::Vec3b>(0, i);
}

/// The colour bar and its scale under the map.
void draw_footer(cv::Mat& img, const std::string& title, double max_error_m) {
  const int y0 = img.rows - kFooterPx;
  cv::putText(img, title, {kMarginPx, y0 + 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  const int bar_w = std::min(400, img.cols - 2 * kMarginPx);
  for (int x = 0; x < bar_w; ++x) {
    const cv::Vec3b c = turbo(static_cast<double>(x) / std::max(1, bar_w - 1));
    cv::line(img, {kMarginPx + x, y0 + 28}, {kMarginPx + x, y0 + 44}, cv::Scalar(c[0], c[1], c[2]));
  }
  for (int k = 0; k <= 4; ++k) {
    const int x = kMarginPx + k * (bar_w - 1) / 4;
    const double mm = 1000.0 * max_error_m * k / 4.0;
    const std::string label = std::to_string(static_cast<int>(std::lround(mm))) + (k == 4 ? "+ mm" : "");
    cv::putText(img, label, {x - 4, y0 + 60}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
}

}  // namespace

cv::Mat make_map_error_top_view(const std::vector<Eigen::Vector3d>& p_w, const std::vector<double>& error_m,
                                const std::string& title, const MapViewOptions& o) {
  if (p_w.size() != error_m.size()) throw std::invalid_argument("map view: points and errors differ in number");
  Eigen::Vector2d lo(0, 0), hi(1, 1);
  if (!p_w.empty()) {
    lo = hi = p_w.front().head<2>();
    for (const Eigen::Vector3d& p : p_w) lo = lo.cwiseMin(p.head<2>()), hi = hi.cwiseMax(p.head<2>());
  }
  const Eigen::Vector2d span = (hi - lo).cwiseMax(o.min_cell_m);
  const double cell_m = std::max(o.min_cell_m, span.maxCoeff() / o.max_side_px);
  const int w = static_cast<int>(std::ceil(span.x() / cell_m)) + 1, h = static_cast<int>(std::ceil(span.y() / cell_m)) + 1;
  cv::Mat img(h + 2 * kMarginPx + kFooterPx, std::max(w + 2 * kMarginPx, 420), CV_8UC3, cv::Scalar(255, 255, 255));
  cv::Mat top_z(h, w, CV_64F, cv::Scalar(-std::numeric_limits<double>::infinity()));
  for (std::size_t i = 0; i < p_w.size(); ++i) {
    const int c = static_cast<int>((p_w[i].x() - lo.x()) / cell_m);
    const int r = h - 1 - static_cast<int>((p_w[i].y() - lo.y()) / cell_m);
    if (r < 0 || r >= h || c < 0 || c >= w || p_w[i].z() <= top_z.at<double>(r, c)) continue;
    top_z.at<double>(r, c) = p_w[i].z();
    img.at<cv::Vec3b>(r + kMarginPx, c + kMarginPx) = turbo(error_m[i] / o.max_error_m);
  }
  draw_footer(img, title, o.max_error_m);
  return img;
}

}  // namespace pvb::plot
