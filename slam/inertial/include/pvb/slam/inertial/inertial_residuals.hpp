#pragma once
// Residuals of the inertial and wheel factors, templated on the scalar so
// that the same code runs on doubles and on automatic-differentiation jets
// (Ceres' Jet: the optimiser differentiates them on its pose manifold).
// Eigen only.
//
// A camera pose is 7 scalars, the optimiser's pose block:
//   [q_c_w (x, y, z, w, Eigen's order), t_c_w],   p_c = q_c_w * p_w + t_c_w.
// The IMU's pose follows from the camera's: T_w_b = T_c_w^-1 * T_b_c^-1,
// the wheel base's from T_base_c.  A bias is 6 scalars [b_g (rad/s), b_a (m/s^2)].
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/inertial/imu_preintegration.hpp"
#include "pvb/slam/inertial/wheel_preintegration.hpp"

namespace pvb::slam {

template <typename T>
using Vec3T = Eigen::Matrix<T, 3, 1>;
template <typename T>
using QuatT = Eigen::Quaternion<T>;

/// Exp of a rotation vector as a unit quaternion, with a series near zero
/// that keeps the derivative exact there.
template <typename T>
QuatT<T> quaternion_exp_t(const Vec3T<T>& w) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T t2 = w.squaredNorm();
  if (t2 < T(1e-16)) return QuatT<T>(T(1) - t2 / T(8), T(0.5) * w.x(), T(0.5) * w.y(), T(0.5) * w.z());
  const T t = sqrt(t2);
  const T s = sin(T(0.5) * t) / t;
  return QuatT<T>(cos(T(0.5) * t), s * w.x(), s * w.y(), s * w.z());
}

/// Log of a unit quaternion as a rotation vector, angle in [0, pi].
template <typename T>
Vec3T<T> quaternion_log_t(QuatT<T> q) {
  using std::atan2;
  using std::sqrt;
  if (q.w() < T(0)) q.coeffs() = -q.coeffs();
  const T n2 = q.vec().squaredNorm();
  if (n2 < T(1e-16)) return q.vec() * (T(2) / q.w());
  const T n = sqrt(n2);
  return q.vec() * (T(2) * atan2(n, q.w()) / n);
}

/// A pose T_c_w read from a 7-scalar block.
template <typename T>
struct CameraPoseT {
  QuatT<T> q_c_w;  ///< rotation world -> camera
  Vec3T<T> t_c_w;  ///< translation world -> camera
  explicit CameraPoseT(const T* x) : q_c_w(x[3], x[0], x[1], x[2]), t_c_w(x[4], x[5], x[6]) {}
  /// The pose of a rigidly attached frame s (T_c_s given as q, p): T_w_s = T_c_w^-1 T_c_s.
  void attached(const Eigen::Quaterniond& q_c_s, const Eigen::Vector3d& p_c_s, QuatT<T>* q_w_s, Vec3T<T>* p_w_s) const {
    const QuatT<T> q_w_c = q_c_w.conjugate();
    *q_w_s = q_w_c * q_c_s.cast<T>();
    *p_w_s = q_w_c * (p_c_s.cast<T>() - t_c_w);
  }
};

/// W with W^T W = Sigma^-1 (so |W r|^2 is the Mahalanobis norm), Sigma's
/// eigenvalues raised to at least max(relative_floor * largest, absolute_floor)
/// so that a near-singular covariance gives finite weights.
template <int N>
Eigen::Matrix<double, N, N> sqrt_information(const Eigen::Matrix<double, N, N>& cov, double relative_floor = 1e-10,
                                             double absolute_floor = 1e-24) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(0.5 * (cov + cov.transpose()));
  const double floor = std::max(relative_floor * std::max(es.eigenvalues().maxCoeff(), 0.0), absolute_floor);
  Eigen::Matrix<double, N, 1> inv_sigma;
  for (int k = 0; k < N; ++k) inv_sigma[k] = 1.0 / std::sqrt(std::max(es.eigenvalues()[k], floor));
  return inv_sigma.asDiagonal() * es.eigenvectors().transpose();
}

