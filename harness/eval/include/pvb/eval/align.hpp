#pragma once
// Aligning an estimated trajectory to ground truth before computing errors.
#include <string>
#include <vector>

#include "pvb/geometry/se3.hpp"

namespace pvb::eval {

/// How the estimate is brought into the ground-truth frame.
enum class Alignment {
  kSe3,     ///< rotation + translation, least squares on positions (Umeyama/Horn)
  kSim3,    ///< rotation + translation + scale (Umeyama)
  kNone,    ///< identity
  kOrigin,  ///< the rigid transform that makes the first estimated pose equal the first ground-truth pose
};

/// Parses "se3", "sim3", "none" or "origin"; throws pvb::ConfigError otherwise.
Alignment parse_alignment(const std::string& name);
/// The name parse_alignment() accepts for `a`.
const char* alignment_name(Alignment a);

/// A similarity transform acting on world points: p' = s * R * p + t.
struct Sim3Transform {
  geom::Mat3d R = geom::Mat3d::Identity();
  geom::Vec3d t = geom::Vec3d::Zero();
  double s = 1.0;

  /// Applies the transform to a point.
  geom::Vec3d apply(const geom::Vec3d& p) const { return s * (R * p) + t; }
  /// Applies the transform to a pose T_w_c: the rotation becomes R * R_w_c and
  /// the position apply(t_w_c).  (Scale changes positions, never rotations.)
  geom::SE3d apply(const geom::SE3d& T_w_c) const {
    return geom::make_se3(geom::Mat3d(R * T_w_c.linear()), apply(geom::Vec3d(T_w_c.translation())));
  }
};

/// Least-squares similarity (Umeyama 1991) mapping `est` positions onto the
/// corresponding `gt` positions, minimising sum |gt_i - (s R est_i + t)|^2.
/// With with_scale == false s is fixed to 1 (this is the same optimum as
/// Horn's method used by TUM's evaluate_ate.py).  Inputs are not modified.
/// Throws EvalError when the sizes differ, when there are fewer than 3 pairs,
/// when a position is not finite or beyond kMaxAbsCoordinateM, or when
/// either point set is degenerate (all points on one line or one point),
/// since the rotation is then not determined.
Sim3Transform umeyama(const std::vector<geom::Vec3d>& est, const std::vector<geom::Vec3d>& gt,
                      bool with_scale);

/// Computes the alignment of kind `kind` from associated poses (est[i] goes
/// with gt[i]).  kSe3/kSim3 use umeyama() on the positions and need at least
/// 3 pairs; when one position set lies on a line (a robot driving exactly
/// straight) the positions leave the turn about that line free and it is
/// taken from the orientations (the turn that best maps the estimated
/// orientations onto the true ones).  kOrigin uses the first pair; kNone
/// returns the identity.  Throws EvalError when there are too few pairs.
Sim3Transform compute_alignment(const std::vector<geom::SE3d>& est, const std::vector<geom::SE3d>& gt,
                                Alignment kind);

/// Returns a copy of `poses` with `transform` applied to each; the input is
/// not modified.
std::vector<geom::SE3d> apply_alignment(const Sim3Transform& transform, const std::vector<geom::SE3d>& poses);

}  // namespace pvb::eval
