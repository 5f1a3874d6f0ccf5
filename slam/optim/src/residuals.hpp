#pragma once
// Ceres cost functions for the reprojection residuals of optimizer.hpp, with
// analytic Jacobians on an SE(3) manifold.  Private to pvb_slam_optim (and
// its tests): callers never see Ceres.
//
// Pose parameterisation: a camera pose T_c_w is ONE parameter block of 7
// doubles,
//   [q_c_w (x, y, z, w, Eigen's order), t_c_w (3)],   p_c = q_c_w * p_w + t_c_w,
// on SE3LeftManifold: tangent delta = [omega (3), rho (3)], the update of
// g2o's SE3Quat that ORB-SLAM2 uses,
//   T_c_w <- [Exp(omega) | rho] * T_c_w,  i.e.  R <- Exp(omega) R,  t <- Exp(omega) t + rho.
//
// Jacobians are "lifted" (as in VINS-Mono or OKVIS): the cost functions
// return d r / d delta in the first 6 columns of their 7-column pose
// Jacobian and 0 in the last, and the manifold's PlusJacobian is [I6; 0],
// so Ceres' product J * PlusJacobian is exactly d r / d delta.  The 7
// columns are therefore NOT derivatives with respect to the quaternion
// components; tests compare the 6 tangent columns with numeric derivatives
// of r(Plus(x, delta)) at delta = 0.
#include <ceres/jet.h>
#include <ceres/manifold.h>
#include <ceres/rotation.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "pvb/slam/optim/optimizer.hpp"

namespace pvb::slam::optim_detail {

constexpr int kPoseSize = 7;     ///< ambient size of a pose block: q (4) + t (3)
constexpr int kPoseTangent = 6;  ///< tangent size: omega (3) + rho (3)

/// True for a stereo observation (u_right >= 0, 3 residual rows); else monocular (2 rows).
inline bool is_stereo(const Observation& obs) { return obs.u_right >= 0.0; }

/// Unit quaternion of the rotation vector omega (Exp(omega)), exact for any angle.
inline Eigen::Quaterniond quaternion_exp(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  if (theta < 1e-10) {
    // Second order: q = (omega / 2, 1 - theta^2 / 8), then normalised.
    Eigen::Quaterniond q(1.0 - theta * theta / 8.0, 0.5 * omega.x(), 0.5 * omega.y(), 0.5 * omega.z());
    return q.normalized();
  }
  const double s = std::sin(0.5 * theta) / theta;
  return Eigen::Quaterniond(std::cos(0.5 * theta), s * omega.x(), s * omega.y(), s * omega.z());
}

/// Rotation vector of a unit quaternion (Log), angle in [0, pi].
inline Eigen::Vector3d quaternion_log(Eigen::Quaterniond q) {
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // same rotation, angle <= pi
  const double vn = q.vec().norm();
  if (vn < 1e-10) return 2.0 * q.vec() / q.w();
  return (2.0 * std::atan2(vn, q.w()) / vn) * q.vec();
}

/// SE(3) with the left update T <- [Exp(omega) | rho] * T on the 7-double
/// block described at the top of this file, with lifted Jacobians.
class SE3LeftManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseSize; }
  int TangentSize() const override { return kPoseTangent; }

  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    const Eigen::Map<const Eigen::Quaterniond> q(x);
    const Eigen::Map<const Eigen::Vector3d> t(x + 4);
    const Eigen::Map<const Eigen::Vector3d> omega(delta), rho(delta + 3);
    const Eigen::Quaterniond dq = quaternion_exp(omega);
    const Eigen::Vector3d t_new = dq * t + rho;  // before writing: x may alias x_plus_delta
    Eigen::Map<Eigen::Quaterniond> q_out(x_plus_delta);
    Eigen::Map<Eigen::Vector3d> t_out(x_plus_delta + 4);
    q_out = (dq * q).normalized();
    t_out = t_new;
    return true;
  }

  /// Lifted: [I6; 0] (see the top of this file).
  bool PlusJacobian(const double* /*x*/, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, kPoseSize, kPoseTangent, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.topRows<kPoseTangent>().setIdentity();
    return true;
  }

  /// delta with Plus(x, delta) = y: omega = Log(q_y q_x^-1), rho = t_y - Exp(omega) t_x.
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    const Eigen::Map<const Eigen::Quaterniond> q_x(x), q_y(y);
    const Eigen::Map<const Eigen::Vector3d> t_x(x + 4), t_y(y + 4);
    const Eigen::Quaterniond dq = (q_y * q_x.conjugate()).normalized();
    Eigen::Map<Eigen::Vector3d> omega(y_minus_x), rho(y_minus_x + 3);
    omega = quaternion_log(dq);
    rho = t_y - dq * t_x;
    return true;
  }

  /// Lifted: [I6 0], the counterpart of PlusJacobian.
  bool MinusJacobian(const double* /*x*/, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, kPoseTangent, kPoseSize, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.leftCols<kPoseTangent>().setIdentity();
    return true;
  }
};

