#include "closed_loop.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "pvb/geometry/time.hpp"

namespace pvb::run {
namespace {

double wrap_angle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace

double camera_heading(const geom::SE3d& T_w_c) {
  const Eigen::Vector3d z = T_w_c.linear().col(2);
  return std::atan2(z.y(), z.x());
}

CameraMount measure_mount(const sim::Pose2d& base, const geom::SE3d& T_w_c) {
  CameraMount m;
  m.yaw_offset = wrap_angle(camera_heading(T_w_c) - base.yaw);
  const Eigen::Vector2d d(T_w_c.translation().x() - base.x, T_w_c.translation().y() - base.y);
  const double c = std::cos(base.yaw), s = std::sin(base.yaw);
  m.offset_b = Eigen::Vector2d(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
  return m;
}

sim::Pose2d base_from_camera(const geom::SE3d& T_w_c, const CameraMount& mount) {
  sim::Pose2d p;
  p.yaw = wrap_angle(camera_heading(T_w_c) - mount.yaw_offset);
  const double c = std::cos(p.yaw), s = std::sin(p.yaw);
  p.x = T_w_c.translation().x() - (c * mount.offset_b.x() - s * mount.offset_b.y());
  p.y = T_w_c.translation().y() - (s * mount.offset_b.x() + c * mount.offset_b.y());
  return p;
}

void ClosedLoop::update(const FrameItem& item, const slam::FrameResult& r) {
  if (item.frame.index == 0) {
    // The robot knows where it starts: its start pose in the site frame
    // (here the ground truth of frame 0) and the camera's mounting.  It
    // stands still until SLAM initialises, so the SLAM world (the first
    // tracked camera frame) is the start camera pose.
    mount_ = measure_mount(item.base_gt, item.gt.T_w_c);
    T_site_slam_ = item.gt.T_w_c;
  }
  const double err = distance_to_polyline(Eigen::Vector2d(item.base_gt.x, item.base_gt.y), route_);
  metrics_.t_s.push_back(geom::ns_to_seconds(item.frame.t_ns));
  metrics_.path_error_m.push_back(err);
  const bool ok = r.state == slam::TrackingState::kOk && r.T_w_c;
  if (!ok) ++metrics_.hold_frames;
  std::lock_guard<std::mutex> lock(steering_.mutex);
  steering_.hold = !ok;
  if (ok) steering_.pose = base_from_camera(T_site_slam_ * *r.T_w_c, mount_);
}

ClosedLoopMetrics ClosedLoop::metrics() const {
  ClosedLoopMetrics m = metrics_;
  if (m.path_error_m.empty()) return m;
  double sum2 = 0;
  for (double e : m.path_error_m) {
    sum2 += e * e;
    m.path_error_max_m = std::max(m.path_error_max_m, e);
  }
  m.path_error_rmse_m = std::sqrt(sum2 / static_cast<double>(m.path_error_m.size()));
  return m;
}

}  // namespace pvb::run