/// The 9-D IMU factor between keyframes i and j (Forster eq. 45):
///   r_R = Log(dR(b_i)^T R_i^T R_j)
///   r_v = R_i^T (v_j - v_i - g dt) - dv(b_i)
///   r_p = R_i^T (p_j - p_i - v_i dt - 1/2 g dt^2) - dp(b_i)
/// with the increments corrected to first order for b_i, whitened by the
/// square root of the inverse of the preintegration's covariance.
struct ImuFactor {
  Eigen::Quaterniond q_dR;          ///< rotation increment at the linearisation bias
  Eigen::Vector3d dv, dp;           ///< velocity and position increments at the linearisation bias
  Eigen::Matrix3d J_R_bg, J_v_bg, J_v_ba, J_p_bg, J_p_ba;  ///< bias Jacobians
  Eigen::Vector3d bg0, ba0;         ///< the linearisation bias
  double dt_s = 0;                  ///< time spanned
  Eigen::Matrix<double, 9, 9> sqrt_info;  ///< whitening of [r_R, r_v, r_p]
  Eigen::Quaterniond q_c_b;         ///< the IMU in the camera frame (T_b_c^-1), rotation
  Eigen::Vector3d p_c_b;            ///< ... and translation

  /// Throws std::invalid_argument for an empty preintegration.
  ImuFactor(const ImuPreintegration& pre, const geom::SE3d& T_b_c)
      : q_dR(Eigen::Quaterniond(pre.delta_R()).normalized()),
        dv(pre.delta_v()),
        dp(pre.delta_p()),
        J_R_bg(pre.J_R_bg()),
        J_v_bg(pre.J_v_bg()),
        J_v_ba(pre.J_v_ba()),
        J_p_bg(pre.J_p_bg()),
        J_p_ba(pre.J_p_ba()),
        bg0(pre.bias().gyro_radps),
        ba0(pre.bias().accel_mps2),
        dt_s(pre.dt_s()),
        q_c_b(Eigen::Quaterniond(T_b_c.inverse().linear()).normalized()),
        p_c_b(T_b_c.inverse().translation()) {
    if (!(pre.dt_s() > 0)) throw std::invalid_argument("ImuFactor: empty preintegration");
    sqrt_info = sqrt_information<9>(pre.covariance());
  }

  /// Whitened residual (9) from two camera poses (7 each), velocities (3),
  /// keyframe i's bias (6) and gravity g_w (3).
  template <typename T>
  void residual(const T* pose_i, const T* v_i, const T* bias_i, const T* pose_j, const T* v_j, const T* g_w,
                T* r) const {
    QuatT<T> q_i, q_j;
    Vec3T<T> p_i, p_j;
    CameraPoseT<T>(pose_i).attached(q_c_b, p_c_b, &q_i, &p_i);
    CameraPoseT<T>(pose_j).attached(q_c_b, p_c_b, &q_j, &p_j);
    const Eigen::Map<const Vec3T<T>> vi(v_i), vj(v_j), g(g_w), bg(bias_i), ba(bias_i + 3);
    const Vec3T<T> dbg = bg - bg0.cast<T>(), dba = ba - ba0.cast<T>();
    const QuatT<T> q_corr = q_dR.cast<T>() * quaternion_exp_t<T>(J_R_bg.cast<T>() * dbg);
    const Vec3T<T> dv_corr = dv.cast<T>() + J_v_bg.cast<T>() * dbg + J_v_ba.cast<T>() * dba;
    const Vec3T<T> dp_corr = dp.cast<T>() + J_p_bg.cast<T>() * dbg + J_p_ba.cast<T>() * dba;
    const T dt(dt_s);
    const QuatT<T> q_i_inv = q_i.conjugate();
    Eigen::Matrix<T, 9, 1> e;
    e.template segment<3>(0) = quaternion_log_t<T>(q_corr.conjugate() * q_i_inv * q_j);
    e.template segment<3>(3) = q_i_inv * Vec3T<T>(vj - vi - g * dt) - dv_corr;
    e.template segment<3>(6) = q_i_inv * Vec3T<T>(p_j - p_i - vi * dt - T(0.5) * g * dt * dt) - dp_corr;
    Eigen::Map<Eigen::Matrix<T, 9, 1>> out(r);
    out = sqrt_info.cast<T>() * e;
  }
};

