#include "pvb/sensor/depth_encoding.hpp"

#include <cmath>
#include <cstdint>

namespace pvb::sensor {

cv::Mat depth_to_u16(const cv::Mat& depth_m, double factor) {
  CV_Assert(depth_m.type() == CV_32FC1 && factor > 0);
  cv::Mat out(depth_m.size(), CV_16UC1);
  for (int r = 0; r < depth_m.rows; ++r) {
    const float* d = depth_m.ptr<float>(r);
    auto* o = out.ptr<std::uint16_t>(r);
    for (int c = 0; c < depth_m.cols; ++c) {
      const double v = std::round(static_cast<double>(d[c]) * factor);
      o[c] = (d[c] > 0 && v <= 65535.0) ? static_cast<std::uint16_t>(v) : 0;
    }
  }
  return out;
}

cv::Mat depth_from_u16(const cv::Mat& depth_u16, double factor) {
  CV_Assert(depth_u16.type() == CV_16UC1 && factor > 0);
  cv::Mat out;
  depth_u16.convertTo(out, CV_32FC1, 1.0 / factor);
  return out;
}

cv::Mat snap_depth_to_u16_grid(const cv::Mat& depth_m, double factor) {
  return depth_from_u16(depth_to_u16(depth_m, factor), factor);
}

}  // namespace pvb::sensor
