// Tracking with the motion sensors: the levelled first pose, the IMU's
// prediction of the next frame, the keyframes' chain in time, dead
// reckoning through blind stretches and finding the local map again after
// one (docs/slam_inertial.md).
#include <cmath>

#include "pvb/common/text.hpp"
#include "pvb/slam/core/tracking.hpp"
#include "pvb/slam/core/frame_pose.hpp"

namespace pvb::slam {

void Tracking::use_motion_sensors(const MotionSensorSettings& sensors) {
  if (sensors.setup == sensor::SensorSetup::kCamera) {
    motion_.reset();
    return;
  }
  motion_ = std::make_unique<MotionIntegrator>(sensors);
}

void Tracking::add_motion(std::int64_t t_ns, const std::vector<sensor::ImuSample>& imu,
                          const std::vector<sensor::WheelTicks>& ticks) {
  if (!motion_) return;
  std::lock_guard<std::mutex> lock(map_.mutex());
  const MapGravity& g = map_.gravity();
  if (g.ready && uses_imu(motion_->setup()) &&
      (g.bias.gyro_radps != motion_->bias().gyro_radps || g.bias.accel_mps2 != motion_->bias().accel_mps2))
    motion_->set_bias(g.bias);
  if (map_.wheels().calibration != motion_->wheel_calibration())
    motion_->set_wheel_calibration(map_.wheels().calibration);
  motion_->add_frame(t_ns, imu, ticks);
}

bool Tracking::inertial_ready() const {
  return motion_ && uses_imu(motion_->setup()) && motion_->has_imu() && map_.gravity().ready && provisional_ == 0;
}

std::optional<std::string> Tracking::waiting_for_accelerometer(const Frame& f) {
  if (!motion_ || !uses_accel(motion_->setup())) return std::nullopt;
  if (!first_frame_t_ns_) first_frame_t_ns_ = f.t_ns;
  const std::int64_t waited_ns = f.t_ns - *first_frame_t_ns_;
  if (waited_ns >= kAccelWaitNs) return std::nullopt;
  // Level only on a quiet accelerometer: the robot not jolted (a start
  // rocks it on its caster for a moment).
  const std::optional<Eigen::Vector3d> f_c = motion_->recent_specific_force_c();
  const std::string so_far = format_number("%.2f s", static_cast<double>(waited_ns) * 1e-9) + " of at most " +
                             format_number("%.0f s", static_cast<double>(kAccelWaitNs) * 1e-9);
  if (!f_c) return "waiting for the accelerometer's first readings (" + so_far + ")";
  const double spread = motion_->recent_spread_mps2();
  if (std::abs(f_c->norm() - 9.81) <= kQuietMps2 && spread <= kQuietMps2) return std::nullopt;
  return "waiting for a quiet accelerometer to level the map: mean " + format_number("%.2f", f_c->norm()) +
         " m/s^2 (g within " + format_number("%.1f", kQuietMps2) + "), spread " +
         format_number("%.2f", spread) + " m/s^2 (under " + format_number("%.1f", kQuietMps2) +
         ") over the last " + format_number("%.1f s", MotionIntegrator::kTiltWindowS) + "; " + so_far;
}

geom::SE3d Tracking::first_pose() const {
  if (!motion_ || !uses_accel(motion_->setup())) return geom::SE3d::Identity();
  const std::optional<Eigen::Vector3d> f_c = motion_->recent_specific_force_c();
  if (!f_c || !(f_c->norm() > 1.0)) return geom::SE3d::Identity();
  // World z (up) seen from the camera is the specific force's direction;
  // world x is the camera's viewing direction made horizontal.
  const Eigen::Vector3d up = f_c->normalized();
  Eigen::Vector3d ahead = Eigen::Vector3d::UnitZ();
  if (std::abs(ahead.dot(up)) > 0.95) ahead = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = (ahead - ahead.dot(up) * up).normalized();
  const Eigen::Vector3d y = up.cross(x);
  Eigen::Matrix3d R_c_w;
  R_c_w << x, y, up;
  return geom::make_se3(R_c_w, Eigen::Vector3d::Zero());
}

geom::SE3d Tracking::predicted_pose(Eigen::Vector3d* v_w) const {
  return motion_->predict(last_.T_c_w, v_last_, map_.gravity().g_w, v_w);
}

void Tracking::update_motion_state(const Frame& f, bool tracked) {
  if (!motion_ || !uses_imu(motion_->setup())) return;
  const KeyFrameMotion* kf_motion = last_kf_ && !last_kf_->bad() ? &last_kf_->motion() : nullptr;
  if (inertial_ready() && kf_motion && kf_motion->has_state) {
    // The keyframe's bundle-adjusted state carried to this frame.
    const NavState at_kf = motion_->nav_state(last_kf_->T_c_w(), kf_motion->v_w_mps);
    const ImuPreintegration& since = motion_->imu_since_keyframe();
    v_last_ = since.size() > 0 ? since.predict(at_kf, map_.gravity().g_w, motion_->bias()).v_w_mps : at_kf.v_w_mps;
    v_last_known_ = true;
    return;
  }
  if (!tracked || !last_.has_pose || f.t_ns <= last_.t_ns) {
    v_last_known_ = false;
    return;
  }
  // Before the inertial state is trusted: the velocity of the IMU between
  // the last two poses.
  const double dt_s = static_cast<double>(f.t_ns - last_.t_ns) * 1e-9;
  const Eigen::Vector3d p1 = motion_->nav_state(f.T_c_w, Eigen::Vector3d::Zero()).p_w_m;
  const Eigen::Vector3d p0 = motion_->nav_state(last_.T_c_w, Eigen::Vector3d::Zero()).p_w_m;
  v_last_ = (p1 - p0) / dt_s;
  v_last_known_ = true;
}

void Tracking::attach_motion(const std::shared_ptr<KeyFrame>& kf) {
  if (!motion_) return;
  KeyframeInterval interval = motion_->take_keyframe_interval();
  KeyFrameMotion& m = kf->motion();
  const bool chained = last_kf_ && !last_kf_->bad() && last_kf_->provisional() == kf->provisional() &&
                       last_kf_->id() < kf->id();
  if (chained) {
    m.prev = last_kf_;
    last_kf_->motion().next = kf;
  } else {
    interval.imu.reset();
    interval.wheels.reset();
  }
  m.from_prev = std::move(interval);
  if (inertial_ready() && v_last_known_) {
    m.has_state = true;
    m.v_w_mps = v_last_;
    m.bias = motion_->bias();
  }
  last_kf_ = kf;
}

bool Tracking::dead_reckon(Frame& f) {
  if (!inertial_ready() || !last_.has_pose || !v_last_known_)
    return fail("dead reckoning: the inertial state is not trusted yet");
  Eigen::Vector3d v_w = Eigen::Vector3d::Zero();
  const geom::SE3d T_c_w = predicted_pose(&v_w);
  const Eigen::Vector3d g_w = map_.gravity().g_w;
  const NavState last_state = motion_->nav_state(last_.T_c_w, v_last_);
  if (!blind_) blind_ = Blind{0.0, ImuAlone{last_.t_ns, last_state.p_w_m, last_state.p_w_m, v_last_}};
  blind_->imu.carry(*motion_, g_w, last_state.R_w_b);
  const NavState predicted = motion_->nav_state(T_c_w, v_w);
  blind_->distance_m += (predicted.p_w_m - last_state.p_w_m).norm();
  const double blind_s = static_cast<double>(f.t_ns - blind_->imu.start_t_ns) * 1e-9;
  const double rise_m = blind_->imu.rise_m(g_w);
  const double apart_m = (blind_->imu.p_w - predicted.p_w_m).norm();
  if (blind_s > options_.blind_max_s)
    return fail("dead reckoning: blind for " + format_fixed(blind_s, 2) + " s (limit " +
                format_fixed(options_.blind_max_s, 2) + " s)");
  if (blind_->distance_m > options_.blind_max_m)
    return fail("dead reckoning: carried " + format_fixed(blind_->distance_m, 2) + " m blind (limit " +
                format_fixed(options_.blind_max_m, 2) + " m)");
  if (rise_m > options_.kidnap_lift_m)
    return fail("kidnap: the IMU rose " + format_fixed(rise_m, 2) + " m while vision was lost");
  const double apart_max_m = options_.kidnap_disagree_m + 0.5 * options_.kidnap_disagree_accel_mps2 * blind_s * blind_s;
  if (uses_wheels(motion_->setup()) && motion_->has_wheels() && apart_m > apart_max_m)
    return fail("kidnap: the IMU and the wheels part by " + format_fixed(apart_m, 2) + " m while vision was lost (" +
                format_fixed(apart_max_m, 2) + " m allowed after " + format_fixed(blind_s, 2) + " s)");
  f.T_c_w = T_c_w;
  f.has_pose = true;
  std::fill(f.map_points.begin(), f.map_points.end(), nullptr);
  std::fill(f.outlier.begin(), f.outlier.end(), 0);
  v_last_ = v_w;
  return true;
}

bool Tracking::track_after_blind(Frame& f) {
  Eigen::Vector3d v_w;
  f.T_c_w = predicted_pose(&v_w);
  f.has_pose = true;
  std::fill(f.map_points.begin(), f.map_points.end(), nullptr);
  std::vector<ProjectedPoint> proj;
  proj.reserve(local_points_.size());
  for (const auto& mp : local_points_) {
    ProjectedPoint p;
    if (!mp->bad() && project_in_frustum(f, mp, &p)) proj.push_back(p);
  }
  const int found = search_local_points(f, proj, options_.after_blind_radius_px);
  if (found < 20)
    return fail("after a blind stretch: only " + std::to_string(found) + " local map matches around the " +
                "dead-reckoned pose (need 20)");
  optimize_frame_pose(f);
  int map_matches = 0;
  discard_outliers(f, &map_matches);
  if (map_matches < 15)
    return fail("after a blind stretch: only " + std::to_string(map_matches) +
                " map matches after pose optimisation (need 15)");
  return true;
}

}  // namespace pvb::slam
