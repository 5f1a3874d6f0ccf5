#include "pvb/sim/robot.hpp"

#include <algorithm>
#include <cmath>

namespace pvb::sim {

Eigen::Vector2d DriveKinematics::wheel_speeds(double v_mps, double w_radps) const {
  Eigen::Vector2d lr((v_mps - 0.5 * w_radps * track_m) / wheel_radius_m,
                     (v_mps + 0.5 * w_radps * track_m) / wheel_radius_m);
  const double peak = lr.cwiseAbs().maxCoeff();
  if (peak > max_wheel_radps) lr *= max_wheel_radps / peak;
  return lr;
}

RouteFollower::RouteFollower(std::vector<Eigen::Vector2d> path, double speed_mps, double lookahead_m)
    : path_(std::move(path)), speed_(speed_mps), lookahead_(lookahead_m) {
  arc_.resize(path_.size(), 0.0);
  for (std::size_t i = 1; i < path_.size(); ++i) arc_[i] = arc_[i - 1] + (path_[i] - path_[i - 1]).norm();
  finished_ = path_.size() < 2;
  for (std::size_t i = 1; i + 1 < path_.size(); ++i) {
    const Eigen::Vector2d a = path_[i] - path_[i - 1], b = path_[i + 1] - path_[i];
    if (a.norm() < 1e-9 || b.norm() < 1e-9) continue;
    const double cos_turn = a.dot(b) / (a.norm() * b.norm());
    if (cos_turn < std::cos(20.0 * M_PI / 180.0)) corners_.push_back(i);
  }
}

double RouteFollower::cross_track_error_m(const Pose2d& pose) const {
  if (path_.empty()) return 0;
  const Eigen::Vector2d p(pose.x, pose.y);
  double best = 1e300;
  const std::size_t lo = progress_ > 40 ? progress_ - 40 : 0;
  const std::size_t hi = std::min(path_.size(), progress_ + 41);
  for (std::size_t i = lo; i < hi; ++i) best = std::min(best, (path_[i] - p).norm());
  return best;
}

Eigen::Vector2d RouteFollower::command(const Pose2d& pose) {
  if (finished_) return Eigen::Vector2d::Zero();
  const Eigen::Vector2d p(pose.x, pose.y);
  // Advance progress to the closest point within a window ahead (never back).
  const double window_m = 2.0 * lookahead_;
  std::size_t best = progress_;
  double best_d = (path_[progress_] - p).squaredNorm();
  for (std::size_t i = progress_ + 1; i < path_.size() && arc_[i] - arc_[progress_] < window_m; ++i) {
    const double d = (path_[i] - p).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  progress_ = best;
  while (next_corner_ < corners_.size() &&
         (progress_ > corners_[next_corner_] || (path_[corners_[next_corner_]] - p).norm() < kCornerReachedM)) {
    progress_ = std::max(progress_, corners_[next_corner_]);
    ++next_corner_;
  }
  const double remaining = arc_.back() - arc_[progress_];
  if (remaining < 0.05) {
    finished_ = true;
    return Eigen::Vector2d::Zero();
  }
  // Lookahead point: lookahead_ m further along the path (or its end).
  std::size_t target = progress_;
  while (target + 1 < path_.size() && arc_[target] - arc_[progress_] < lookahead_) ++target;
  if (next_corner_ < corners_.size()) target = std::min(target, corners_[next_corner_]);
  const Eigen::Vector2d d = path_[target] - p;
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  const double xl = c * d.x() + s * d.y();
  const double yl = -s * d.x() + c * d.y();
  const double l2 = std::max(xl * xl + yl * yl, 1e-6);
  const double curvature = 2.0 * yl / l2;
  // Turn on the spot when the target is far off the heading (behind, or a
  // sharp corner just reached); slow down in tight turns, before corners and
  // near the end.
  const double heading_error = std::atan2(yl, xl);
  if (std::abs(heading_error) > 50.0 * M_PI / 180.0)
    return Eigen::Vector2d(0.0, std::copysign(std::min(1.0, 2.0 * speed_), heading_error));
  double v = speed_ / (1.0 + 0.6 * std::abs(curvature));
  double slow_for = remaining;
  if (next_corner_ < corners_.size()) slow_for = std::min(slow_for, (path_[corners_[next_corner_]] - p).norm());
  v = std::min(v, std::max(0.08, 0.8 * slow_for));
  return Eigen::Vector2d(v, v * curvature);
}

}  // namespace pvb::sim
