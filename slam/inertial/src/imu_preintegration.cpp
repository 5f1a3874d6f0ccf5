// IMU preintegration (Forster et al., T-RO 2017, section VI and appendix).
#include "pvb/slam/inertial/imu_preintegration.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "pvb/geometry/se3.hpp"

namespace pvb::slam {
namespace {

/// Below this angle (rad) the Jacobians use their Taylor series.
constexpr double kSmallAngle = 1e-5;

/// Re-orthonormalises a rotation that products have made drift.
Eigen::Matrix3d orthonormalised(const Eigen::Matrix3d& R) {
  return Eigen::Quaterniond(R).normalized().toRotationMatrix();
}

void check_finite_positive(double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) {
    throw std::invalid_argument("ImuPreintegration::integrate: dt_s must be positive and finite, got " +
                                std::to_string(dt_s));
  }
}

}  // namespace

Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi) {
  // Jr = I - (1 - cos t) / t^2 [phi]x + (t - sin t) / t^3 [phi]x^2.
  const double t = phi.norm();
  const Eigen::Matrix3d S = geom::skew(phi);
  if (t < kSmallAngle) return Eigen::Matrix3d::Identity() - 0.5 * S + (1.0 / 6.0) * S * S;
  const double t2 = t * t;
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(t)) / t2 * S + (t - std::sin(t)) / (t2 * t) * S * S;
}

Eigen::Matrix3d so3_right_jacobian_inverse(const Eigen::Vector3d& phi) {
  // Jr^-1 = I + 1/2 [phi]x + (1 / t^2 - (1 + cos t) / (2 t sin t)) [phi]x^2.
  const double t = phi.norm();
  const Eigen::Matrix3d S = geom::skew(phi);
  if (t < kSmallAngle) return Eigen::Matrix3d::Identity() + 0.5 * S + (1.0 / 12.0) * S * S;
  const double c = 1.0 / (t * t) - (1.0 + std::cos(t)) / (2.0 * t * std::sin(t));
  return Eigen::Matrix3d::Identity() + 0.5 * S + c * S * S;
}

ImuPreintegration::ImuPreintegration(const ImuBias& bias, const sensor::ImuNoise& noise) : bias_(bias), noise_(noise) {}

