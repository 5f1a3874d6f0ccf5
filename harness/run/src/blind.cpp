#include "pvb/run/blind.hpp"

#include <algorithm>
#include <cmath>

#include "pvb/common/text.hpp"
#include "pvb/geometry/time.hpp"

namespace pvb::run {
namespace {

/// The tracking method timing.csv writes for a global relocalisation.
constexpr const char* kRelocalisationMethod = "reloc";

/// The pose of `traj` at exactly t_ns, if it has one.
const geom::SE3d* pose_at(const eval::Trajectory& traj, std::int64_t t_ns) {
  const auto it = std::lower_bound(traj.poses.begin(), traj.poses.end(), t_ns,
                                   [](const geom::StampedPose& p, std::int64_t t) { return p.t_ns < t; });
  return it != traj.poses.end() && it->t_ns == t_ns ? &it->T_w_c : nullptr;
}

/// The record of frame `index`, if the run processed it.
const FrameRecord* record_of(const std::vector<FrameRecord>& frames, int index) {
  const auto it = std::lower_bound(frames.begin(), frames.end(), index,
                                   [](const FrameRecord& r, int i) { return r.frame < i; });
  return it != frames.end() && it->frame == index ? &*it : nullptr;
}

/// The estimated motion from frame `before` to frame `after` against the true one.
std::optional<PoseError> relative_error(int before, int after, double fps, const eval::Trajectory& est,
                                        const eval::Trajectory& gt) {
  const std::int64_t t_before_ns = geom::frame_time_ns(0, before, fps);
  const std::int64_t t_after_ns = geom::frame_time_ns(0, after, fps);
  const geom::SE3d* est_before = pose_at(est, t_before_ns);
  const geom::SE3d* est_after = pose_at(est, t_after_ns);
  const geom::SE3d* gt_before = pose_at(gt, t_before_ns);
  const geom::SE3d* gt_after = pose_at(gt, t_after_ns);
  if (!est_before || !est_after || !gt_before || !gt_after) return std::nullopt;
  const geom::SE3d T_before_after_est = est_before->inverse() * *est_after;
  const geom::SE3d T_before_after_gt = gt_before->inverse() * *gt_after;
  return pose_error(T_before_after_gt, T_before_after_est);
}

/// Frame `after` in the evaluation's aligned frame, if it was associated.
std::optional<PoseError> aligned_error(int after, double fps, const eval::EvalResult& eval) {
  const std::int64_t t_ns = geom::frame_time_ns(0, after, fps);
  const auto it = std::find(eval.t_ns.begin(), eval.t_ns.end(), t_ns);
  if (it == eval.t_ns.end()) return std::nullopt;
  const auto i = static_cast<std::size_t>(it - eval.t_ns.begin());
  return pose_error(eval.T_w_c_gt[i], eval.T_w_c_est[i]);
}

}  // namespace

PoseError pose_error(const geom::SE3d& T_w_c_true, const geom::SE3d& T_w_c_est) {
  PoseError e;
  e.trans_m = (T_w_c_est.translation() - T_w_c_true.translation()).norm();
  e.rot_deg = geom::rotation_angle_rad(T_w_c_true.linear().transpose() * T_w_c_est.linear()) * 180.0 / M_PI;
  return e;
}

BlindStretch blind_stretch(const scenes::CoverFrames& cover, double fps,
                           const std::vector<FrameRecord>& frames, const eval::Trajectory& est,
                           const eval::Trajectory& gt, const std::optional<eval::EvalResult>& eval) {
  BlindStretch b;
  b.first_covered = cover.begin;
  b.last_covered = cover.end - 1;
  for (const FrameRecord& r : frames) {
    if (r.frame < cover.begin && r.tracked) b.last_before = r.frame;
    if (r.frame > cover.end) continue;
    if (cover.covered(r.frame)) {
      ++b.covered_processed;
      if (r.tracked) ++b.covered_with_pose;
    }
    if (r.frame >= cover.begin && r.tracked && r.method == kRelocalisationMethod) ++b.relocalised_frames;
  }
  const FrameRecord* after = record_of(frames, cover.end);
  if (!after) return b;
  b.first_after = cover.end;
  b.first_after_tracked = after->tracked;
  b.first_after_state = after->state;
  b.first_after_method = after->method;
  if (!after->tracked) return b;
  if (b.last_before) b.first_after_error = relative_error(*b.last_before, cover.end, fps, est, gt);
  if (eval) b.first_after_ate = aligned_error(cover.end, fps, *eval);
  return b;
}

}  // namespace pvb::run
