#include "pvb/sensor/wheel_odometry.hpp"

#include <cmath>

namespace pvb::sensor {

Eigen::Vector2d odometry_frame_position(const geom::SE3d& T_w_b0, const geom::SE3d& T_w_b) {
  const Eigen::Vector3d x = T_w_b0.linear().col(0);
  const double yaw = std::atan2(x.y(), x.x());
  const Eigen::Vector2d d = (T_w_b.translation() - T_w_b0.translation()).head<2>();
  return {std::cos(yaw) * d.x() + std::sin(yaw) * d.y(), -std::sin(yaw) * d.x() + std::cos(yaw) * d.y()};
}

double WheelOdometry::metres_per_tick() const { return 2.0 * M_PI * d_.wheel_radius_m / d_.ticks_per_rev; }

void WheelOdometry::add(const WheelTicks& t) {
  if (!last_) {
    last_ = t;
    state_.t_ns = t.t_ns;
    return;
  }
  const double left_m = static_cast<double>(t.left - last_->left) * metres_per_tick();
  const double right_m = static_cast<double>(t.right - last_->right) * metres_per_tick();
  const double ds = 0.5 * (left_m + right_m), dyaw = (right_m - left_m) / d_.track_m;
  const double mid = state_.yaw_rad + 0.5 * dyaw;
  state_.x_m += ds * std::cos(mid);
  state_.y_m += ds * std::sin(mid);
  state_.yaw_rad += dyaw;
  const double dt_s = static_cast<double>(t.t_ns - last_->t_ns) * 1e-9;
  state_.v_mps = dt_s > 0 ? ds / dt_s : 0.0;
  state_.w_radps = dt_s > 0 ? dyaw / dt_s : 0.0;
  state_.t_ns = t.t_ns;
  last_ = t;
}

}  // namespace pvb::sensor
