#pragma once
// Gravity and tilt against ground truth (docs/evaluation.md, "Gravity and
// tilt"):
//  - the gravity error per frame: the angle between the estimated and the
//    true direction of gravity, both in the camera frame: estimated
//    R_c_map * (0, 0, -1) (the map's down; the map frame is gravity-aligned
//    only when the SLAM system fuses an accelerometer, else it is the first
//    camera's frame and the figure measures that frame's tilt), true
//    R_c_w * down_w (the ground truth's down);
//  - per keyframe, after the ATE alignment, the pitch and roll error: the
//    error rotation R_err = R_w_c_true^T * R_w_c_est (the estimated camera in
//    the true camera's frame) as a rotation vector w = log(R_err); pitch =
//    w_x (about the camera's x axis, right; positive: the optical axis turned
//    up, towards -y), roll = w_z (about the optical axis; positive: x turned
//    towards +y, down); degrees.  Their least-squares slope over the
//    keyframe index, in degrees per keyframe, and its sign.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pvb/eval/align.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/geometry/se3.hpp"

namespace pvb::eval {

struct GravityError {
  std::string map_frame;          ///< "gravity_aligned" or "first_camera" (the caller's label)
  std::vector<double> t_s;        ///< frame time from the first associated frame
  std::vector<double> angle_deg;  ///< per associated frame
  double median_deg = 0, p95_deg = 0, final_deg = 0;
};

/// The core's gravity over time: each entry (time in ns, gravity's
/// direction in the map's frame) holds from its time, less a millisecond
/// (trajectory files keep microseconds), until the next entry.  A zero
/// vector, or a frame before the first entry, takes the map's -z (before
/// the inertial state is trusted, the map's frame is all the core says
/// about gravity).  Entries are made only where the estimate changes
/// (`record_gravity`), so a long run keeps one per refinement, not one per
/// frame.
using GravityEstimates = std::map<std::int64_t, geom::Vec3d>;

/// Adds the core's estimate at t_ns (none: not trusted, or not given) to
/// `estimates` when it differs from the one held at that time; estimates
/// are recorded in time order.
void record_gravity(GravityEstimates* estimates, std::int64_t t_ns, const std::optional<geom::Vec3d>& g_w);

/// The gravity error of `est` (T_map_c) against `gt` (T_w_c) with gravity
/// down_w in gt's world (normalised here): per frame, the angle between the
/// true and the estimated down seen from the camera.  Frames associated as
/// the ATE associates them.  Empty when nothing associates.
GravityError gravity_error(const Trajectory& gt, const Trajectory& est, const geom::Vec3d& down_w,
                           const std::string& map_frame, const GravityEstimates& estimates = {});

struct TiltDrift {
  std::vector<double> t_s;  ///< keyframe time from the first associated keyframe
  std::vector<double> pitch_deg, roll_deg;
  double pitch_mean_deg = 0, roll_mean_deg = 0;
  double pitch_slope_deg_per_kf = 0, roll_slope_deg_per_kf = 0;  ///< least squares over the keyframe index
  int pitch_slope_sign = 0, roll_slope_sign = 0;                 ///< -1, 0 or +1
};

/// Pitch and roll error of the keyframes `keyframes` (T_map_c), put into
/// gt's world by `alignment` (the camera trajectory's ATE alignment).
TiltDrift tilt_drift(const Trajectory& gt, const Trajectory& keyframes, const Sim3Transform& alignment);

/// Pitch (x) and roll (z) error, degrees, of an estimated camera against the true one.
std::pair<double, double> pitch_roll_error_deg(const geom::Mat3d& R_w_c_true, const geom::Mat3d& R_w_c_est);

/// Least-squares slope of `v` over its index (0 for fewer than 2 values).
double slope_per_index(const std::vector<double>& v);

/// {"map_frame": ..., "frames": n, "median_deg", "p95_deg", "final_deg", "t_s": [...], "angle_deg": [...]}.
std::string gravity_json(const GravityError& g);
/// {"keyframes": n, "pitch_mean_deg", "pitch_slope_deg_per_keyframe", "pitch_slope_sign", the same for
/// roll, "t_s": [...], "pitch_deg": [...], "roll_deg": [...]}.
std::string tilt_json(const TiltDrift& t);

}  // namespace pvb::eval
