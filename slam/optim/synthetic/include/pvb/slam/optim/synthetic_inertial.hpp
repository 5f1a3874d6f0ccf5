#pragma once
// Synthetic motion with known derivatives for the inertial tests: a body
// (a ground robot's base: x forward, y left, z up) whose heading, speed,
// height and tilt are smooth signals of time, the IMU readings and wheel
// encoder counts it produces, and the camera poses of a camera on it.
// World: z up, gravity g_w = (0, 0, -9.81).  Every random choice takes a seed.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/inertial/imu_preintegration.hpp"
#include "pvb/slam/inertial/wheel_preintegration.hpp"

namespace pvb::slam::testing {

/// s(t) = c0 + c1 t + c2 t^2 / 2 + sum_k A_k sin(w_k t + phi_k).
struct Signal {
  struct Wave {
    double amplitude = 0;   ///< A
    double omega_radps = 0; ///< w (> 0)
    double phase_rad = 0;   ///< phi
  };
  double c0 = 0, c1 = 0, c2 = 0;  ///< value, slope and curvature at t = 0 (without the waves)
  std::vector<Wave> waves;        ///< sinusoids added

  double value(double t) const {
    double s = c0 + c1 * t + 0.5 * c2 * t * t;
    for (const Wave& w : waves) s += w.amplitude * std::sin(w.omega_radps * t + w.phase_rad);
    return s;
  }
  double d1(double t) const {
    double s = c1 + c2 * t;
    for (const Wave& w : waves) s += w.amplitude * w.omega_radps * std::cos(w.omega_radps * t + w.phase_rad);
    return s;
  }
  double d2(double t) const {
    double s = c2;
    for (const Wave& w : waves) s -= w.amplitude * w.omega_radps * w.omega_radps * std::sin(w.omega_radps * t + w.phase_rad);
    return s;
  }
  /// Integral from 0 to t.
  double integral(double t) const {
    double s = c0 * t + 0.5 * c1 * t * t + c2 * t * t * t / 6.0;
    for (const Wave& w : waves)
      s += w.amplitude / w.omega_radps * (std::cos(w.phase_rad) - std::cos(w.omega_radps * t + w.phase_rad));
    return s;
  }
};

/// The motion of a base: horizontal speed along its heading, heading (yaw),
/// height, pitch and roll as signals; R_w_base = Rz(yaw) Ry(pitch) Rx(roll).
struct BodyMotion {
  Signal speed_mps, yaw_rad, pitch_rad, roll_rad, z_m;
  Eigen::Vector2d xy0_m = Eigen::Vector2d::Zero();  ///< horizontal position at t = 0