void ImuPreintegration::integrate(const Eigen::Vector3d& gyro_radps, const Eigen::Vector3d& accel_mps2, double dt_s) {
  check_finite_positive(dt_s);
  readings_.push_back(Reading{gyro_radps, accel_mps2, dt_s});
  const Eigen::Vector3d w = gyro_radps - bias_.gyro_radps;
  const Eigen::Vector3d a = accel_mps2 - bias_.accel_mps2;
  const double dt2 = dt_s * dt_s;
  const Eigen::Vector3d phi = w * dt_s;
  const Eigen::Matrix3d dR_k = geom::so3_exp(phi);
  const Eigen::Matrix3d Jr_k = so3_right_jacobian(phi);
  // The reading is a mean over its period: its specific force is rotated by
  // the attitude at the middle of the period, dR_h = dR Exp(phi / 2).
  const Eigen::Matrix3d H = geom::so3_exp(0.5 * phi);
  const Eigen::Matrix3d Jr_h = so3_right_jacobian(0.5 * phi);
  const Eigen::Matrix3d dR_h = dR_ * H;
  const Eigen::Matrix3d dR_h_a_x = dR_h * geom::skew(a);
  // Rotation error of dR_h: H^T dphi + Jr_h dt / 2 (gyro noise) ...
  const Eigen::Matrix3d Ht = H.transpose();
  // ... and its Jacobian with respect to the gyro bias.
  const Eigen::Matrix3d J_Rh_bg = Ht * J_R_bg_ - 0.5 * dt_s * Jr_h;

  // Covariance of [dphi, dv, dp] (Forster eq. 62 with the mid-period
  // attitude): Sigma <- A Sigma A^T + B_g Q_g B_g^T + B_a Q_a B_a^T,
  // discrete white noise of variance density^2 / dt.
  Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Identity();
  A.block<3, 3>(0, 0) = dR_k.transpose();
  A.block<3, 3>(3, 0) = -dR_h_a_x * Ht * dt_s;
  A.block<3, 3>(6, 0) = -0.5 * dR_h_a_x * Ht * dt2;
  A.block<3, 3>(6, 3) = Eigen::Matrix3d::Identity() * dt_s;
  Eigen::Matrix<double, 9, 3> B_g, B_a = Eigen::Matrix<double, 9, 3>::Zero();
  B_g.block<3, 3>(0, 0) = Jr_k * dt_s;
  B_g.block<3, 3>(3, 0) = -0.5 * dR_h_a_x * Jr_h * dt2;
  B_g.block<3, 3>(6, 0) = -0.25 * dR_h_a_x * Jr_h * dt2 * dt_s;
  B_a.block<3, 3>(3, 0) = dR_h * dt_s;
  B_a.block<3, 3>(6, 0) = 0.5 * dR_h * dt2;
  const double q_g = noise_.gyro_noise_density * noise_.gyro_noise_density / dt_s;
  const double q_a = noise_.accel_noise_density * noise_.accel_noise_density / dt_s;
  cov_ = A * cov_ * A.transpose() + q_g * B_g * B_g.transpose() + q_a * B_a * B_a.transpose();

  // Bias Jacobians (Forster appendix B), position and velocity first: they
  // use the rotation Jacobian and increment before this step.
  J_p_ba_ += J_v_ba_ * dt_s - 0.5 * dR_h * dt2;
  J_p_bg_ += J_v_bg_ * dt_s - 0.5 * dR_h_a_x * J_Rh_bg * dt2;
  J_v_ba_ -= dR_h * dt_s;
  J_v_bg_ -= dR_h_a_x * J_Rh_bg * dt_s;
  J_R_bg_ = dR_k.transpose() * J_R_bg_ - Jr_k * dt_s;

  // Increments (Forster eq. 37 in recursive form).
  dp_ += dv_ * dt_s + 0.5 * dR_h * a * dt2;
  dv_ += dR_h * a * dt_s;
  dR_ = orthonormalised(dR_ * dR_k);
  dt_s_ += dt_s;
  if (readings_.size() >= kFoldAt) fold_oldest(kFoldCount);
}

void ImuPreintegration::append(const ImuPreintegration& next) {
  // Copy first: next may be *this.
  const ImuPreintegration more = next;
  if (more.folded_) {
    // The folded part has no readings to integrate at this bias: it is
    // joined by its increments, and everything up to its end is folded.
    compose(corrected(*more.folded_, bias_));
    folded_ = increments();
    folded_count_ += readings_.size() + more.folded_count_;
    readings_.clear();
  }
  for (const Reading& r : more.readings_) integrate(r.gyro_radps, r.accel_mps2, r.dt_s);
}

void ImuPreintegration::reintegrate(const ImuBias& bias) {
  const std::vector<Reading> kept = std::move(readings_);
  if (folded_)
    start_from(corrected(*folded_, bias));
  else
    *this = ImuPreintegration(bias, noise_);
  for (const Reading& r : kept) integrate(r.gyro_radps, r.accel_mps2, r.dt_s);
}

ImuPreintegration::Increments ImuPreintegration::increments() const {
  return Increments{bias_, dt_s_, dR_, J_R_bg_, J_v_bg_, J_v_ba_, J_p_bg_, J_p_ba_, dv_, dp_, cov_};
}

ImuPreintegration::Increments ImuPreintegration::corrected(const Increments& f, const ImuBias& b) {
  Increments out = f;
  out.bias = b;
  const Eigen::Vector3d dbg = b.gyro_radps - f.bias.gyro_radps;
  const Eigen::Vector3d dba = b.accel_mps2 - f.bias.accel_mps2;
  out.dR = orthonormalised(f.dR * geom::so3_exp(f.J_R_bg * dbg));
  out.dv = f.dv + f.J_v_bg * dbg + f.J_v_ba * dba;
  out.dp = f.dp + f.J_p_bg * dbg + f.J_p_ba * dba;
  return out;
}

void ImuPreintegration::start_from(const Increments& f) {
  bias_ = f.bias;
  readings_.clear();
  dR_ = f.dR;
  dv_ = f.dv;
  dp_ = f.dp;
  J_R_bg_ = f.J_R_bg;
  J_v_bg_ = f.J_v_bg;
  J_v_ba_ = f.J_v_ba;
  J_p_bg_ = f.J_p_bg;
  J_p_ba_ = f.J_p_ba;
  cov_ = f.cov;
  dt_s_ = f.dt_s;
}

