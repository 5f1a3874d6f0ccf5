#pragma once
// IMU preintegration on the manifold (Forster, Carlone, Dellaert and
// Scaramuzza, "On-Manifold Preintegration for Real-Time Visual-Inertial
// Odometry", T-RO 2017): the rotation, velocity and position increments
// between two instants from the readings between them, their covariance,
// and their first-order Jacobians with respect to the biases, so that a
// bias update corrects the increments without integrating again.
//
// Frames: b is the IMU's frame, w a world frame whose gravity is g_w.
// Readings are means over their period (sensor::ImuSample): one reading is
// held constant over its dt.
//
// Memory stays bounded however long the interval (a robot parked for an
// hour makes no keyframe): past kFoldAt readings the oldest kFoldCount are
// folded into increments of their own, which a new bias corrects to first
// order instead of integrating them again.
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "pvb/sensor/motion.hpp"

namespace pvb::slam {

struct ImuBias {
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
};

/// The IMU's navigation state: attitude, velocity and position of the IMU
/// frame in the world.
struct NavState {
  Eigen::Matrix3d R_w_b = Eigen::Matrix3d::Identity();
  Eigen::Vector3d v_w_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_w_m = Eigen::Vector3d::Zero();
};

class ImuPreintegration {
 public:
  /// One reading as integrated: held over dt_s.
  struct Reading {
    Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
    Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
    double dt_s = 0;
  };

  /// Readings kept to integrate again; reaching this many folds the oldest
  /// kFoldCount (about 10 s at 200 Hz).
  static constexpr std::size_t kFoldAt = 4096;
  static constexpr std::size_t kFoldCount = 2048;

  ImuPreintegration() = default;
  /// Empty: identity increments at linearisation bias `bias`.
  ImuPreintegration(const ImuBias& bias, const sensor::ImuNoise& noise);

  /// Adds one reading held constant over dt_s (> 0) and propagates the
  /// covariance (discrete noise: density^2 / dt) and the bias Jacobians.
  /// The specific force is rotated by the attitude at the middle of the
  /// period (the reading is a mean over it).  Throws std::invalid_argument
  /// for dt_s <= 0.
  void integrate(const Eigen::Vector3d& gyro_radps, const Eigen::Vector3d& accel_mps2, double dt_s);
  /// Appends the readings of `next` (which starts where this one ends),
  /// integrated at this one's bias; the part `next` has folded is joined
  /// by its increments, corrected to this one's bias.
  void append(const ImuPreintegration& next);
  /// Integrates every kept reading again at a new linearisation bias,
  /// after the folded ones corrected to it to first order.
  void reintegrate(const ImuBias& bias);

  double dt_s() const { return dt_s_; }
  /// Readings integrated, folded ones included.
  std::size_t size() const { return folded_count_ + readings_.size(); }
  /// The readings kept (the newest; at most kFoldAt - 1).
  const std::vector<Reading>& readings() const { return readings_; }
  std::size_t folded_count() const { return folded_count_; }
  const ImuBias& bias() const { return bias_; }
  const sensor::ImuNoise& noise() const { return noise_; }

  /// Increments at the linearisation bias.
  const Eigen::Matrix3d& delta_R() const { return dR_; }
  const Eigen::Vector3d& delta_v() const { return dv_; }
  const Eigen::Vector3d& delta_p() const { return dp_; }
  /// Increments corrected to first order for bias b (Forster eq. 44):
  /// dR Exp(J_R_bg dbg), dv + J_v_bg dbg + J_v_ba dba, dp + ...
  Eigen::Matrix3d delta_R(const ImuBias& b) const;
  Eigen::Vector3d delta_v(const ImuBias& b) const;
  Eigen::Vector3d delta_p(const ImuBias& b) const;

  /// Bias Jacobians of the increments at the linearisation bias.
  const Eigen::Matrix3d& J_R_bg() const { return J_R_bg_; }
  const Eigen::Matrix3d& J_v_bg() const { return J_v_bg_; }
  const Eigen::Matrix3d& J_v_ba() const { return J_v_ba_; }
  const Eigen::Matrix3d& J_p_bg() const { return J_p_bg_; }
  const Eigen::Matrix3d& J_p_ba() const { return J_p_ba_; }

  /// Covariance of the increment errors, order [rotation, velocity, position].
  const Eigen::Matrix<double, 9, 9>& covariance() const { return cov_; }

  /// The state at the end from the state at the start, gravity g_w and
  /// bias b (Forster eq. 33 with the corrected increments).
  NavState predict(const NavState& start, const Eigen::Vector3d& g_w, const ImuBias& b) const;

 private:
  /// The increments, their bias Jacobians and covariance of a stretch of
  /// readings at linearisation bias `bias`.
  struct Increments {
    ImuBias bias;
    double dt_s = 0;
    Eigen::Matrix3d dR, J_R_bg, J_v_bg, J_v_ba, J_p_bg, J_p_ba;
    Eigen::Vector3d dv, dp;
    Eigen::Matrix<double, 9, 9> cov;
  };
  Increments increments() const;
  /// f's increments at bias b, corrected to first order (eq. 44); its
  /// Jacobians and covariance are kept.
  static Increments corrected(const Increments& f, const ImuBias& b);
  /// No readings kept: the state is f's.
  void start_from(const Increments& f);
  /// Composes `s` (at this bias, starting where this ends) onto the end.
  void compose(const Increments& s);
  void fold_oldest(std::size_t n);

  ImuBias bias_;
  sensor::ImuNoise noise_;
  std::vector<Reading> readings_;
  std::optional<Increments> folded_;  ///< the readings before readings_, if any were folded
  std::size_t folded_count_ = 0;
  double dt_s_ = 0;
  Eigen::Matrix3d dR_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d dv_ = Eigen::Vector3d::Zero(), dp_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d J_R_bg_ = Eigen::Matrix3d::Zero(), J_v_bg_ = Eigen::Matrix3d::Zero(),
                  J_v_ba_ = Eigen::Matrix3d::Zero(), J_p_bg_ = Eigen::Matrix3d::Zero(),
                  J_p_ba_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 9, 9> cov_ = Eigen::Matrix<double, 9, 9>::Zero();
};

/// The right Jacobian of SO(3) and its inverse (Forster eq. 8); the
/// exponential and logarithm are geom::so3_exp and geom::so3_log.
Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi);
Eigen::Matrix3d so3_right_jacobian_inverse(const Eigen::Vector3d& phi);

}  // namespace pvb::slam