  Eigen::Matrix3d R_w_base(double t) const {
    return (Eigen::AngleAxisd(yaw_rad.value(t), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(pitch_rad.value(t), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(roll_rad.value(t), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
  /// Position: the horizontal part by 5-point Gauss-Legendre quadrature on 10 ms panels.
  Eigen::Vector3d p_w(double t) const {
    static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
    static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                                0.2369268850561891};
    Eigen::Vector2d xy = xy0_m;
    const int panels = std::max(1, static_cast<int>(std::ceil(t / 0.01)));
    const double h = t / panels;
    for (int k = 0; k < panels; ++k) {
      const double mid = (k + 0.5) * h;
      for (int q = 0; q < 5; ++q) {
        const double tq = mid + 0.5 * h * x[q];
        const double psi = yaw_rad.value(tq);
        xy += 0.5 * h * w[q] * speed_mps.value(tq) * Eigen::Vector2d(std::cos(psi), std::sin(psi));
      }
    }
    return {xy.x(), xy.y(), z_m.value(t)};
  }
  Eigen::Vector3d v_w(double t) const {
    const double psi = yaw_rad.value(t), s = speed_mps.value(t);
    return {s * std::cos(psi), s * std::sin(psi), z_m.d1(t)};
  }
  Eigen::Vector3d a_w(double t) const {
    const double psi = yaw_rad.value(t), s = speed_mps.value(t), ds = speed_mps.d1(t), dpsi = yaw_rad.d1(t);
    return {ds * std::cos(psi) - s * dpsi * std::sin(psi), ds * std::sin(psi) + s * dpsi * std::cos(psi), z_m.d2(t)};
  }
  /// Angular rate in the base frame: Rx^T Ry^T (0, 0, yaw') + Rx^T (0, pitch', 0) + (roll', 0, 0).
  Eigen::Vector3d omega_base(double t) const {
    const Eigen::Matrix3d Ry = Eigen::AngleAxisd(pitch_rad.value(t), Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Matrix3d Rx = Eigen::AngleAxisd(roll_rad.value(t), Eigen::Vector3d::UnitX()).toRotationMatrix();
    return Rx.transpose() * (Ry.transpose() * Eigen::Vector3d(0, 0, yaw_rad.d1(t)) + Eigen::Vector3d(0, pitch_rad.d1(t), 0)) +
           Eigen::Vector3d(roll_rad.d1(t), 0, 0);
  }
  geom::SE3d T_w_base(double t) const { return geom::make_se3(R_w_base(t), p_w(t)); }
};

/// An IMU on the base (at its origin, rotated by R_base_imu) and how it errs.
struct ImuRig {
  Eigen::Matrix3d R_base_imu = Eigen::Matrix3d::Identity();
  Eigen::Vector3d g_w = Eigen::Vector3d(0, 0, -9.81);
  ImuBias true_bias;      ///< added to every reading (constant)
  sensor::ImuNoise noise; ///< the model the preintegration is told
  bool white_noise = true;///< add discrete white noise of variance density^2 / dt
  double rate_hz = 200;   ///< reading rate

  geom::SE3d T_base_imu() const { return geom::make_se3(R_base_imu, Eigen::Vector3d::Zero()); }

  /// The exact mean over [t, t + dt] of the angular rate and the specific
  /// force in the IMU frame (3-point Gauss-Legendre of the instantaneous values).
  void mean_reading(const BodyMotion& m, double t, double dt, Eigen::Vector3d* gyro, Eigen::Vector3d* accel) const {
    static const double x[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
    static const double w[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    gyro->setZero();
    accel->setZero();
    for (int q = 0; q < 3; ++q) {
      const double tq = t + 0.5 * dt * (1.0 + x[q]);
      const Eigen::Matrix3d R_w_imu = m.R_w_base(tq) * R_base_imu;
      *gyro += 0.5 * w[q] * R_base_imu.transpose() * m.omega_base(tq);
      *accel += 0.5 * w[q] * R_w_imu.transpose() * (m.a_w(tq) - g_w);
    }
  }

  /// Readings from t0_s to t1_s (a whole number of periods), biased and
  /// (when white_noise) noisy, preintegrated at linearisation bias `lin_bias`.
  std::shared_ptr<ImuPreintegration> preintegrate(const BodyMotion& m, double t0_s, double t1_s,
                                                  const ImuBias& lin_bias, std::mt19937* rng) const {
    auto pre = std::make_shared<ImuPreintegration>(lin_bias, noise);
    const int n = static_cast<int>(std::lround((t1_s - t0_s) * rate_hz));
    const double dt = (t1_s - t0_s) / n;
    std::normal_distribution<double> n01(0.0, 1.0);
    for (int k = 0; k < n; ++k) {
      Eigen::Vector3d gyro, accel;
      mean_reading(m, t0_s + k * dt, dt, &gyro, &accel);
      gyro += true_bias.gyro_radps;
      accel += true_bias.accel_mps2;
      if (white_noise) {
        const double sg = noise.gyro_noise_density / std::sqrt(dt), sa = noise.accel_noise_density / std::sqrt(dt);
        for (int i = 0; i < 3; ++i) {
          gyro[i] += sg * n01(*rng);
          accel[i] += sa * n01(*rng);
        }
      }
      pre->integrate(gyro, accel, dt);
    }
    return pre;
  }
};

/// Wheel encoders of a differential drive on the base (no slip): each
/// wheel's arc is the distance rolled -/+ track/2 times the heading change.
struct WheelRig {
  sensor::DriveDescription drive;
  WheelNoise noise;
  double rate_hz = 100;  ///< encoder reading rate

  /// Cumulative counts at t (floor of the arc over the distance per count).
  std::int64_t ticks(const BodyMotion& m, double t, bool left) const {
    const double arc = m.speed_mps.integral(t) + (left ? -0.5 : 0.5) * drive.track_m * (m.yaw_rad.value(t) - m.yaw_rad.value(0));
    const double per_tick = 2.0 * M_PI * drive.wheel_radius_m / drive.ticks_per_rev;
    return static_cast<std::int64_t>(std::floor(arc / per_tick));
  }
  std::shared_ptr<WheelPreintegration> preintegrate(const BodyMotion& m, double t0_s, double t1_s) const {
    auto pre = std::make_shared<WheelPreintegration>(drive, noise);
    const int n = std::max(1, static_cast<int>(std::lround((t1_s - t0_s) * rate_hz)));
    for (int k = 0; k < n; ++k) {
      const double ta = t0_s + (t1_s - t0_s) * k / n, tb = t0_s + (t1_s - t0_s) * (k + 1) / n;
      pre->add(ticks(m, tb, true) - ticks(m, ta, true), ticks(m, tb, false) - ticks(m, ta, false));
    }
    return pre;
  }
};

/// A forward-looking camera on the base: optical axes, 0.2 m ahead and 0.5 m up.
inline geom::SE3d default_T_base_camera() {
  return geom::make_se3(geom::R_body_optical(), Eigen::Vector3d(0.2, 0.0, 0.5));
}

/// A rotation of the IMU on the base that is not a plain axis swap.
inline Eigen::Matrix3d default_R_base_imu() {
  return (Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// T_c_w of the camera at time t.
inline geom::SE3d camera_pose(const BodyMotion& m, const geom::SE3d& T_base_c, double t) {
  return (m.T_w_base(t) * T_base_c).inverse();
}

}  // namespace pvb::slam::testing
