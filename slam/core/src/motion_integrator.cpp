#include "pvb/slam/core/motion_integrator.hpp"

#include <cmath>

namespace pvb::slam {

MotionIntegrator::MotionIntegrator(const MotionSensorSettings& sensors)
    : setup_(sensors.setup),
      imu_(sensors.imu),
      imu_noise_(sensors.imu.fused_noise()),
      robot_(sensors.robot),
      period_ns_(static_cast<std::int64_t>(std::llround(1e9 / sensors.imu.rate_hz))),
      encoder_period_ns_(static_cast<std::int64_t>(std::llround(1e9 / sensors.robot.encoder_rate_hz))),
      imu_frame_(ImuBias{}, imu_noise_),
      imu_kf_(ImuBias{}, imu_noise_),
      wheel_frame_(sensors.robot.drive, sensors.robot.wheel_noise),
      wheel_kf_(sensors.robot.drive, sensors.robot.wheel_noise) {}

void MotionIntegrator::add_frame(std::int64_t t_ns, const std::vector<sensor::ImuSample>& imu,
                                 const std::vector<sensor::WheelTicks>& ticks) {
  imu_frame_ = ImuPreintegration(bias_, imu_noise_);
  wheel_frame_ = WheelPreintegration(robot_.drive, robot_.wheel_noise, wheel_calibration_);
  if (uses_accel(setup_))
    for (const auto& s : imu) add_imu(s);
  if (uses_imu(setup_)) integrate_up_to(t_ns);
  if (uses_wheels(setup_)) {
    for (const auto& t : ticks) add_ticks(t);
    wheels_up_to(t_ns);
  }
  // The tilt window ends at the frame.
  const auto window_ns = static_cast<std::int64_t>(kTiltWindowS * 1e9);
  while (!recent_f_c_.empty() && recent_f_c_.front().first < t_ns - window_ns) recent_f_c_.pop_front();
}

void MotionIntegrator::add_imu(const sensor::ImuSample& s) {
  if (last_imu_t_ns_ && s.t_ns <= *last_imu_t_ns_) return;  // a repeated reading
  last_imu_t_ns_ = s.t_ns;
  if (!s.accel_mps2.allFinite()) return;
  ++imu_count_;
  const Eigen::Matrix3d R_c_b = imu_.T_b_c.linear().transpose();
  recent_f_c_.emplace_back(s.t_ns, R_c_b * (s.accel_mps2 - bias_.accel_mps2));
  if (!uses_imu(setup_) || !s.gyro_radps.allFinite()) return;
  // The reading is the mean over its period; the part of it before the
  // time already integrated (a frame's time inside the period) was
  // counted with the frame.  A gap (a dropped stretch) is integrated as at
  // most ten periods: the rest is not known.
  const std::int64_t start_ns = covered_t_ns_ ? *covered_t_ns_ : s.t_ns - period_ns_;
  covered_t_ns_ = s.t_ns;
  last_reading_ = s;
  const double dt_s = static_cast<double>(std::min(s.t_ns - start_ns, 10 * period_ns_)) * 1e-9;
  if (!(dt_s > 0)) return;
  imu_frame_.integrate(s.gyro_radps, s.accel_mps2, dt_s);
  imu_kf_.integrate(s.gyro_radps, s.accel_mps2, dt_s);
}

void MotionIntegrator::integrate_up_to(std::int64_t t_ns) {
  if (!last_reading_ || !covered_t_ns_ || *covered_t_ns_ >= t_ns || t_ns - *covered_t_ns_ > period_ns_)
    return;
  // The interval ends at the frame: the newest reading is held up to it
  // (the next reading, which covers this stretch too, begins there).
  const double dt_s = static_cast<double>(t_ns - *covered_t_ns_) * 1e-9;
  imu_frame_.integrate(last_reading_->gyro_radps, last_reading_->accel_mps2, dt_s);
  imu_kf_.integrate(last_reading_->gyro_radps, last_reading_->accel_mps2, dt_s);
  covered_t_ns_ = t_ns;
}

void MotionIntegrator::add_ticks(const sensor::WheelTicks& t) {
  if (last_ticks_ && t.t_ns > last_ticks_->t_ns) {
    const Eigen::Vector2d counts(static_cast<double>(t.left - last_ticks_->left),
                                 static_cast<double>(t.right - last_ticks_->right));
    // The part a frame between the readings already took is not counted twice.
    const Eigen::Vector2d rest = counts - ticks_ahead_;
    wheel_frame_.add(rest.x(), rest.y());
    wheel_kf_.add(rest.x(), rest.y());
    tick_rate_per_ns_ = counts / static_cast<double>(t.t_ns - last_ticks_->t_ns);
  }
  ticks_ahead_.setZero();
  last_ticks_ = t;
}

void MotionIntegrator::wheels_up_to(std::int64_t t_ns) {
  // Increments end at the frame, as the IMU's do: without this, an
  // interval between keyframes is off by up to an encoder period of
  // driving at each end (9 mm at 0.45 m/s and 50 Hz).  Past two periods
  // (a dropped stretch) nothing is guessed.
  if (!last_ticks_ || !tick_rate_per_ns_ || t_ns <= last_ticks_->t_ns) return;
  const std::int64_t ahead_ns = t_ns - last_ticks_->t_ns;
  if (ahead_ns > 2 * encoder_period_ns_) return;
  const Eigen::Vector2d step = *tick_rate_per_ns_ * static_cast<double>(ahead_ns) - ticks_ahead_;
  wheel_frame_.add(step.x(), step.y());
  wheel_kf_.add(step.x(), step.y());
  ticks_ahead_ += step;
}

KeyframeInterval MotionIntegrator::take_keyframe_interval() {
  KeyframeInterval out;
  if (uses_imu(setup_) && imu_kf_.size() > 0) out.imu = std::make_shared<ImuPreintegration>(imu_kf_);
  if (uses_wheels(setup_) && has_wheels()) out.wheels = std::make_shared<WheelPreintegration>(wheel_kf_);
  out.f_c_mps2 = recent_specific_force_c();
  out.f_spread_mps2 = recent_spread_mps2();
  imu_kf_ = ImuPreintegration(bias_, imu_noise_);
  wheel_kf_ = WheelPreintegration(robot_.drive, robot_.wheel_noise, wheel_calibration_);
  return out;
}

void MotionIntegrator::set_wheel_calibration(const WheelCalibration& c) {
  wheel_calibration_ = c;
  const auto unmoved = [](const WheelPreintegration& w) { return w.distance_m() == 0 && w.turn_rad() == 0; };
  if (unmoved(wheel_frame_)) wheel_frame_ = WheelPreintegration(robot_.drive, robot_.wheel_noise, c);
  if (unmoved(wheel_kf_)) wheel_kf_ = WheelPreintegration(robot_.drive, robot_.wheel_noise, c);
}

void MotionIntegrator::set_bias(const ImuBias& b) {
  bias_ = b;
  imu_frame_.reintegrate(b);
  imu_kf_.reintegrate(b);
}

std::optional<Eigen::Vector3d> MotionIntegrator::recent_specific_force_c() const {
  if (recent_f_c_.empty()) return std::nullopt;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& [t, f] : recent_f_c_) mean += f;
  return mean / static_cast<double>(recent_f_c_.size());
}

