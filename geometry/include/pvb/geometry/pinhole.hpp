#pragma once
// Pinhole camera without distortion, in pixel units.  Pixel centres are at
// integer coordinates: the centre of the top-left pixel is (0, 0).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace pvb::geom {

struct PinholeIntrinsics {
  double fx = 525.0;  ///< focal length along x, pixels
  double fy = 525.0;  ///< focal length along y, pixels
  double cx = 319.5;  ///< principal point x, pixels
  double cy = 239.5;  ///< principal point y, pixels
  int width = 640;    ///< image width, pixels
  int height = 480;   ///< image height, pixels

  /// Projects a point in the camera's optical frame; empty when z <= 0.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_c) const {
    if (p_c.z() <= 0.0) return std::nullopt;
    return Eigen::Vector2d(fx * p_c.x() / p_c.z() + cx, fy * p_c.y() / p_c.z() + cy);
  }
  /// Back-projects pixel (u, v) with metric depth z along the optical axis.
  Eigen::Vector3d unproject(double u, double v, double depth_m) const {
    return {(u - cx) / fx * depth_m, (v - cy) / fy * depth_m, depth_m};
  }
  bool in_image(const Eigen::Vector2d& uv, double border_px = 0.0) const {
    return uv.x() >= -0.5 + border_px && uv.y() >= -0.5 + border_px &&
           uv.x() <= width - 0.5 - border_px && uv.y() <= height - 0.5 - border_px;
  }
  Eigen::Matrix3d K() const {
    Eigen::Matrix3d k;
    k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
    return k;
  }
};

}  // namespace pvb::geom