/// Writes a pose block from T_c_w (quaternion normalised).
inline void pose_to_block(const geom::SE3d& T_c_w, double* pose) {
  Eigen::Map<Eigen::Quaterniond> q_c_w(pose);
  Eigen::Map<Eigen::Vector3d> t_c_w(pose + 4);
  q_c_w = Eigen::Quaterniond(Eigen::Matrix3d(T_c_w.linear())).normalized();
  t_c_w = T_c_w.translation();
}

/// T_c_w of a pose block.
inline geom::SE3d block_to_pose(const double* pose) {
  return geom::make_se3(Eigen::Quaterniond(Eigen::Map<const Eigen::Quaterniond>(pose)),
                        Eigen::Vector3d(Eigen::Map<const Eigen::Vector3d>(pose + 4)));
}

/// Weighted reprojection residual of one observation and its Jacobians:
///   p_c = R_c_w p_w + t_c_w                     (camera optical frame)
///   u   = fx x / z + cx,   v = fy y / z + cy
///   u_r = u - bf / z                            (stereo rows only)
///   r   = w ([u_obs, v_obs(, u_r_obs)] - [u, v(, u_r)]),   w = sqrt(inv_sigma2)
/// so |r|^2 is the chi2 of ORB-SLAM2's g2o edge with information inv_sigma2 * I
/// (observation_chi2() computes the same number).
///
/// With P = d[u, v(, u_r)] / d p_c
///   = [ fx/z   0     -fx x / z^2        ]
///     [ 0      fy/z  -fy y / z^2        ]
///     [ fx/z   0     (bf - fx x) / z^2  ]   (stereo row)
/// and d p_c / d delta = [ -[p_c]x | I ] for the left update above,
///   d r / d delta = -w P [ -[p_c]x | I ],    d r / d p_w = -w P R_c_w.
/// Returns false (Ceres rejects the step) when the point is not in front of
/// the camera, where the projection is undefined.
template <int kRows>
bool reprojection(const StereoIntrinsics& K, const Observation& obs, const double* pose, const Eigen::Vector3d& p_w,
                  double* residual, double* J_pose /* kRows x 7 row-major, may be null */,
                  double* J_point /* kRows x 3 row-major, may be null */) {
  const Eigen::Map<const Eigen::Quaterniond> q_c_w(pose);
  const Eigen::Map<const Eigen::Vector3d> t_c_w(pose + 4);
  const Eigen::Matrix3d R_c_w = q_c_w.toRotationMatrix();
  const Eigen::Vector3d p_c = R_c_w * p_w + t_c_w;
  if (!(p_c.z() > 0.0)) return false;
  const double inv_z = 1.0 / p_c.z();
  const double u = K.fx * p_c.x() * inv_z + K.cx;
  const double v = K.fy * p_c.y() * inv_z + K.cy;
  const double w = std::sqrt(obs.inv_sigma2);
  residual[0] = w * (obs.uv.x() - u);
  residual[1] = w * (obs.uv.y() - v);
  if constexpr (kRows == 3) residual[2] = w * (obs.u_right - (u - K.bf * inv_z));
  if (J_pose == nullptr && J_point == nullptr) return true;

  // D = -w P: the derivative of r with respect to p_c.
  const double inv_z2 = inv_z * inv_z;
  Eigen::Matrix<double, kRows, 3> D;
  D(0, 0) = -w * K.fx * inv_z;
  D(0, 1) = 0.0;
  D(0, 2) = w * K.fx * p_c.x() * inv_z2;
  D(1, 0) = 0.0;
  D(1, 1) = -w * K.fy * inv_z;
  D(1, 2) = w * K.fy * p_c.y() * inv_z2;
  if constexpr (kRows == 3) {
    D(2, 0) = D(0, 0);
    D(2, 1) = 0.0;
    D(2, 2) = -w * (K.bf - K.fx * p_c.x()) * inv_z2;
  }
  if (J_pose != nullptr) {
    Eigen::Map<Eigen::Matrix<double, kRows, kPoseSize, Eigen::RowMajor>> J(J_pose);
    // D * (-[p_c]x) column by column: -[p_c]x = [[0, z, -y], [-z, 0, x], [y, -x, 0]].
    J.col(0) = D.col(1) * (-p_c.z()) + D.col(2) * p_c.y();
    J.col(1) = D.col(0) * p_c.z() - D.col(2) * p_c.x();
    J.col(2) = -D.col(0) * p_c.y() + D.col(1) * p_c.x();
    J.template block<kRows, 3>(0, 3) = D;
    J.col(6).setZero();  // lifted: the 7th ambient column is unused
  }
  if (J_point != nullptr) {
    Eigen::Map<Eigen::Matrix<double, kRows, 3, Eigen::RowMajor>> J(J_point);
    J = D * R_c_w;
  }
  return true;
}