double MotionIntegrator::recent_spread_mps2() const {
  const std::optional<Eigen::Vector3d> mean = recent_specific_force_c();
  if (!mean) return 0;
  double sum = 0;
  for (const auto& [t, f] : recent_f_c_) sum += (f - *mean).squaredNorm();
  return std::sqrt(sum / static_cast<double>(recent_f_c_.size()));
}

NavState MotionIntegrator::nav_state(const geom::SE3d& T_c_w, const Eigen::Vector3d& v_w) const {
  const geom::SE3d T_w_b = T_c_w.inverse() * imu_.T_b_c.inverse();
  NavState s;
  s.R_w_b = T_w_b.linear();
  s.p_w_m = T_w_b.translation();
  s.v_w_mps = v_w;
  return s;
}

geom::SE3d MotionIntegrator::camera_pose(const NavState& s) const {
  const geom::SE3d T_w_c = geom::make_se3(s.R_w_b, s.p_w_m) * imu_.T_b_c;
  return geom::make_se3(Eigen::Quaterniond(T_w_c.linear()), T_w_c.translation()).inverse();
}

geom::SE3d MotionIntegrator::predict(const geom::SE3d& T_c_w_last, const Eigen::Vector3d& v_w_last,
                                     const Eigen::Vector3d& g_w, Eigen::Vector3d* v_w_out) const {
  const NavState start = nav_state(T_c_w_last, v_w_last);
  const NavState end = imu_frame_.size() > 0 ? imu_frame_.predict(start, g_w, bias_) : start;
  if (v_w_out) *v_w_out = end.v_w_mps;
  if (!uses_wheels(setup_) || !has_wheels()) return camera_pose(end);
  // Wheels: the base moves by the encoders' planar increment in its own
  // frame, turned as the gyro says.
  const geom::SE3d T_base_b = robot_.T_base_c * imu_.T_b_c.inverse();
  const geom::SE3d T_w_base0 = T_c_w_last.inverse() * robot_.T_base_c.inverse();
  const Eigen::Matrix3d R_b0_b1 =
      imu_frame_.size() > 0 ? imu_frame_.delta_R(bias_) : Eigen::Matrix3d(Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d R_base0_base1 = T_base_b.linear() * R_b0_b1 * T_base_b.linear().transpose();
  const Eigen::Vector3d& d = wheel_frame_.delta();
  const geom::SE3d T_base0_base1 =
      geom::make_se3(Eigen::Quaterniond(R_base0_base1), Eigen::Vector3d(d.x(), d.y(), 0));
  geom::SE3d T_w_c1 = T_w_base0 * T_base0_base1 * robot_.T_base_c;
  // Kept a rotation: Isometry3d's inverse transposes, so a drift from
  // orthonormality would grow from frame to frame of a blind stretch.
  T_w_c1 = geom::make_se3(Eigen::Quaterniond(T_w_c1.linear()), T_w_c1.translation());
  if (v_w_out && imu_frame_.dt_s() > 0)
    *v_w_out = ((T_w_c1 * imu_.T_b_c.inverse()).translation() - start.p_w_m) / imu_frame_.dt_s();
  return T_w_c1.inverse();
}

}  // namespace pvb::slam
