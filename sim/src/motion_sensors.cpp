#include "pvb/sim/motion_sensors.hpp"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <cmath>

#include "pvb/common/error.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "carry_path.hpp"
#include "splitmix.hpp"

namespace pvb::sim {
namespace {

int joint_id(const mjModel* m, const char* name) {
  const int id = mj_name2id(m, mjOBJ_JOINT, name);
  if (id < 0) throw Error(std::string("generated model lacks joint ") + name);
  return id;
}

/// Saturation, then the converter's step (2 range / 2^bits), as a reading leaves the part.
double clip_and_quantise(double v, const scenes::InertialNoise& spec) {
  v = std::max(-spec.range, std::min(spec.range, v));
  if (spec.bits <= 0) return v;
  const double lsb = 2.0 * spec.range / std::ldexp(1.0, spec.bits);
  return lsb * std::round(v / lsb);
}

}  // namespace

InertialNoiseModel::InertialNoiseModel(const scenes::InertialNoise& spec, double dt_s, std::uint64_t seed,
                                       std::uint64_t stream)
    : spec_(spec), dt_s_(dt_s), rng_state_(SplitMix(seed, stream).s) {
  for (int a = 0; a < 3; ++a) bias_[a] = spec_.turn_on_bias * normal();
}

double InertialNoiseModel::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  SplitMix rng(0, 0);
  rng.s = rng_state_;
  const double u1 = rng.uniform(), u2 = rng.uniform();
  rng_state_ = rng.s;
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(2.0 * M_PI * u2);
  has_spare_ = true;
  return r * std::cos(2.0 * M_PI * u2);
}

Eigen::Vector3d InertialNoiseModel::apply(const Eigen::Vector3d& truth, Eigen::Vector3d* bias) {
  if (bias) *bias = bias_;
  const double sigma_d = spec_.noise_density / std::sqrt(dt_s_);
  Eigen::Vector3d out;
  for (int a = 0; a < 3; ++a) out[a] = clip_and_quantise(truth[a] + bias_[a] + sigma_d * normal(), spec_);
  const double walk = spec_.random_walk * std::sqrt(dt_s_);
  for (int a = 0; a < 3; ++a) bias_[a] += walk * normal();
  return out;
}

sensor::DriveDescription nominal_description(const scenes::Scenario& s) {
  SplitMix rng(s.station_seed_or_seed(), 0xCA11B);
  const double e_radius = (2.0 * rng.uniform() - 1.0) * s.robot.radius_error;
  const double e_track = (2.0 * rng.uniform() - 1.0) * s.robot.track_error;
  sensor::DriveDescription d;
  d.wheel_radius_m = s.robot.wheel_radius_m * (1.0 + e_radius);
  d.track_m = s.robot.track_m * (1.0 + e_track);
  d.ticks_per_rev = s.wheels.ticks_per_rev;
  return d;
}

MotionSensors::MotionSensors(const mjModel* m, const scenes::Scenario& s, int robot_body, const geom::SE3d& T_b_c)
    : T_b_i_(T_b_c * scenes::T_camera_imu(s.imu)),
      dt_s_(m->opt.timestep),
      imu_rate_hz_(scenes::imu_rate_hz(s)),
      wheel_rate_hz_(scenes::wheel_rate_hz(s)),
      imu_steps_(static_cast<int>(std::lround(scenes::physics_rate_hz(s) / imu_rate_hz_))),
      wheel_steps_(static_cast<int>(std::lround(scenes::physics_rate_hz(s) / wheel_rate_hz_))),
      free_qpos_(m->jnt_qposadr[m->body_jntadr[robot_body]]),
      free_dof_(m->jnt_dofadr[m->body_jntadr[robot_body]]),
      wheel_radius_m_{s.robot.left_radius_m(), s.robot.right_radius_m()},
      track_m_(s.robot.track_m),
      ticks_per_rev_(s.wheels.ticks_per_rev),
      gyro_noise_(s.imu.gyro, 1.0 / imu_rate_hz_, s.seed, 0x1A0001),
      accel_noise_(s.imu.accel, 1.0 / imu_rate_hz_, s.seed, 0x1A0002) {
  const char* names[2] = {kLeftActuator, kRightActuator};
  for (int side = 0; side < 2; ++side) {
    const int j = joint_id(m, names[side]);
    wheel_qpos_[side] = m->jnt_qposadr[j];
    wheel_dof_[side] = m->jnt_dofadr[j];
    wheel_act_[side] = mj_name2id(m, mjOBJ_ACTUATOR, names[side]);
  }
}

void MotionSensors::before_step(const mjData* d) {
  const FreeState f = free_state(d, free_qpos_, free_dof_);
  pre_ = {f.R_w_b, f.v_w, f.w_b};
}

