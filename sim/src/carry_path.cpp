#include "carry_path.hpp"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace pvb::sim {
namespace {

/// Quintic Hermite basis at s in [0, 1] for end values and end tangents
/// with zero second derivative at both ends, and its derivatives in s.
struct Hermite {
  double h00, h10, h01, h11;
  double d00, d10, d01, d11;
  explicit Hermite(double s) {
    const double s2 = s * s, s3 = s2 * s, s4 = s3 * s, s5 = s4 * s;
    h00 = 1 - 10 * s3 + 15 * s4 - 6 * s5;
    h10 = s - 6 * s3 + 8 * s4 - 3 * s5;
    h01 = 10 * s3 - 15 * s4 + 6 * s5;
    h11 = -4 * s3 + 7 * s4 - 3 * s5;
    d00 = -30 * s2 + 60 * s3 - 30 * s4;
    d10 = 1 - 18 * s2 + 32 * s3 - 15 * s4;
    d01 = 30 * s2 - 60 * s3 + 30 * s4;
    d11 = -12 * s2 + 28 * s3 - 15 * s4;
  }
};

}  // namespace

FreeState free_state(const mjData* d, int qpos, int dof) {
  FreeState f;
  f.p_w = Eigen::Vector3d(d->qpos + qpos);
  const mjtNum* q = d->qpos + qpos + 3;
  f.R_w_b = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  f.v_w = Eigen::Vector3d(d->qvel + dof);
  f.w_b = Eigen::Vector3d(d->qvel + dof + 3);
  return f;
}

void set_free_state(mjData* d, int qpos, int dof, const FreeState& f) {
  const Eigen::Quaterniond q(f.R_w_b);
  const mjtNum values[7] = {f.p_w.x(), f.p_w.y(), f.p_w.z(), q.w(), q.x(), q.y(), q.z()};
  std::copy(values, values + 7, d->qpos + qpos);
  for (int i = 0; i < 3; ++i) {
    d->qvel[dof + i] = f.v_w[i];
    d->qvel[dof + 3 + i] = f.w_b[i];
  }
}

Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi) {
  const double th = phi.norm();
  const Eigen::Matrix3d K = geom::skew(phi);
  if (th < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 6.0;
  return Eigen::Matrix3d::Identity() - (1 - std::cos(th)) / (th * th) * K +
         (th - std::sin(th)) / (th * th * th) * K * K;
}

CarryPath::CarryPath(const FreeState& a, const FreeState& b, double duration_s) : a_(a), b_(b), T_(duration_s) {
  phi_b_ = geom::so3_log(a.R_w_b.transpose() * b.R_w_b);
  dphi_a_ = a.w_b;
  dphi_b_ = so3_right_jacobian(phi_b_).inverse() * b.w_b;
}

FreeState CarryPath::at(double t_s) const {
  const double s = std::max(0.0, std::min(1.0, t_s / T_));
  const Hermite h(s);
  FreeState out;
  out.p_w = h.h00 * a_.p_w + h.h10 * T_ * a_.v_w + h.h01 * b_.p_w + h.h11 * T_ * b_.v_w;
  out.v_w = (h.d00 * a_.p_w + h.d10 * T_ * a_.v_w + h.d01 * b_.p_w + h.d11 * T_ * b_.v_w) / T_;
  // the lift: 64 s^3 (1 - s)^3, 1 at s = 1/2, flat to the second derivative at both ends
  const double u = s * (1 - s);
  out.p_w.z() += kLiftM * 64 * u * u * u;
  out.v_w.z() += kLiftM * 64 * 3 * u * u * (1 - 2 * s) / T_;
  const Eigen::Vector3d phi = h.h10 * T_ * dphi_a_ + h.h01 * phi_b_ + h.h11 * T_ * dphi_b_;
  const Eigen::Vector3d dphi = (h.d10 * T_ * dphi_a_ + h.d01 * phi_b_ + h.d11 * T_ * dphi_b_) / T_;
  out.R_w_b = a_.R_w_b * geom::so3_exp(phi);
  out.w_b = so3_right_jacobian(phi) * dphi;
  if (s >= 1.0) out = b_;  // exactly the target at the end
  return out;
}

}  // namespace pvb::sim
