#pragma once
// The path of a robot carried by hand from one state to another (a
// scenario's kidnap): lifted, moved and put down, with the velocities of
// both states at its ends, so that an IMU sees a smooth carry and no jump.
#include <Eigen/Core>

#include "pvb/geometry/se3.hpp"

typedef struct mjData_ mjData;

namespace pvb::sim {

/// A free body's state: origin position and linear velocity in the world,
/// orientation, and angular velocity in the body's frame (MuJoCo's free joint).
struct FreeState {
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_w_b = Eigen::Matrix3d::Identity();
  Eigen::Vector3d v_w = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_b = Eigen::Vector3d::Zero();
};

/// The free body's state in `d`: its free joint's positions start at
/// `qpos`, its velocities at `dof`.
FreeState free_state(const mjData* d, int qpos, int dof);
/// Sets that state in `d` (positions and velocities of the free joint).
void set_free_state(mjData* d, int qpos, int dof, const FreeState& f);

/// Position: a quintic Hermite curve between the two states' positions and
/// velocities with no acceleration at either end, plus a lift of
/// kLiftM 64 s^3 (1 - s)^3 (s = t / T).  Orientation:
/// R_a Exp(phi(t)), phi such a curve from 0 to Log(R_a^T R_b) whose
/// end tangents give the two states' angular velocities (through the
/// right Jacobian of SO(3)).
class CarryPath {
 public:
  static constexpr double kLiftM = 0.30;
  CarryPath(const FreeState& a, const FreeState& b, double duration_s);
  /// The state at t in [0, duration]: a at 0, b at the end.
  FreeState at(double t_s) const;
  double duration_s() const { return T_; }

 private:
  FreeState a_, b_;
  double T_;
  Eigen::Vector3d phi_b_, dphi_a_, dphi_b_;
};

/// SO(3)'s right Jacobian: d Exp(phi) = Exp(phi) Exp(J_r(phi) d phi) to first order.
Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi);

}  // namespace pvb::sim
