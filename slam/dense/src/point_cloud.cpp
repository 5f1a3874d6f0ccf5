#include "pvb/slam/dense/point_cloud.hpp"

#include <algorithm>
#include <cmath>

#include "pvb/common/error.hpp"

namespace pvb::slam::dense {

PointCloud back_project(const cv::Mat& rgb, const cv::Mat& depth_m, const geom::PinholeIntrinsics& K,
                        const BackProjectionParams& params) {
  if (depth_m.type() != CV_32FC1) throw Error("back_project: depth image must be CV_32FC1 (metres)");
  if (rgb.type() != CV_8UC3 && rgb.type() != CV_8UC1)
    throw Error("back_project: colour image must be CV_8UC3 or CV_8UC1");
  if (rgb.size() != depth_m.size()) throw Error("back_project: colour and depth images differ in size");
  if (params.stride_px < 1) throw Error("back_project: stride must be >= 1");
  const int step = params.stride_px;
  const float zmin = static_cast<float>(std::max(params.min_depth_m, 0.0));
  const float zmax = static_cast<float>(params.max_depth_m);
  const bool colour = rgb.channels() == 3;
  PointCloud out;
  out.reserve(static_cast<std::size_t>((depth_m.rows + step - 1) / step) *
              static_cast<std::size_t>((depth_m.cols + step - 1) / step));
  for (int v = 0; v < depth_m.rows; v += step) {
    const float* d = depth_m.ptr<float>(v);
    const std::uint8_t* c = rgb.ptr<std::uint8_t>(v);
    const double y_n = (v - K.cy) / K.fy;
    for (int u = 0; u < depth_m.cols; u += step) {
      const float z = d[u];
      if (!(z > 0.0f && z >= zmin && z <= zmax)) continue;  // also drops NaN
      CloudPoint p;
      p.x = static_cast<float>((u - K.cx) / K.fx * z);
      p.y = static_cast<float>(y_n * z);
      p.z = z;
      if (colour) {
        p.r = c[3 * u];
        p.g = c[3 * u + 1];
        p.b = c[3 * u + 2];
      } else {
        p.r = p.g = p.b = c[u];
      }
      out.push_back(p);
    }
  }
  return out;
}

PointCloud voxel_filter(const PointCloud& in, double leaf_m) {
  auto finite = [](const CloudPoint& p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
  };
  if (!(leaf_m > 0)) {
    PointCloud out;
    out.reserve(in.size());
    for (const CloudPoint& p : in)
      if (finite(p)) out.push_back(p);
    return out;
  }
  struct Key {
    std::int64_t ix, iy, iz;
    std::uint32_t idx;  ///< input position: keeps sums in input order
  };
  const double inv = 1.0 / leaf_m;
  std::vector<Key> keys;
  keys.reserve(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    const CloudPoint& p = in[i];
    if (!finite(p)) continue;
    keys.push_back({static_cast<std::int64_t>(std::floor(p.x * inv)),
                    static_cast<std::int64_t>(std::floor(p.y * inv)),
                    static_cast<std::int64_t>(std::floor(p.z * inv)), static_cast<std::uint32_t>(i)});
  }
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    if (a.ix != b.ix) return a.ix < b.ix;
    if (a.iy != b.iy) return a.iy < b.iy;
    if (a.iz != b.iz) return a.iz < b.iz;
    return a.idx < b.idx;
  });
  PointCloud out;
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i;
    double sx = 0, sy = 0, sz = 0, sr = 0, sg = 0, sb = 0;
    for (;
         j < keys.size() && keys[j].ix == keys[i].ix && keys[j].iy == keys[i].iy && keys[j].iz == keys[i].iz;
         ++j) {
      const CloudPoint& p = in[keys[j].idx];
      sx += p.x;
      sy += p.y;
      sz += p.z;
      sr += p.r;
      sg += p.g;
      sb += p.b;
    }
    const double n = static_cast<double>(j - i);
    CloudPoint q;
    q.x = static_cast<float>(sx / n);
    q.y = static_cast<float>(sy / n);
    q.z = static_cast<float>(sz / n);
    q.r = static_cast<std::uint8_t>(std::lround(sr / n));
    q.g = static_cast<std::uint8_t>(std::lround(sg / n));
    q.b = static_cast<std::uint8_t>(std::lround(sb / n));
    out.push_back(q);
    i = j;
  }
  return out;
}

PointCloud transform(const PointCloud& cloud_b, const geom::SE3d& T_a_b) {
  const Eigen::Matrix3d R = T_a_b.linear();
  const Eigen::Vector3d t = T_a_b.translation();
  PointCloud out(cloud_b.size());
  for (std::size_t i = 0; i < cloud_b.size(); ++i) {
    const CloudPoint& p = cloud_b[i];
    const Eigen::Vector3d q = R * Eigen::Vector3d(p.x, p.y, p.z) + t;
    out[i] = {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()), p.r, p.g, p.b};
  }
  return out;
}

void append(PointCloud& cloud, const PointCloud& tail) {
  cloud.insert(cloud.end(), tail.begin(), tail.end());
}

}  // namespace pvb::slam::dense
