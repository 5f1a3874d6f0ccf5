#pragma once
// Synthetic RGB-D views of a plane, rendered exactly (ray / plane
// intersection per pixel), for the dense-mapping tests.
#include <cmath>
#include <opencv2/core.hpp>

#include "pvb/geometry/pinhole.hpp"
#include "pvb/geometry/se3.hpp"

namespace pvb::test {

/// The plane n . p_w = d (n unit length) seen from T_w_c; depth 0 where
/// the ray misses it (parallel or behind).  Colour encodes the pixel:
/// R = u mod 256, G = v mod 256, B = 7.
struct PlaneView {
  cv::Mat rgb;
  cv::Mat depth_m;
};

inline PlaneView render_plane(const geom::PinholeIntrinsics& K, const geom::SE3d& T_w_c,
                              const Eigen::Vector3d& n, double d) {
  PlaneView v{cv::Mat(K.height, K.width, CV_8UC3), cv::Mat(K.height, K.width, CV_32FC1, cv::Scalar(0))};
  const Eigen::Matrix3d R = T_w_c.linear();
  const Eigen::Vector3d o = T_w_c.translation();
  for (int r = 0; r < K.height; ++r)
    for (int c = 0; c < K.width; ++c) {
      const Eigen::Vector3d ray_c((c - K.cx) / K.fx, (r - K.cy) / K.fy, 1.0);
      const double denom = n.dot(R * ray_c);
      const double s = std::abs(denom) > 1e-12 ? (d - n.dot(o)) / denom : -1.0;  // s = depth (ray_c.z = 1)
      v.depth_m.at<float>(r, c) = s > 0 ? static_cast<float>(s) : 0.0f;
      v.rgb.at<cv::Vec3b>(r, c) =
          cv::Vec3b(static_cast<unsigned char>(c % 256), static_cast<unsigned char>(r % 256), 7);
    }
  return v;
}

/// A small camera for fast tests.
inline geom::PinholeIntrinsics small_camera() {
  geom::PinholeIntrinsics K;
  K.fx = K.fy = 160.0;
  K.cx = 79.5;
  K.cy = 59.5;
  K.width = 160;
  K.height = 120;
  return K;
}

}  // namespace pvb::test