/// Pose-only edge (ORB-SLAM2's EdgeSE3ProjectXYZOnlyPose / EdgeStereoSE3ProjectXYZOnlyPose):
/// the world point p_w is a constant, the pose is variable.
/// Residual and Jacobian: reprojection() above, kRows = 2 (mono) or 3 (stereo).
/// Parameter block: the pose (7, SE3LeftManifold).
template <int kRows>
class PoseOnlyReprojection final : public ceres::SizedCostFunction<kRows, kPoseSize> {
 public:
  PoseOnlyReprojection(const StereoIntrinsics& K, const Observation& obs, const Eigen::Vector3d& p_w)
      : K_(K), obs_(obs), p_w_(p_w) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    return reprojection<kRows>(K_, obs_, parameters[0], p_w_, residuals,
                               jacobians != nullptr ? jacobians[0] : nullptr, nullptr);
  }

 private:
  StereoIntrinsics K_;
  Observation obs_;
  Eigen::Vector3d p_w_;  ///< world point, fixed in pose-only optimisation
};

/// Bundle-adjustment edge (ORB-SLAM2's EdgeSE3ProjectXYZ / EdgeStereoSE3ProjectXYZ):
/// pose and world point both variable.
/// Residual and Jacobians: reprojection() above, kRows = 2 (mono) or 3 (stereo).
/// Parameter blocks: the pose (7, SE3LeftManifold), p_w (3).
template <int kRows>
class BaReprojection final : public ceres::SizedCostFunction<kRows, kPoseSize, 3> {
 public:
  BaReprojection(const StereoIntrinsics& K, const Observation& obs) : K_(K), obs_(obs) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> p_w(parameters[1]);
    return reprojection<kRows>(K_, obs_, parameters[0], p_w, residuals,
                               jacobians != nullptr ? jacobians[0] : nullptr,
                               jacobians != nullptr ? jacobians[1] : nullptr);
  }

 private:
  StereoIntrinsics K_;
  Observation obs_;
};

/// Normal equations of the pose-only problem at one pose: H = sum J^T w J,
/// g = sum J^T w r over the active observations (J = d r / d delta, 6
/// columns of reprojection()'s lifted Jacobian), and the robust cost
/// 0.5 sum rho(|r|^2).  w = rho'(|r|^2) is the Huber IRLS weight (1 inside
/// the threshold, delta / |r| outside; g2o's robustified information, as
/// ORB-SLAM2 uses it).  Returns false if a point is not in front of the camera.
struct PoseNormalEquations {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  double cost = 0.0;
};

/// Huber rho(s) and rho'(s) of a squared residual s with threshold delta^2 = chi2.
inline void huber_rho(double s, double chi2, bool robust, double* rho, double* drho) {
  if (!robust || s <= chi2) {
    *rho = s;
    *drho = 1.0;
    return;
  }
  const double delta = std::sqrt(chi2), r = std::sqrt(s);
  *rho = 2.0 * delta * r - chi2;
  *drho = delta / r;
}

