#pragma once
// Rigid transforms.  Naming: T_a_b maps points from frame b into frame a,
// p_a = T_a_b * p_b.  Camera frames are optical: x right, y down, z forward.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace pvb::geom {

using SE3d = Eigen::Isometry3d;
using Vec3d = Eigen::Vector3d;
using Mat3d = Eigen::Matrix3d;
using Quatd = Eigen::Quaterniond;

/// Builds a transform from a rotation and a translation.
inline SE3d make_se3(const Mat3d& R, const Vec3d& t) {
  SE3d T = SE3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

/// Builds a transform from a unit quaternion (normalised here) and a translation.
inline SE3d make_se3(const Quatd& q, const Vec3d& t) { return make_se3(q.normalized().toRotationMatrix(), t); }

/// Rotation angle of R in radians, in [0, pi].
inline double rotation_angle_rad(const Mat3d& R) {
  const double c = std::clamp((R.trace() - 1.0) * 0.5, -1.0, 1.0);
  return std::acos(c);
}

/// SO(3) exponential map (Rodrigues).
inline Mat3d so3_exp(const Vec3d& w) {
  const double theta = w.norm();
  if (theta < 1e-12) return Mat3d::Identity();
  return Eigen::AngleAxisd(theta, w / theta).toRotationMatrix();
}

/// SO(3) logarithm, the inverse of so3_exp for angles below pi.
inline Vec3d so3_log(const Mat3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

/// Skew-symmetric matrix [v]x with [v]x * u = v.cross(u).
inline Mat3d skew(const Vec3d& v) {
  Mat3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

/// Rotation from the body frame of a ROS-style camera (x forward, y left,
/// z up) to the optical frame (x right, y down, z forward): R_body_optical.
inline Mat3d R_body_optical() {
  Mat3d R;
  // columns are the optical axes expressed in the body frame
  R << 0, 0, 1,   //
      -1, 0, 0,   //
      0, -1, 0;
  return R;
}

}  // namespace pvb::geom
