#pragma once
// Ceres cost functors for the reprojection residuals of optimizer.hpp.
// Private to pvb_slam_optim (and its tests): callers never see Ceres.
//
// Pose parameterisation: a camera pose T_c_w is two parameter blocks,
//   q_c_w  4 doubles, Eigen's quaternion order (x, y, z, w), on
//          ceres::EigenQuaternionManifold (increment q <- exp(dtheta) * q),
//   t_c_w  3 doubles, Euclidean,
// so p_c = q_c_w * p_w + t_c_w.  Derivatives are automatic (ceres::Jet).
#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "pvb/slam/optim/optimizer.hpp"

namespace pvb::slam::optim_detail {

/// True for a stereo observation (u_right >= 0, 3 residual rows); else monocular (2 rows).
inline bool is_stereo(const Observation& obs) { return obs.u_right >= 0.0; }

/// Weighted reprojection residual shared by all functors:
///   p_c = q_c_w * p_w + t_c_w                    (camera optical frame)
///   u   = fx x_c / z_c + cx,   v = fy y_c / z_c + cy
///   u_r = u - bf / z_c                          (stereo rows only)
///   r   = sqrt(inv_sigma2) * ([u_obs, v_obs(, u_r_obs)] - [u, v(, u_r)])
/// so |r|^2 is the chi2 of ORB-SLAM2's g2o edge with information inv_sigma2 * I
/// (observation_chi2() computes the same number in plain doubles).
/// Returns false (Ceres rejects the step) when the point is not in front of
/// the camera, where the projection is undefined.
template <typename T, int kRows>
bool reprojection_residual(const StereoIntrinsics& K, const Observation& obs, const T* q_c_w_ptr,
                           const T* t_c_w_ptr, const T* p_w_ptr, T* residual_ptr) {
  const Eigen::Map<const Eigen::Quaternion<T>> q_c_w(q_c_w_ptr);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_c_w(t_c_w_ptr);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_w(p_w_ptr);
  Eigen::Map<Eigen::Matrix<T, kRows, 1>> r(residual_ptr);

  const Eigen::Matrix<T, 3, 1> p_c = q_c_w * p_w + t_c_w;
  if (!(p_c.z() > T(0))) return false;
  const T inv_z = T(1) / p_c.z();
  const T u = T(K.fx) * p_c.x() * inv_z + T(K.cx);
  const T v = T(K.fy) * p_c.y() * inv_z + T(K.cy);
  const T w = T(std::sqrt(obs.inv_sigma2));
  r(0) = w * (T(obs.uv.x()) - u);
  r(1) = w * (T(obs.uv.y()) - v);
  if constexpr (kRows == 3) r(2) = w * (T(obs.u_right) - (u - T(K.bf) * inv_z));
  return true;
}

/// Pose-only edge (ORB-SLAM2's EdgeSE3ProjectXYZOnlyPose / EdgeStereoSE3ProjectXYZOnlyPose):
/// the world point p_w is a constant of the functor, the pose is variable.
/// Residual: reprojection_residual() above, kRows = 2 (mono) or 3 (stereo).
/// Parameter blocks: q_c_w (4), t_c_w (3).
template <int kRows>
class PoseOnlyReprojection {
 public:
  PoseOnlyReprojection(const StereoIntrinsics& K, const Observation& obs, const Eigen::Vector3d& p_w)
      : K_(K), obs_(obs), p_w_(p_w) {}

  template <typename T>
  bool operator()(const T* q_c_w, const T* t_c_w, T* residual) const {
    const Eigen::Matrix<T, 3, 1> p_w = p_w_.cast<T>();
    return reprojection_residual<T, kRows>(K_, obs_, q_c_w, t_c_w, p_w.data(), residual);
  }

  static ceres::CostFunction* Create(const StereoIntrinsics& K, const Observation& obs,
                                     const Eigen::Vector3d& p_w) {
    return new ceres::AutoDiffCostFunction<PoseOnlyReprojection, kRows, 4, 3>(
        new PoseOnlyReprojection(K, obs, p_w));
  }

 private:
  StereoIntrinsics K_;
  Observation obs_;
  Eigen::Vector3d p_w_;  ///< world point, fixed in pose-only optimisation
};

/// Bundle-adjustment edge (ORB-SLAM2's EdgeSE3ProjectXYZ / EdgeStereoSE3ProjectXYZ):
/// pose and world point both variable.
/// Residual: reprojection_residual() above, kRows = 2 (mono) or 3 (stereo).
/// Parameter blocks: q_c_w (4), t_c_w (3), p_w (3).
template <int kRows>
class BaReprojection {
 public:
  BaReprojection(const StereoIntrinsics& K, const Observation& obs) : K_(K), obs_(obs) {}

  template <typename T>
  bool operator()(const T* q_c_w, const T* t_c_w, const T* p_w, T* residual) const {
    return reprojection_residual<T, kRows>(K_, obs_, q_c_w, t_c_w, p_w, residual);
  }

  static ceres::CostFunction* Create(const StereoIntrinsics& K, const Observation& obs) {
    return new ceres::AutoDiffCostFunction<BaReprojection, kRows, 4, 3, 3>(new BaReprojection(K, obs));
  }

 private:
  StereoIntrinsics K_;
  Observation obs_;
};

/// Cost function of one pose-only observation, mono or stereo as the observation says.
inline ceres::CostFunction* make_pose_only_cost(const StereoIntrinsics& K, const Observation& obs,
                                                const Eigen::Vector3d& p_w) {
  return is_stereo(obs) ? PoseOnlyReprojection<3>::Create(K, obs, p_w)
                        : PoseOnlyReprojection<2>::Create(K, obs, p_w);
}

/// Cost function of one bundle-adjustment observation, mono or stereo as the observation says.
inline ceres::CostFunction* make_ba_cost(const StereoIntrinsics& K, const Observation& obs) {
  return is_stereo(obs) ? BaReprojection<3>::Create(K, obs) : BaReprojection<2>::Create(K, obs);
}

}  // namespace pvb::slam::optim_detail
