#pragma once
// Ceres cost functions of the inertial and wheel factors
// (pvb/slam/inertial/inertial_residuals.hpp) on the optimiser's blocks:
// camera poses (7, SE3LeftManifold, lifted Jacobians: see residuals.hpp),
// velocities (3) and biases (6, [b_g, b_a]), both Euclidean.
//
// Jacobians by forward-mode automatic differentiation on the tangent
// spaces: each pose block is replaced by Plus(x, d) with d = [omega, rho]
// a 6-vector of jets at 0, each Euclidean block by itself plus jets; the
// derivative with respect to d goes into the first 6 of the 7 pose columns
// and 0 into the 7th, which is what Ceres multiplies by the manifold's
// PlusJacobian [I6; 0].  Private to pvb_slam_optim (and its tests).
#include <ceres/jet.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <array>

#include "pvb/slam/inertial/inertial_residuals.hpp"
#include "residuals.hpp"

namespace pvb::slam::optim_detail {

/// Plus(x, d) of a pose block in scalar T: q <- Exp(omega) q, t <- Exp(omega) t + rho.
template <typename T>
void perturbed_pose(const double* x, const T* d, T* out) {
  const QuatT<T> dq = quaternion_exp_t<T>(Vec3T<T>(d[0], d[1], d[2]));
  const QuatT<T> q = dq * QuatT<T>(T(x[3]), T(x[0]), T(x[1]), T(x[2]));
  const Vec3T<T> t = dq * Vec3T<T>(T(x[4]), T(x[5]), T(x[6])) + Vec3T<T>(d[3], d[4], d[5]);
  out[0] = q.x();
  out[1] = q.y();
  out[2] = q.z();
  out[3] = q.w();
  for (int k = 0; k < 3; ++k) out[4 + k] = t[k];
}

/// A cost function whose Derived::residual<T>(const T* const* blocks, T* r)
/// is differentiated with jets on the tangent spaces.  A block of size 7 is
/// a pose (tangent 6), any other size is Euclidean.
template <class Derived, int kResiduals, int... kBlockSizes>
class TangentJetCost : public ceres::SizedCostFunction<kResiduals, kBlockSizes...> {
 public:
  static constexpr int kNumBlocks = sizeof...(kBlockSizes);
  static constexpr std::array<int, kNumBlocks> kSizes = {kBlockSizes...};
  static constexpr int tangent(int size) { return size == kPoseSize ? kPoseTangent : size; }
  static constexpr int kTangent = (tangent(kBlockSizes) + ...);

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Derived& self = static_cast<const Derived&>(*this);
    if (jacobians == nullptr) {
      self.template residual<double>(parameters, residuals);
      return true;
    }
    using Jet = ceres::Jet<double, kTangent>;
    std::array<std::array<Jet, kPoseSize>, kNumBlocks> storage;
    std::array<const Jet*, kNumBlocks> blocks;
    int offset = 0;
    for (int b = 0; b < kNumBlocks; ++b) {
      if (kSizes[b] == kPoseSize) {
        Jet d[kPoseTangent];
        for (int c = 0; c < kPoseTangent; ++c) d[c] = Jet(0.0, offset + c);
        perturbed_pose(parameters[b], d, storage[b].data());
      } else {
        for (int c = 0; c < kSizes[b]; ++c) storage[b][c] = Jet(parameters[b][c], offset + c);
      }
      blocks[b] = storage[b].data();
      offset += tangent(kSizes[b]);
    }
    Jet r[kResiduals];
    self.template residual<Jet>(blocks.data(), r);
    for (int row = 0; row < kResiduals; ++row) residuals[row] = r[row].a;
    offset = 0;
    for (int b = 0; b < kNumBlocks; ++b) {
      const int n = tangent(kSizes[b]);
      if (jacobians[b] != nullptr) {
        for (int row = 0; row < kResiduals; ++row) {
          double* J = jacobians[b] + row * kSizes[b];
          for (int c = 0; c < n; ++c) J[c] = r[row].v[offset + c];
          if (kSizes[b] == kPoseSize) J[kPoseTangent] = 0.0;  // lifted
        }
      }
      offset += n;
    }
    return true;
  }
};

