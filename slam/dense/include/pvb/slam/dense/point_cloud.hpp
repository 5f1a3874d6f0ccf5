#pragma once
// Coloured point clouds for the dense map: back-projection of an RGB-D
// image, rigid transformation and a voxel-grid filter.  Small on purpose:
// this is all the dense mapper needs, so PCL (a very heavy dependency) is
// not used.  Clouds are plain vectors; every function is deterministic.
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "pvb/geometry/pinhole.hpp"
#include "pvb/geometry/se3.hpp"

namespace pvb::slam::dense {

/// One point: position in metres (frame given by the cloud's owner) and
/// colour in 8-bit R, G, B.
struct CloudPoint {
  float x = 0, y = 0, z = 0;
  std::uint8_t r = 0, g = 0, b = 0;
};
/// Exact equality of position (bit for bit, for finite values) and colour.
inline bool operator==(const CloudPoint& a, const CloudPoint& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z && a.r == b.r && a.g == b.g && a.b == b.b;
}
using PointCloud = std::vector<CloudPoint>;

/// Which pixels become points.
struct BackProjectionParams {
  int stride_px = 3;         ///< every stride-th pixel in both directions, from (0, 0)
  double min_depth_m = 0.1;  ///< depth below this (and 0 = invalid) is skipped
  double max_depth_m = 4.0;  ///< depth above this is skipped (noise grows as z^2)
};

/// Back-projects the depth image (CV_32FC1, metres along the optical axis,
/// 0 = invalid) through the pinhole K into the camera frame, row by row,
/// coloured from `rgb` (CV_8UC3 in R, G, B order, or CV_8UC1 grey) at the
/// same pixel.  The images must have the same size.  Lens distortion is
/// ignored (the registered depth of a Kinect is treated as undistorted, as
/// the ORB-SLAM2 point-cloud forks do).  Throws pvb::Error on bad image types.
PointCloud back_project(const cv::Mat& rgb, const cv::Mat& depth_m, const geom::PinholeIntrinsics& K,
                        const BackProjectionParams& params);

/// Voxel-grid filter: points are binned into cubes of `leaf_m` (voxel index
/// floor(coordinate / leaf_m) per axis); each occupied voxel becomes one point
/// at the mean position with the mean colour (rounded).  The output is sorted
/// by voxel index (x, then y, then z), and sums run in input order, so the
/// result depends only on the input.  Non-finite points are dropped.
/// leaf_m <= 0 returns the finite input points unchanged.
PointCloud voxel_filter(const PointCloud& in, double leaf_m);

/// p_a = T_a_b * p_b for every point (colours unchanged).
PointCloud transform(const PointCloud& cloud_b, const geom::SE3d& T_a_b);

/// Appends `tail` to `cloud`.
void append(PointCloud& cloud, const PointCloud& tail);

}  // namespace pvb::slam::dense