void ImuPreintegration::compose(const Increments& s) {
  // This stretch P, then s: dR = dR_P dR_s, dv = dv_P + dR_P dv_s,
  // dp = dp_P + T_s dv_P + dR_P dp_s.  The errors of P (right-perturbed
  // rotation) and of s are independent, each carried to the end.
  const Eigen::Matrix3d dR_P = dR_;
  const Eigen::Matrix3d dR_P_dv_x = dR_P * geom::skew(s.dv), dR_P_dp_x = dR_P * geom::skew(s.dp);
  Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Identity();
  A.block<3, 3>(0, 0) = s.dR.transpose();
  A.block<3, 3>(3, 0) = -dR_P_dv_x;
  A.block<3, 3>(6, 0) = -dR_P_dp_x;
  A.block<3, 3>(6, 3) = Eigen::Matrix3d::Identity() * s.dt_s;
  Eigen::Matrix<double, 9, 9> B = Eigen::Matrix<double, 9, 9>::Zero();
  B.block<3, 3>(0, 0) = Eigen::Matrix3d::Identity();
  B.block<3, 3>(3, 3) = dR_P;
  B.block<3, 3>(6, 6) = dR_P;
  cov_ = A * cov_ * A.transpose() + B * s.cov * B.transpose();

  // Bias Jacobians: dR_P moves with the gyro bias by J_R_bg (right).
  J_p_bg_ += J_v_bg_ * s.dt_s - dR_P_dp_x * J_R_bg_ + dR_P * s.J_p_bg;
  J_p_ba_ += J_v_ba_ * s.dt_s + dR_P * s.J_p_ba;
  J_v_bg_ += -dR_P_dv_x * J_R_bg_ + dR_P * s.J_v_bg;
  J_v_ba_ += dR_P * s.J_v_ba;
  J_R_bg_ = s.dR.transpose() * J_R_bg_ + s.J_R_bg;

  dp_ += dv_ * s.dt_s + dR_P * s.dp;
  dv_ += dR_P * s.dv;
  dR_ = orthonormalised(dR_P * s.dR);
  dt_s_ += s.dt_s;
}

void ImuPreintegration::fold_oldest(std::size_t n) {
  // The increments up to the n-th kept reading, at this bias: the folded
  // part (already corrected to it when the kept readings were integrated)
  // and the n readings after it.
  ImuPreintegration head(bias_, noise_);
  if (folded_) head.start_from(corrected(*folded_, bias_));
  for (std::size_t k = 0; k < n; ++k)
    head.integrate(readings_[k].gyro_radps, readings_[k].accel_mps2, readings_[k].dt_s);
  folded_ = head.increments();
  folded_count_ += n;
  readings_.erase(readings_.begin(), readings_.begin() + static_cast<std::ptrdiff_t>(n));
}

Eigen::Matrix3d ImuPreintegration::delta_R(const ImuBias& b) const {
  return orthonormalised(dR_ * geom::so3_exp(J_R_bg_ * (b.gyro_radps - bias_.gyro_radps)));
}

Eigen::Vector3d ImuPreintegration::delta_v(const ImuBias& b) const {
  return dv_ + J_v_bg_ * (b.gyro_radps - bias_.gyro_radps) + J_v_ba_ * (b.accel_mps2 - bias_.accel_mps2);
}

Eigen::Vector3d ImuPreintegration::delta_p(const ImuBias& b) const {
  return dp_ + J_p_bg_ * (b.gyro_radps - bias_.gyro_radps) + J_p_ba_ * (b.accel_mps2 - bias_.accel_mps2);
}

NavState ImuPreintegration::predict(const NavState& start, const Eigen::Vector3d& g_w, const ImuBias& b) const {
  NavState end;
  const double T = dt_s_;
  end.R_w_b = orthonormalised(start.R_w_b * delta_R(b));
  end.v_w_mps = start.v_w_mps + g_w * T + start.R_w_b * delta_v(b);
  end.p_w_m = start.p_w_m + start.v_w_mps * T + 0.5 * g_w * T * T + start.R_w_b * delta_p(b);
  return end;
}

}  // namespace pvb::slam
