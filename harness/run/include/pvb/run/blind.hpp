#pragma once
// The blind stretch of a run (a scenario's cover, or a kidnap's covered
// frames): what one SLAM system did while its camera saw nothing, and how
// well it came out of it.  docs/evaluation.md, "The blind stretch".
#include <optional>
#include <vector>

#include "pvb/eval/evaluate.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/report/report.hpp"
#include "pvb/scenes/scenario.hpp"

namespace pvb::run {

/// The error of an estimated pose against the true one: the distance
/// between their positions and the angle of R_true^T R_est.
PoseError pose_error(const geom::SE3d& T_w_c_true, const geom::SE3d& T_w_c_est);

/// The blind stretch of one system: `frames` its per-frame records (frame
/// i at geom::frame_time_ns(0, i, fps)), `est` its trajectory, `gt` the
/// ground truth and `eval` its evaluation against it (nullopt: none).
BlindStretch blind_stretch(const scenes::CoverFrames& cover, double fps,
                           const std::vector<FrameRecord>& frames, const eval::Trajectory& est,
                           const eval::Trajectory& gt, const std::optional<eval::EvalResult>& eval);

}  // namespace pvb::run