/// Random walk of the biases between keyframes i and j (6):
///   r = (b_j - b_i) / sigma,  sigma^2 = walk^2 dt  (gyro, then accelerometer).
struct BiasWalkFactor {
  double inv_sigma_g = 0, inv_sigma_a = 0;  ///< 1 / sigma of the gyro and accelerometer rows

  /// Throws std::invalid_argument for an empty preintegration or a zero random walk.
  explicit BiasWalkFactor(const ImuPreintegration& pre) {
    const double dt = pre.dt_s();
    if (!(dt > 0) || !(pre.noise().gyro_random_walk > 0) || !(pre.noise().accel_random_walk > 0))
      throw std::invalid_argument("BiasWalkFactor: needs dt > 0 and positive random walks");
    inv_sigma_g = 1.0 / (pre.noise().gyro_random_walk * std::sqrt(dt));
    inv_sigma_a = 1.0 / (pre.noise().accel_random_walk * std::sqrt(dt));
  }

  template <typename T>
  void residual(const T* bias_i, const T* bias_j, T* r) const {
    for (int k = 0; k < 3; ++k) {
      r[k] = (bias_j[k] - bias_i[k]) * T(inv_sigma_g);
      r[3 + k] = (bias_j[3 + k] - bias_i[3 + k]) * T(inv_sigma_a);
    }
  }
};

/// Wheel factor between keyframes i and j (6 rows).  With the relative base
/// pose T_bi_bj = T_base_c T_ci_w T_cj_w^-1 T_base_c^-1 and its ZYX angles
/// (yaw, pitch, roll):
///   rows 0-2: W ([x, y, wrap(yaw)] - delta),  W^T W = (Sigma_wheel + floor^2 I)^-1
///   rows 3-5: [z, roll, pitch] / planar_sigma()
/// (floor = WheelNoise::planar_floor, so that standing still stays finite).
struct WheelFactor {
  Eigen::Vector3d delta;            ///< measured [x, y, yaw]
  Eigen::Matrix3d sqrt_info;        ///< whitening of the planar rows
  Eigen::Vector3d inv_planar_sigma; ///< 1 / [z, roll, pitch] sigmas
  Eigen::Quaterniond q_base_c;      ///< the camera in the base frame, rotation
  Eigen::Vector3d p_base_c;         ///< ... and translation

  WheelFactor(const WheelPreintegration& pre, const geom::SE3d& T_base_c)
      : delta(pre.delta()),
        inv_planar_sigma(pre.planar_sigma().cwiseInverse()),
        q_base_c(Eigen::Quaterniond(T_base_c.linear()).normalized()),
        p_base_c(T_base_c.translation()) {
    const double floor = pre.noise().planar_floor;
    sqrt_info = sqrt_information<3>(pre.covariance() + floor * floor * Eigen::Matrix3d::Identity());
  }

  /// The relative base pose T_bi_bj from the camera poses.
  template <typename T>
  void relative(const T* pose_i, const T* pose_j, QuatT<T>* q, Vec3T<T>* t) const {
    const CameraPoseT<T> ci(pose_i), cj(pose_j);
    const QuatT<T> q_bc = q_base_c.cast<T>();
    const Vec3T<T> p_bc = p_base_c.cast<T>();
    const Vec3T<T> p_c_base = -(q_bc.conjugate() * p_bc);     // origin of the base in the camera
    const Vec3T<T> p_w = cj.q_c_w.conjugate() * (p_c_base - cj.t_c_w);  // ... at j, in the world
    *t = q_bc * Vec3T<T>(ci.q_c_w * p_w + ci.t_c_w) + p_bc;
    *q = q_bc * ci.q_c_w * cj.q_c_w.conjugate() * q_bc.conjugate();
  }