/// H += w J J^T (upper triangle only) and g += w r J for one residual row.
inline void accumulate_upper(const Eigen::Matrix<double, 6, 1>& J, double w, double r, Eigen::Matrix<double, 6, 6>* H,
                             Eigen::Matrix<double, 6, 1>* g) {
  for (int c = 0; c < 6; ++c) {
    const double wj = w * J[c];
    for (int k = 0; k <= c; ++k) (*H)(k, c) += wj * J[k];
    (*g)[c] += wj * r;
  }
}

template <bool kWithJacobian>
inline bool pose_normal_equations(const StereoIntrinsics& K, const std::vector<Eigen::Vector3d>& points_w,
                           const std::vector<Observation>& obs, const std::vector<std::size_t>& active, bool robust,
                           const PoseOptimizerOptions& options, const double* pose, PoseNormalEquations* out) {
  // The residual and Jacobian of reprojection() above, with the rotation
  // computed once per evaluation instead of once per observation;
  // test_residuals compares the two and the gradient with numeric ones.
  *out = PoseNormalEquations();
  const Eigen::Map<const Eigen::Quaterniond> q_c_w(pose);
  const Eigen::Map<const Eigen::Vector3d> t_c_w(pose + 4);
  const Eigen::Matrix3d R_c_w = q_c_w.toRotationMatrix();
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  double cost = 0.0;
  for (std::size_t i : active) {
    const Observation& o = obs[i];
    const bool stereo = is_stereo(o);
    const Eigen::Vector3d p_c = R_c_w * points_w[i] + t_c_w;
    if (!(p_c.z() > 0.0)) return false;
    const double inv_z = 1.0 / p_c.z();
    const double u = K.fx * p_c.x() * inv_z + K.cx;
    const double v = K.fy * p_c.y() * inv_z + K.cy;
    const double w = std::sqrt(o.inv_sigma2);
    const double r0 = w * (o.uv.x() - u), r1 = w * (o.uv.y() - v);
    const double r2 = stereo ? w * (o.u_right - (u - K.bf * inv_z)) : 0.0;
    const double s = r0 * r0 + r1 * r1 + r2 * r2;
    double rho, drho;
    huber_rho(s, stereo ? options.chi2_stereo : options.chi2_mono, robust, &rho, &drho);
    cost += 0.5 * rho;
    if constexpr (kWithJacobian) {
      // Rows of d r / d delta = D [ -[p_c]x | I ] with D = d r / d p_c.
      const double x = p_c.x(), y = p_c.y(), z = p_c.z();
      const double inv_z2 = inv_z * inv_z;
      const double d00 = -w * K.fx * inv_z, d02 = w * K.fx * x * inv_z2;
      const double d11 = -w * K.fy * inv_z, d12 = w * K.fy * y * inv_z2;
      Eigen::Matrix<double, 6, 1> J0, J1;
      J0 << d02 * y, d00 * z - d02 * x, -d00 * y, d00, 0.0, d02;
      J1 << -d11 * z + d12 * y, -d12 * x, d11 * x, 0.0, d11, d12;
      accumulate_upper(J0, drho, r0, &H, &g);
      accumulate_upper(J1, drho, r1, &H, &g);
      if (stereo) {
        const double d22 = -w * (K.bf - K.fx * x) * inv_z2;
        Eigen::Matrix<double, 6, 1> J2;
        J2 << d22 * y, d00 * z - d22 * x, -d00 * y, d00, 0.0, d22;
        accumulate_upper(J2, drho, r2, &H, &g);
      }
    }
  }
  if constexpr (kWithJacobian) {
    out->H = H.selfadjointView<Eigen::Upper>();
    out->g = g;
  }
  out->cost = cost;
  return true;
}
/// Relative-pose edge of the SE(3) pose graph (optimize_pose_graph):
///   E = M T_i T_j^-1,  M = T_i_j(measured)^-1,  T_i = T_iw, T_j = T_jw,
///   r = w [w_r Log(R_E); t_E]                   (6 rows)
/// Jacobians with respect to the left updates T <- [Exp(omega) | rho] T of
/// both poses, lifted as above (columns 0-5, column 6 zero), computed by
/// forward-mode automatic differentiation of r(Plus(x_i, d_i), Plus(x_j, d_j))
/// at d = 0 with 12-dimensional jets.
/// Parameter blocks: pose i (7), pose j (7), both on SE3LeftManifold.
class RelativePoseError final : public ceres::SizedCostFunction<6, kPoseSize, kPoseSize> {
 public:
  RelativePoseError(const geom::SE3d& T_i_j, double weight, double rotation_weight = 1.0)
      : q_m_(Eigen::Quaterniond(Eigen::Matrix3d(T_i_j.inverse().linear())).normalized()),
        t_m_(T_i_j.inverse().translation()),
        weight_(weight),
        rotation_weight_(rotation_weight) {}

