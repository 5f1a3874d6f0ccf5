#pragma once
// Metric depth in 16-bit images: value = round(depth_m * factor), 0 where
// invalid.  TUM RGB-D PNGs use factor 5000 (0.2 mm steps); OpenNI2 streams
// millimetres (factor 1000).
#include <opencv2/core.hpp>

namespace pvb::sensor {

/// DepthMapFactor of TUM RGB-D PNGs: raw units per metre.
inline constexpr double kTumDepthFactor = 5000.0;

/// CV_32FC1 metres to CV_16UC1 raw units; 0 where the depth is not positive
/// or beyond 65535 / factor.
cv::Mat depth_to_u16(const cv::Mat& depth_m, double factor);

/// CV_16UC1 raw units to CV_32FC1 metres (0 stays 0).
cv::Mat depth_from_u16(const cv::Mat& depth_u16, double factor);

/// depth_from_u16(depth_to_u16(depth_m)): depth on the 16-bit grid, bit for
/// bit what a reader gets back from an image written with the same factor.
cv::Mat snap_depth_to_u16_grid(const cv::Mat& depth_m, double factor);

}  // namespace pvb::sensor