void MotionSensors::after_step(const mjModel* m, const mjData* d, bool carried) {
  accumulate_imu(m, d);
  ++steps_;
  if (steps_ % imu_steps_ == 0) emit_imu(d);
  if (steps_ % wheel_steps_ == 0) {
    emit_wheels(d);
    out_.wheel_truth.back().carried = carried;
  }
}

// One physics step from state n to n + 1.  MuJoCo moves the free body's
// origin with the new linear velocity (world frame) and turns it with the
// new angular velocity (body frame) over the whole step, so the origin's
// acceleration is the change of velocity over the step, and an offset
// point adds the angular acceleration's and the centripetal terms.  The
// specific force is that acceleration less gravity, in the IMU's axes.
void MotionSensors::accumulate_imu(const mjModel* m, const mjData* d) {
  const FreeState now = free_state(d, free_qpos_, free_dof_);
  const Eigen::Vector3d& w1 = now.w_b;
  const Eigen::Vector3d a_origin_w = (now.v_w - pre_.v_w) / dt_s_;
  const Eigen::Vector3d alpha_b = (w1 - pre_.w_b) / dt_s_;
  const Eigen::Matrix3d R_mid = pre_.R_w_b * geom::so3_exp(0.5 * dt_s_ * w1);
  const Eigen::Vector3d r = T_b_i_.translation();
  const Eigen::Vector3d a_w = a_origin_w + R_mid * (alpha_b.cross(r) + w1.cross(w1.cross(r)));
  const Eigen::Vector3d g_w(m->opt.gravity[0], m->opt.gravity[1], m->opt.gravity[2]);
  const Eigen::Matrix3d R_i_b = T_b_i_.linear().transpose();
  sum_accel_ += R_i_b * (R_mid.transpose() * (a_w - g_w));
  sum_gyro_ += R_i_b * w1;
}

void MotionSensors::emit_imu(const mjData* d) {
  ImuTruth truth;
  truth.t_ns = geom::frame_time_ns(0, steps_ / imu_steps_, imu_rate_hz_);
  truth.gyro_radps = sum_gyro_ / imu_steps_;
  truth.accel_mps2 = sum_accel_ / imu_steps_;
  sum_gyro_.setZero();
  sum_accel_.setZero();
  const FreeState f = free_state(d, free_qpos_, free_dof_);
  truth.T_w_i = geom::make_se3(f.R_w_b, f.p_w) * T_b_i_;
  truth.v_w_i = f.v_w + f.R_w_b * f.w_b.cross(T_b_i_.translation());
  sensor::ImuSample sample;
  sample.t_ns = truth.t_ns;
  sample.gyro_radps = gyro_noise_.apply(truth.gyro_radps, &truth.gyro_bias);
  sample.accel_mps2 = accel_noise_.apply(truth.accel_mps2, &truth.accel_bias);
  out_.imu.push_back(sample);
  out_.imu_truth.push_back(truth);
}

double MotionSensors::wheel_angle(const mjData* d, int side) const {
  return d->qpos[wheel_qpos_[side]] + wheel_offset_rad_[side];
}

void MotionSensors::emit_wheels(const mjData* d) {
  WheelTruth truth;
  truth.t_ns = geom::frame_time_ns(0, steps_ / wheel_steps_, wheel_rate_hz_);
  const FreeState f = free_state(d, free_qpos_, free_dof_);
  truth.T_w_b = geom::make_se3(f.R_w_b, f.p_w);
  sensor::WheelTicks ticks;
  ticks.t_ns = truth.t_ns;
  for (int side = 0; side < 2; ++side) {
    const double revs = wheel_angle(d, side) / (2.0 * M_PI);
    const auto count = static_cast<std::int64_t>(std::floor(revs * ticks_per_rev_));
    (side == 0 ? ticks.left : ticks.right) = count;
    const Eigen::Vector3d centre_b(0.0, (side == 0 ? 0.5 : -0.5) * track_m_, 0.0);
    const Eigen::Vector3d v_centre_b = f.R_w_b.transpose() * f.v_w + f.w_b.cross(centre_b);
    const double wheel = d->qvel[wheel_dof_[side]], ground = v_centre_b.x();
    truth.wheel_radps[side] = wheel;
    truth.ground_mps[side] = ground;
    truth.commanded_radps[side] = wheel_act_[side] >= 0 ? d->ctrl[wheel_act_[side]] : 0.0;
    const double rolled = wheel * wheel_radius_m_[side];
    truth.slip[side] = (rolled - ground) / std::max({std::abs(rolled), std::abs(ground), 1e-3});
  }
  out_.ticks.push_back(ticks);
  out_.wheel_truth.push_back(truth);
}

void MotionSensors::rebase_wheels(const mjData* before, const mjData* after) {
  for (int side = 0; side < 2; ++side)
    wheel_offset_rad_[side] += before->qpos[wheel_qpos_[side]] - after->qpos[wheel_qpos_[side]];
}

MotionBatch MotionSensors::take() {
  MotionBatch out;
  std::swap(out, out_);
  return out;
}

}  // namespace pvb::sim
