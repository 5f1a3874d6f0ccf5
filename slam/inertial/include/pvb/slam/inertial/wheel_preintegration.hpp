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

/// The wheels as measured against their description: each wheel's rolling
/// radius and the track as factors on the described values (1: as
/// described).  A differential drive's yaw needs the ratio of the two radii
/// to better than 1e-3 to be any use on a straight (a ratio off by e turns
/// the robot by e / track radians a metre).
struct WheelCalibration {
  double left_scale = 1.0;   ///< left wheel's rolling radius / described radius
  double right_scale = 1.0;  ///< right wheel's rolling radius / described radius
  double track_scale = 1.0;  ///< effective track / described track
  bool operator==(const WheelCalibration& o) const {
    return left_scale == o.left_scale && right_scale == o.right_scale && track_scale == o.track_scale;
  }
  bool operator!=(const WheelCalibration& o) const { return !(*this == o); }
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
  WheelPreintegration(const sensor::DriveDescription& drive, const WheelNoise& noise,
                      const WheelCalibration& calibration = {});

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
  const WheelCalibration& calibration() const { return calibration_; }
  /// Distance a wheel rolls per encoder count as described, metres.
  double metres_per_tick() const;
  /// The arcs each wheel rolled as described (counts x metres_per_tick(),
  /// signed, before the calibration): what a calibration is fitted to.
  double described_left_m() const { return described_left_m_; }
  double described_right_m() const { return described_right_m_; }

 private:
  sensor::DriveDescription drive_;
  WheelNoise noise_;
  WheelCalibration calibration_;
  Eigen::Vector3d delta_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_ = Eigen::Matrix3d::Zero();
  double distance_m_ = 0, turn_rad_ = 0;
  double described_left_m_ = 0, described_right_m_ = 0;
};

}  // namespace pvb::slam