  template <typename T>
  void residual(const T* pose_i, const T* pose_j, T* r) const {
    using std::atan2;
    using std::sqrt;
    QuatT<T> q;
    Vec3T<T> t;
    relative(pose_i, pose_j, &q, &t);
    const Eigen::Matrix<T, 3, 3> R = q.toRotationMatrix();
    const T yaw = atan2(R(1, 0), R(0, 0));
    const T pitch = atan2(-R(2, 0), sqrt(R(2, 1) * R(2, 1) + R(2, 2) * R(2, 2)));
    const T roll = atan2(R(2, 1), R(2, 2));
    T dyaw = yaw - T(delta.z());
    const T pi(M_PI);
    while (dyaw > pi) dyaw -= T(2) * pi;
    while (dyaw < -pi) dyaw += T(2) * pi;
    const Vec3T<T> e(t.x() - T(delta.x()), t.y() - T(delta.y()), dyaw);
    Eigen::Map<Vec3T<T>> planar(r);
    planar = sqrt_info.cast<T>() * e;
    r[3] = t.z() * T(inv_planar_sigma[0]);
    r[4] = roll * T(inv_planar_sigma[1]);
    r[5] = pitch * T(inv_planar_sigma[2]);
  }
};

/// Gravity direction from an accelerometer without gyro (2 rows): the angle
/// between the measured specific force f_c and the direction of -g_w in the
/// camera, u = R_c_w (-g_w / |g_w|), as a tangent vector at f_c / |f_c|:
///   r = theta / sin(theta) [e1 . (m x u), e2 . (m x u)] / sigma,   m = f_c / |f_c|,
/// e1, e2 an orthonormal basis of the plane orthogonal to m.
struct GravityFactor {
  Eigen::Vector3d m;         ///< measured direction (unit, camera frame)
  Eigen::Vector3d e1, e2;    ///< basis of the tangent plane at m
  Eigen::Vector3d up_w;      ///< -g_w / |g_w|
  double inv_sigma = 0;      ///< 1 / sigma (rad)

  /// Throws std::invalid_argument for a zero force or gravity, or sigma <= 0.
  GravityFactor(const Eigen::Vector3d& f_c, const Eigen::Vector3d& g_w, double sigma_rad) {
    if (!(f_c.norm() > 0) || !(g_w.norm() > 0) || !(sigma_rad > 0))
      throw std::invalid_argument("GravityFactor: needs a non-zero force and gravity and sigma > 0");
    m = f_c.normalized();
    up_w = -g_w.normalized();
    Eigen::Index axis = 0;
    m.cwiseAbs().minCoeff(&axis);
    e1 = m.cross(Eigen::Vector3d::Unit(axis)).normalized();
    e2 = m.cross(e1);
    inv_sigma = 1.0 / sigma_rad;
  }

  template <typename T>
  void residual(const T* pose, T* r) const {
    using std::atan2;
    using std::sqrt;
    const CameraPoseT<T> c(pose);
    const Vec3T<T> u = c.q_c_w * up_w.cast<T>();
    const Vec3T<T> s = m.cast<T>().cross(u);
    const T sin2 = s.squaredNorm();
    T factor = T(inv_sigma);
    if (sin2 > T(1e-20)) {
      const T sin_t = sqrt(sin2);
      factor *= atan2(sin_t, m.cast<T>().dot(u)) / sin_t;
    }
    r[0] = factor * e1.cast<T>().dot(s);
    r[1] = factor * e2.cast<T>().dot(s);
  }
};

}  // namespace pvb::slam
