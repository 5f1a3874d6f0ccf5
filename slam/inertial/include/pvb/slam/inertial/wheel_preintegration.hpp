#pragma once
// Wheel odometry between two instants, preintegrated in the base frame of
// the first: the planar increment (x forward, y left, yaw) of a
// differential-drive robot from its encoder counts, and a covariance that
// grows with the distance rolled and the angle turned, so that slip is
// absorbed rather than believed.
#include <Eigen/Core>
#include <cstdint>

#include "pvb/sensor/motion.hpp"

namespace pvb::slam {

/// Noise of the planar increments, per metre rolled and per radian turned
/// (variances add: sigma^2 = a^2 d + b^2 |dyaw|), and of the soft planar
/// constraint (z, roll, pitch of the relative motion: the ground is not flat).
struct WheelNoise {
  double translation_per_sqrt_m = 0.02;     ///< m / sqrt(m) along and across
  double yaw_per_sqrt_m = 0.01;             ///< rad / sqrt(m)
  double yaw_per_sqrt_rad = 0.05;           ///< rad / sqrt(rad)
  double planar_z_per_m = 0.05;             ///< m per m rolled (plus planar_floor)
  double planar_tilt_per_m = 0.03;          ///< rad per m rolled
  double planar_floor = 1e-3;               ///< m / rad added so standing still is not infinitely stiff
};

/// Composition of planar poses [x, y, yaw]: b expressed in a's frame,
///   a (+) b = [a_xy + R(a_yaw) b_xy, a_yaw + b_yaw],
/// with its Jacobians with respect to a and b (either may be null).
Eigen::Vector3d planar_compose(const Eigen::Vector3d& a, const Eigen::Vector3d& b, Eigen::Matrix3d* J_a = nullptr,
                               Eigen::Matrix3d* J_b = nullptr);

/// The increment [x, y, yaw] of one encoder interval from the arcs the left
/// and right wheel rolled (m): ds = (l + r) / 2 along the chord at half the
/// turn dyaw = (r - l) / track.
Eigen::Vector3d wheel_step(double left_m, double right_m, double track_m);

class WheelPreintegration {
 public:
  WheelPreintegration() = default;
  WheelPreintegration(const sensor::DriveDescription& drive, const WheelNoise& noise);

  /// Adds one encoder interval: the count changes of the left and right
  /// wheel (positive forward), with a fraction where the interval is a
  /// reading's share of the time up to a frame between two readings.
  void add(double d_left_ticks, double d_right_ticks);
  /// Appends `next`, which starts where this one ends.
  void append(const WheelPreintegration& next);

  /// [x, y, yaw] of the base at the end in the base frame at the start.
  const Eigen::Vector3d& delta() const { return delta_; }
  /// Covariance of delta().
  const Eigen::Matrix3d& covariance() const { return cov_; }
  double distance_m() const { return distance_m_; }  ///< arc length rolled (mean of the wheels, absolute)
  double turn_rad() const { return turn_rad_; }      ///< absolute yaw turned
  /// Standard deviations of the soft planar constraint for this increment:
  /// [z (m), roll (rad), pitch (rad)].
  Eigen::Vector3d planar_sigma() const;
  const sensor::DriveDescription& drive() const { return drive_; }
  const WheelNoise& noise() const { return noise_; }
  /// Distance a wheel rolls per encoder count, metres.
  double metres_per_tick() const;

 private:
  sensor::DriveDescription drive_;
  WheelNoise noise_;
  Eigen::Vector3d delta_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_ = Eigen::Matrix3d::Zero();
  double distance_m_ = 0, turn_rad_ = 0;
};

}  // namespace pvb::slam
