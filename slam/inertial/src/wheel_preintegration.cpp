// Differential-drive wheel increments with their covariance (the planar
// odometry of "VINS on Wheels", Wu et al., ICRA 2017, preintegrated between
// two instants).
#include "pvb/slam/inertial/wheel_preintegration.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace pvb::slam {

Eigen::Vector3d planar_compose(const Eigen::Vector3d& a, const Eigen::Vector3d& b, Eigen::Matrix3d* J_a,
                               Eigen::Matrix3d* J_b) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  const Eigen::Vector3d out(a.x() + c * b.x() - s * b.y(), a.y() + s * b.x() + c * b.y(), a.z() + b.z());
  if (J_a != nullptr) {
    *J_a << 1, 0, -s * b.x() - c * b.y(),  //
        0, 1, c * b.x() - s * b.y(),       //
        0, 0, 1;
  }
  if (J_b != nullptr) {
    *J_b << c, -s, 0,  //
        s, c, 0,       //
        0, 0, 1;
  }
  return out;
}

Eigen::Vector3d wheel_step(double left_m, double right_m, double track_m) {
  const double ds = 0.5 * (left_m + right_m), dyaw = (right_m - left_m) / track_m;
  return {ds * std::cos(0.5 * dyaw), ds * std::sin(0.5 * dyaw), dyaw};
}

WheelPreintegration::WheelPreintegration(const sensor::DriveDescription& drive, const WheelNoise& noise,
                                         const WheelCalibration& calibration)
    : drive_(drive), noise_(noise), calibration_(calibration) {
  if (!(drive.wheel_radius_m > 0) || !(drive.track_m > 0) || drive.ticks_per_rev <= 0) {
    throw std::invalid_argument("WheelPreintegration: wheel radius, track and ticks per revolution must be positive");
  }
  if (!(noise.translation_per_sqrt_m >= 0) || !(noise.yaw_per_sqrt_m >= 0) || !(noise.yaw_per_sqrt_rad >= 0) ||
      !(noise.planar_z_per_m >= 0) || !(noise.planar_tilt_per_m >= 0) || !(noise.planar_floor > 0)) {
    throw std::invalid_argument("WheelPreintegration: noise terms must be >= 0 and planar_floor > 0");
  }
  if (!(calibration.left_scale > 0) || !(calibration.right_scale > 0) || !(calibration.track_scale > 0)) {
    throw std::invalid_argument("WheelPreintegration: calibration factors must be positive");
  }
}

double WheelPreintegration::metres_per_tick() const {
  return 2.0 * M_PI * drive_.wheel_radius_m / drive_.ticks_per_rev;
}

void WheelPreintegration::add(double d_left_ticks, double d_right_ticks) {
  described_left_m_ += d_left_ticks * metres_per_tick();
  described_right_m_ += d_right_ticks * metres_per_tick();
  const double left_m = d_left_ticks * metres_per_tick() * calibration_.left_scale;
  const double right_m = d_right_ticks * metres_per_tick() * calibration_.right_scale;
  const Eigen::Vector3d step = wheel_step(left_m, right_m, drive_.track_m * calibration_.track_scale);
  const double ds = std::abs(0.5 * (left_m + right_m)), dyaw = std::abs(step.z());
  // Noise of this step in its own frame: isotropic in the plane (along and
  // across the chord alike), yaw from the distance and the turn.
  const double var_t = noise_.translation_per_sqrt_m * noise_.translation_per_sqrt_m * ds;
  const double var_yaw = noise_.yaw_per_sqrt_m * noise_.yaw_per_sqrt_m * ds +
                         noise_.yaw_per_sqrt_rad * noise_.yaw_per_sqrt_rad * dyaw;
  const Eigen::Matrix3d Q = Eigen::Vector3d(var_t, var_t, var_yaw).asDiagonal();
  Eigen::Matrix3d J_a, J_b;
  delta_ = planar_compose(delta_, step, &J_a, &J_b);
  cov_ = J_a * cov_ * J_a.transpose() + J_b * Q * J_b.transpose();
  distance_m_ += ds;
  turn_rad_ += dyaw;
}

void WheelPreintegration::append(const WheelPreintegration& next) {
  Eigen::Matrix3d J_a, J_b;
  const Eigen::Vector3d delta = planar_compose(delta_, next.delta_, &J_a, &J_b);
  cov_ = J_a * cov_ * J_a.transpose() + J_b * next.cov_ * J_b.transpose();
  delta_ = delta;
  distance_m_ += next.distance_m_;
  turn_rad_ += next.turn_rad_;
  described_left_m_ += next.described_left_m_;
  described_right_m_ += next.described_right_m_;
}

Eigen::Vector3d WheelPreintegration::planar_sigma() const {
  return {noise_.planar_floor + noise_.planar_z_per_m * distance_m_,
          noise_.planar_floor + noise_.planar_tilt_per_m * distance_m_,
          noise_.planar_floor + noise_.planar_tilt_per_m * distance_m_};
}

}  // namespace pvb::slam
