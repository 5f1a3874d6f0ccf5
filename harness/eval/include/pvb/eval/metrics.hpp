#pragma once
// Absolute trajectory error (ATE) and relative pose error (RPE), defined as in
// the TUM RGB-D benchmark's evaluate_ate.py and evaluate_rpe.py (see
// docs/evaluation.md).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pvb/geometry/se3.hpp"

namespace pvb::eval {

/// Summary statistics of a list of errors.  std is the population standard
/// deviation (numpy.std), median averages the two middle values for even
/// counts (numpy.median).  All zero with count 0 for an empty list.
struct Stats {
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
  std::size_t count = 0;
};

/// Computes Stats over `values` (not modified).
Stats compute_stats(const std::vector<double>& values);

/// p-quantile (p in 0..1, clamped) with linear interpolation between the
/// sorted values (numpy.percentile's default); 0 for no values.  The one
/// quantile of the harness's timing, gravity and map summaries.
double percentile(std::vector<double> values, double p);

/// Arithmetic mean; 0 for no values.
double mean_of(const std::vector<double>& values);

/// ATE per pose: |t(gt_i) - t(est_i)| in metres, for already aligned,
/// associated pose lists of equal length (EvalError otherwise).
std::vector<double> ate_errors_m(const std::vector<geom::SE3d>& est, const std::vector<geom::SE3d>& gt);

/// Unit of the RPE delta.
enum class DeltaUnit {
  kFrames,   ///< pose index along the associated sequence
  kSeconds,  ///< estimate time stamps
  kMetres,   ///< distance travelled along the (aligned) estimate
};

/// Parses "f", "s" or "m"; throws pvb::ConfigError otherwise.
DeltaUnit parse_delta_unit(const std::string& name);
/// "f", "s" or "m".
const char* delta_unit_name(DeltaUnit u);

/// Which pose pairs (i, j) the RPE is evaluated on.
enum class PairMode {
  kAll,          ///< every start pose i with its j at delta (evaluate_rpe.py --fixed_delta)
  kConsecutive,  ///< non-overlapping chained segments: i_0 = 0, i_{k+1} = j_k (evo's default)
};

/// Parses "all" or "consecutive"; throws pvb::ConfigError otherwise.
PairMode parse_pair_mode(const std::string& name);

struct RpeOptions {
  double delta = 1.0;                    ///< in `unit`
  DeltaUnit unit = DeltaUnit::kFrames;
  PairMode pairs = PairMode::kAll;
};

/// One evaluated pose pair.
struct RpePair {
  std::size_t i = 0, j = 0;  ///< indices into the associated sequence
  double trans_m = 0.0;      ///< translational error, metres
  double rot_deg = 0.0;      ///< rotational error, degrees
  /// The same error E signed, per axis of the start camera (x right, y down,
  /// z forward for an optical frame): so3_log(R(E)) in degrees and t(E) in
  /// metres.  Their means over many pairs separate a bias (a calibration or
  /// model error repeats with the motion) from random drift.
  geom::Vec3d rot_err_deg = geom::Vec3d::Zero();
  geom::Vec3d trans_err_m = geom::Vec3d::Zero();
};

/// Per-axis mean and population standard deviation of signed 3-vectors.
struct AxisStats {
  geom::Vec3d mean = geom::Vec3d::Zero();
  geom::Vec3d std = geom::Vec3d::Zero();
  std::size_t count = 0;
};

/// AxisStats over `values`; all zero with count 0 for an empty list.
AxisStats compute_axis_stats(const std::vector<geom::Vec3d>& values);

/// Selects the RPE pose pairs.  `index` is the monotonic coordinate of each
/// pose in the delta unit (frame number, seconds or metres travelled).
/// kAll follows evaluate_rpe.py: for every i, j is the pose whose index is
/// closest to index[i] + delta (the lower one on a tie), and the pair is
/// dropped when j is the last pose.  kConsecutive starts at 0, takes the same
/// closest j (at least i + 1), stops once index[i] + delta lies beyond the
/// last pose, and continues from j.
std::vector<std::pair<std::size_t, std::size_t>> select_rpe_pairs(const std::vector<double>& index,
                                                                  double delta, PairMode mode);

/// Relative pose error for associated pose lists (est[i] with gt[i]) whose
/// estimate times are `t_ns`.  For each pair (i, j), with A = est_i^-1 est_j
/// and B = gt_i^-1 gt_j, the error is E = A * B^-1 (evaluate_rpe.py's
/// ominus(ominus(est_j, est_i), ominus(gt_j, gt_i))); trans_m = |t(E)| and
/// rot_deg = acos(clamp((trace(R(E)) - 1) / 2, -1, 1)) in degrees.  Throws
/// EvalError when the lists differ in size, have fewer than 2 poses, or no
/// pair can be formed for this delta.
std::vector<RpePair> rpe(const std::vector<geom::SE3d>& est, const std::vector<geom::SE3d>& gt,
                         const std::vector<std::int64_t>& t_ns, const RpeOptions& options);

}  // namespace pvb::eval
