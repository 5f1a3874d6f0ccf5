#pragma once
// Inertial and wheel terms of local bundle adjustment, and the inertial
// initialisation (gravity, velocities, biases from keyframes whose poses
// vision has fixed).  Plain structs in, results out, as optimizer.hpp.
#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/inertial/imu_preintegration.hpp"
#include "pvb/slam/inertial/wheel_preintegration.hpp"

namespace pvb::slam {

/// A keyframe's inertial state: the IMU's velocity in the world and its biases.
struct BaInertialState {
  Eigen::Vector3d v_w_mps = Eigen::Vector3d::Zero();
  ImuBias bias;
};

/// IMU increments from keyframe i to keyframe j (indices into
/// BaProblem::keyframes): the 9-D inertial residual and the bias random walk.
struct BaImuEdge {
  std::size_t i = 0, j = 0;
  std::shared_ptr<const ImuPreintegration> pre;
};
/// Wheel increments from keyframe i to keyframe j: planar [x, y, yaw] of
/// the base, plus the soft planar constraint [z, roll, pitch].
struct BaWheelEdge {
  std::size_t i = 0, j = 0;
  std::shared_ptr<const WheelPreintegration> pre;
};
/// The mean specific force a keyframe's accelerometer read around its
/// time, in the camera frame: a tilt measurement (camera + accelerometer
/// without gyro).  Residual: the angle between it and -g_w seen from the camera.
struct BaGravityEdge {
  std::size_t keyframe = 0;
  Eigen::Vector3d f_c = Eigen::Vector3d::Zero();
  double sigma_rad = 0.01;
};

struct BaInertial {
  geom::SE3d T_b_c = geom::SE3d::Identity();     ///< the camera in the IMU frame (ORB-SLAM3's IMU.T_b_c1)
  geom::SE3d T_base_c = geom::SE3d::Identity();  ///< the camera in the wheel base frame
  Eigen::Vector3d g_w = Eigen::Vector3d(0, 0, -9.81);  ///< gravity in the world (map) frame
  /// One per BaProblem::keyframes entry; in and out.  A fixed keyframe
  /// keeps its state constant too, unless fixed_states_free.
  std::vector<BaInertialState> states;
  std::vector<BaImuEdge> imu_edges;
  std::vector<BaWheelEdge> wheel_edges;
  std::vector<BaGravityEdge> gravity_edges;
  /// A fixed keyframe's velocity and bias are estimated (its pose held):
  /// the window's biases then follow the data instead of the oldest
  /// keyframe's estimate, which the bias random walk would pin them to.
  bool fixed_states_free = false;
  double wheel_huber = 2.0;  ///< Huber delta of the whitened wheel residual (slip)
  /// > 0: gravity's direction is estimated with the IMU edges (its
  /// magnitude kept), under a prior of this standard deviation about g_w,
  /// and written back to g_w; 0: g_w is held.
  double gravity_sigma_rad = 0;
};

/// Inertial initialisation: keyframe poses from vision (fixed), the IMU
/// increments between consecutive ones; estimates gravity's direction
/// (its magnitude is |g_w_guess|), one bias for all and a velocity per keyframe.
struct InertialInitProblem {
  std::vector<geom::SE3d> T_c_w;                                   ///< keyframes in time order
  std::vector<std::shared_ptr<const ImuPreintegration>> pre;       ///< pre[k]: keyframe k to k + 1
  geom::SE3d T_b_c = geom::SE3d::Identity();
  Eigen::Vector3d g_w_guess = Eigen::Vector3d(0, 0, -9.81);
  ImuBias bias_guess;
  double gyro_bias_prior_radps = 0.01;  ///< sigma of a zero-mean prior on the gyro bias
  double accel_bias_prior_mps2 = 0.1;   ///< sigma of a zero-mean prior on the accelerometer bias
  /// Noise of the fixed keyframe poses (vision's), per pose: position in
  /// metres and rotation in radians.  It is added to each interval's
  /// covariance; without it a millimetre of visual noise over an interval
  /// of a few frames reads as a metre per second squared of acceleration,
  /// which gravity's direction and the biases then absorb.
  double pose_sigma_m = 0;
  double pose_sigma_rad = 0;
};
struct InertialInitResult {
  bool ok = false;
  Eigen::Vector3d g_w = Eigen::Vector3d(0, 0, -9.81);
  ImuBias bias;
  std::vector<Eigen::Vector3d> v_w_mps;  ///< per keyframe
  double rms_whitened = 0;               ///< RMS of the whitened inertial residuals at the solution
};
InertialInitResult initialize_inertial(const InertialInitProblem& problem);

}  // namespace pvb::slam
