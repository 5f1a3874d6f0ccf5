#pragma once
// Differential-drive kinematics and a pure-pursuit route follower.
#include <Eigen/Core>
#include <vector>

namespace pvb::sim {

/// Planar robot pose: position of the axle centre and heading (rad, CCW from x).
struct Pose2d {
  double x = 0, y = 0, yaw = 0;
};

/// Effective kinematics of the simulated drive.  MuJoCo's wheel scrub makes
/// turns slower than the ideal model, so the track used for steering is
/// measured (Simulator calibrates it) rather than taken from the geometry.
struct DriveKinematics {
  double wheel_radius_m = 0.1;  ///< effective rolling radius
  double track_m = 0.42;        ///< effective track width for turning
  double max_wheel_radps = 12;

  /// Wheel speeds (left, right) in rad/s for body speeds v (m/s), w (rad/s),
  /// scaled down together if one exceeds the limit.
  Eigen::Vector2d wheel_speeds(double v_mps, double w_radps) const;
};

/// Pure pursuit along a polyline.  Progress along the path only moves
/// forward, so closed loops and lawnmower turns are followed in order.
/// Sharp corners (where the path turns by more than 20 degrees) are driven
/// to, not cut: the lookahead point stops at the next corner until the robot
/// is within kCornerReachedM of it, and the robot turns on the spot when its
/// next target lies behind it.
class RouteFollower {
 public:
  static constexpr double kCornerReachedM = 0.08;
  RouteFollower(std::vector<Eigen::Vector2d> path, double speed_mps, double lookahead_m);

  /// Body speed command (v, w) for the given pose; (0, 0) once finished.
  Eigen::Vector2d command(const Pose2d& pose);
  bool finished() const { return finished_; }
  /// Index of the path point the robot has progressed to.
  std::size_t progress_index() const { return progress_; }
  /// Distance from the pose to the nearest path point near the progress index.
  double cross_track_error_m(const Pose2d& pose) const;
  const std::vector<Eigen::Vector2d>& path() const { return path_; }

 private:
  std::vector<Eigen::Vector2d> path_;
  std::vector<double> arc_;  ///< cumulative length at each point
  std::vector<std::size_t> corners_;  ///< indices where the path turns sharply: reached, not cut
  std::size_t next_corner_ = 0;       ///< first corner not yet reached
  double speed_;
  double lookahead_;
  std::size_t progress_ = 0;
  bool finished_ = false;
};

}  // namespace pvb::sim