  /// The residual at the perturbed poses (d = [omega, rho] for each).
  template <typename T>
  void residual(const double* x_i, const double* x_j, const T* d_i, const T* d_j, T* r) const {
    using Quat = Eigen::Quaternion<T>;
    using Vec3 = Eigen::Matrix<T, 3, 1>;
    const auto perturbed = [](const double* x, const T* d, Quat* q, Vec3* t) {
      T q_ceres[4];  // Ceres' order: w, x, y, z
      ceres::AngleAxisToQuaternion(d, q_ceres);
      const Quat dq(q_ceres[0], q_ceres[1], q_ceres[2], q_ceres[3]);
      const Quat q0{T{x[3]}, T{x[0]}, T{x[1]}, T{x[2]}};
      const Vec3 t0{T{x[4]}, T{x[5]}, T{x[6]}};
      *q = dq * q0;
      *t = dq * t0 + Vec3(d[3], d[4], d[5]);
    };
    Quat q_i, q_j;
    Vec3 t_i, t_j;
    perturbed(x_i, d_i, &q_i, &t_i);
    perturbed(x_j, d_j, &q_j, &t_j);
    const Quat q_j_inv = q_j.conjugate();
    const Vec3 t_j_inv = -(q_j_inv * t_j);
    const Quat q_m = q_m_.cast<T>();
    const Vec3 t_m = t_m_.cast<T>();
    // E = M * T_i * T_j^-1
    const Quat q_ij = q_i * q_j_inv;
    const Vec3 t_ij = q_i * t_j_inv + t_i;
    const Quat q_e = q_m * q_ij;
    const Vec3 t_e = q_m * t_ij + t_m;
    const T q_e_ceres[4] = {q_e.w(), q_e.x(), q_e.y(), q_e.z()};
    ceres::QuaternionToAngleAxis(q_e_ceres, r);
    for (int k = 0; k < 3; ++k) {
      r[k] *= T(weight_ * rotation_weight_);
      r[3 + k] = T(weight_) * t_e[k];
    }
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const bool want_jacobians = jacobians != nullptr && (jacobians[0] != nullptr || jacobians[1] != nullptr);
    if (!want_jacobians) {
      const double zero[6] = {0, 0, 0, 0, 0, 0};
      residual<double>(parameters[0], parameters[1], zero, zero, residuals);
      return true;
    }
    using Jet = ceres::Jet<double, 12>;
    Jet d_i[6], d_j[6], r[6];
    for (int k = 0; k < 6; ++k) {
      d_i[k] = Jet(0.0, k);
      d_j[k] = Jet(0.0, 6 + k);
    }
    residual<Jet>(parameters[0], parameters[1], d_i, d_j, r);
    for (int row = 0; row < 6; ++row) {
      residuals[row] = r[row].a;
      for (int b = 0; b < 2; ++b) {
        if (jacobians[b] == nullptr) continue;
        double* J = jacobians[b] + row * kPoseSize;
        for (int c = 0; c < kPoseTangent; ++c) J[c] = r[row].v[6 * b + c];
        J[6] = 0.0;  // lifted
      }
    }
    return true;
  }

 private:
  Eigen::Quaterniond q_m_;  ///< rotation of M = T_i_j^-1
  Eigen::Vector3d t_m_;     ///< translation of M
  double weight_;
  double rotation_weight_;
};

/// Cost function of one pose-only observation, mono or stereo as the observation says.
inline ceres::CostFunction* make_pose_only_cost(const StereoIntrinsics& K, const Observation& obs,
                                                const Eigen::Vector3d& p_w) {
  if (is_stereo(obs)) return new PoseOnlyReprojection<3>(K, obs, p_w);
  return new PoseOnlyReprojection<2>(K, obs, p_w);
}

/// Cost function of one bundle-adjustment observation, mono or stereo as the observation says.
inline ceres::CostFunction* make_ba_cost(const StereoIntrinsics& K, const Observation& obs) {
  if (is_stereo(obs)) return new BaReprojection<3>(K, obs);
  return new BaReprojection<2>(K, obs);
}

}  // namespace pvb::slam::optim_detail
