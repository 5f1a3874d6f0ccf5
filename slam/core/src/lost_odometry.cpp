// While tracking is lost with the wheels and a trusted IMU: the pose they
// carry on from the last one, and the bound it sets on a relocalisation.
// Among rows that look alike, a relocalisation in the wrong aisle is
// several metres from where the wheels say the robot is; the wheels' own
// error grows with the distance driven, so the bound does too.  A carry
// (the IMU rises) or a long loss lifts the bound: the wheels no longer
// know where the robot is.
#include <algorithm>
#include <cmath>
#include <limits>

#include "pvb/common/text.hpp"
#include "pvb/slam/core/tracking.hpp"

namespace pvb::slam {

void Tracking::ImuAlone::carry(const MotionIntegrator& motion, const Eigen::Vector3d& g_w,
                               const Eigen::Matrix3d& R_w_b) {
  if (motion.imu_since_frame().size() == 0) return;
  NavState s;
  s.R_w_b = R_w_b;
  s.p_w_m = p_w;
  s.v_w_mps = v_w;
  s = motion.imu_since_frame().predict(s, g_w, motion.bias());
  p_w = s.p_w_m;
  v_w = s.v_w_mps;
}

void Tracking::begin_lost_odometry() {
  lost_odom_.reset();
  if (options_.reloc_odometry_rate <= 0 || !motion_ || !uses_wheels(motion_->setup()) || !motion_->has_wheels() ||
      !inertial_ready() || !last_.has_pose || !v_last_known_)
    return;
  const Eigen::Vector3d g_w = map_.gravity().g_w;
  const NavState last_state = motion_->nav_state(last_.T_c_w, v_last_);
  LostOdometry o;
  o.T_c_w = motion_->predict(last_.T_c_w, v_last_, g_w, &o.v_w);
  if (blind_) {  // dead_reckon() has already carried the IMU alone through f
    o.distance_m = blind_->distance_m;
    o.imu = blind_->imu;
  } else {
    o.distance_m = (motion_->nav_state(o.T_c_w, o.v_w).p_w_m - last_state.p_w_m).norm();
    o.imu = ImuAlone{last_.t_ns, last_state.p_w_m, last_state.p_w_m, v_last_};
    o.imu.carry(*motion_, g_w, last_state.R_w_b);
  }
  o.lifted = o.imu.rise_m(g_w) > options_.kidnap_lift_m;
  lost_odom_ = o;
}

void Tracking::carry_lost_odometry(const Frame& f) {
  if (!lost_odom_ || !motion_) return;
  LostOdometry& o = *lost_odom_;
  const Eigen::Vector3d g_w = map_.gravity().g_w;
  const NavState before = motion_->nav_state(o.T_c_w, o.v_w);
  Eigen::Vector3d v_w = Eigen::Vector3d::Zero();
  o.T_c_w = motion_->predict(o.T_c_w, o.v_w, g_w, &v_w);
  o.v_w = v_w;
  o.distance_m += (motion_->nav_state(o.T_c_w, o.v_w).p_w_m - before.p_w_m).norm();
  const double lost_s = static_cast<double>(f.t_ns - o.imu.start_t_ns) * 1e-9;
  if (o.lifted || lost_s > options_.reloc_odometry_lift_window_s) return;
  // The IMU alone, for a lift, only near the loss: its double integration
  // drifts by metres within a minute.
  o.imu.carry(*motion_, g_w, before.R_w_b);
  o.lifted = o.imu.rise_m(g_w) > options_.kidnap_lift_m;
}

double Tracking::lost_odometry_bound_m(const Frame& f) const {
  if (!lost_odom_ || lost_odom_->lifted) return std::numeric_limits<double>::infinity();
  const double lost_s = static_cast<double>(f.t_ns - lost_odom_->imu.start_t_ns) * 1e-9;
  if (lost_s > options_.reloc_odometry_max_s) return std::numeric_limits<double>::infinity();
  return options_.reloc_odometry_floor_m + options_.reloc_odometry_rate * lost_odom_->distance_m;
}

std::string Tracking::odometry_refuses(const Frame& f, const Frame& found) const {
  const double bound_m = lost_odometry_bound_m(f);
  if (!std::isfinite(bound_m)) return {};
  const Eigen::Vector3d carried_w = lost_odom_->T_c_w.inverse().translation();
  const double off_m = (found.camera_center_w() - carried_w).norm();
  if (off_m <= bound_m) return {};
  return "relocalisation: the match puts the camera " + format_fixed(off_m, 2) +
         " m from where the wheels carried it (within " + format_fixed(bound_m, 2) + " m after " +
         format_fixed(lost_odom_->distance_m, 2) + " m)";
}

std::shared_ptr<KeyFrame> Tracking::restart_at_carried_pose(Frame& f) {
  if (options_.carried_restart_after <= 0 || localise_only_ || lost_in_row_ < options_.carried_restart_after ||
      !std::isfinite(lost_odometry_bound_m(f)))
    return nullptr;
  if (f.num_with_depth() <= options_.min_init_points) return nullptr;
  f.T_c_w = lost_odom_->T_c_w;
  f.has_pose = true;
  std::fill(f.map_points.begin(), f.map_points.end(), nullptr);
  std::fill(f.outlier.begin(), f.outlier.end(), 0);
  v_last_ = lost_odom_->v_w;
  v_last_known_ = true;
  auto kf = add_keyframe_in_own_map(f);  // the wheels' readings since hold it to the last keyframe
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.depth_m[i] > 0) add_point_from_depth(f, kf, i);
  ref_kf_ = kf;
  local_kfs_ = {kf};
  last_kf_frame_id_ = f.id;
  stats_.method = TrackingMethod::kCarriedRestart;
  stats_.new_keyframe = true;
  stats_.reloc_failure = TrackingStats::RelocFailure::kNone;
  state_ = TrackingState::kOk;
  lost_in_row_ = 0;
  lost_odom_.reset();
  velocity_.reset();
  update_motion_state(f, false);
  last_is_keyframe_ = true;
  T_last_ref_ = geom::SE3d::Identity();
  last_ = std::move(f);
  return kf;
}

}  // namespace pvb::slam