/// IMU factor (9 rows).  Blocks: pose i, v_i, bias i, pose j, v_j.
class ImuCost final : public TangentJetCost<ImuCost, 9, kPoseSize, 3, 6, kPoseSize, 3> {
 public:
  ImuCost(const ImuPreintegration& pre, const geom::SE3d& T_b_c, const Eigen::Vector3d& g_w)
      : factor_(pre, T_b_c), g_w_(g_w) {}
  template <typename T>
  void residual(const T* const* b, T* r) const {
    const T g[3] = {T(g_w_.x()), T(g_w_.y()), T(g_w_.z())};
    factor_.residual(b[0], b[1], b[2], b[3], b[4], g, r);
  }

 private:
  ImuFactor factor_;
  Eigen::Vector3d g_w_;  ///< gravity in the world
};

/// IMU factor with gravity estimated (9 rows).  Blocks: pose i, v_i,
/// bias i, pose j, v_j, g_w (3, on a sphere of radius |g|).
class ImuCostFreeGravity final : public TangentJetCost<ImuCostFreeGravity, 9, kPoseSize, 3, 6, kPoseSize, 3, 3> {
 public:
  ImuCostFreeGravity(const ImuPreintegration& pre, const geom::SE3d& T_b_c) : factor_(pre, T_b_c) {}
  template <typename T>
  void residual(const T* const* b, T* r) const {
    factor_.residual(b[0], b[1], b[2], b[3], b[4], b[5], r);
  }

 private:
  ImuFactor factor_;
};

/// Prior on gravity's direction (3 rows): (g - g0) / (|g0| sigma).
class GravityPriorCost final : public ceres::SizedCostFunction<3, 3> {
 public:
  GravityPriorCost(const Eigen::Vector3d& g0, double sigma_rad) : g0_(g0), w_(1.0 / (g0.norm() * sigma_rad)) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    for (int k = 0; k < 3; ++k) residuals[k] = w_ * (parameters[0][k] - g0_[k]);
    if (jacobians != nullptr && jacobians[0] != nullptr)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) jacobians[0][r * 3 + c] = r == c ? w_ : 0.0;
    return true;
  }

 private:
  Eigen::Vector3d g0_;
  double w_;
};

/// Bias random walk (6 rows).  Blocks: bias i, bias j.
class BiasWalkCost final : public TangentJetCost<BiasWalkCost, 6, 6, 6> {
 public:
  explicit BiasWalkCost(const ImuPreintegration& pre) : factor_(pre) {}
  template <typename T>
  void residual(const T* const* b, T* r) const {
    factor_.residual(b[0], b[1], r);
  }

 private:
  BiasWalkFactor factor_;
};

/// Wheel factor, rows [kFirst, kFirst + 3) of WheelFactor's 6: 0 the
/// planar increment, 3 the soft planar constraint.  Blocks: pose i, pose j.
template <int kFirst>
class WheelCost final : public TangentJetCost<WheelCost<kFirst>, 3, kPoseSize, kPoseSize> {
 public:
  WheelCost(const WheelPreintegration& pre, const geom::SE3d& T_base_c) : factor_(pre, T_base_c) {}
  template <typename T>
  void residual(const T* const* b, T* r) const {
    T all[6];
    factor_.residual(b[0], b[1], all);
    for (int k = 0; k < 3; ++k) r[k] = all[kFirst + k];
  }

 private:
  WheelFactor factor_;
};
using WheelPlanarCost = WheelCost<0>;
using WheelTiltCost = WheelCost<3>;

/// Gravity direction of a camera (2 rows).  Block: the pose.
class GravityCost final : public TangentJetCost<GravityCost, 2, kPoseSize> {
 public:
  GravityCost(const Eigen::Vector3d& f_c, const Eigen::Vector3d& g_w, double sigma_rad) : factor_(f_c, g_w, sigma_rad) {}
  template <typename T>
  void residual(const T* const* b, T* r) const {
    factor_.residual(b[0], r);
  }

 private:
  GravityFactor factor_;
};

}  // namespace pvb::slam::optim_detail
