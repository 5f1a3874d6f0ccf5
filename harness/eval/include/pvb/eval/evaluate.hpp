#pragma once
// The whole evaluation of one estimate against ground truth: associate,
// align, ATE, RPE; plus the text reports `pvbench eval` prints and writes.
#include <cstdint>
#include <string>
#include <vector>

#include "pvb/eval/align.hpp"
#include "pvb/eval/associate.hpp"
#include "pvb/eval/metrics.hpp"
#include "pvb/eval/trajectory.hpp"

namespace pvb::eval {

struct EvalOptions {
  AssociationOptions association;
  Alignment alignment = Alignment::kSe3;
  RpeOptions rpe;
};

struct EvalResult {
  std::string est_source;                ///< estimate file name
  std::vector<IndexPair> pairs;          ///< association (indices into gt and est)
  std::vector<std::int64_t> t_ns;        ///< estimate time of each associated pair
  std::vector<geom::SE3d> T_w_c_gt;      ///< associated ground-truth poses
  std::vector<geom::SE3d> T_w_c_est;     ///< associated estimated poses, after alignment
  Sim3Transform alignment;               ///< applied to the estimate
  Alignment alignment_kind = Alignment::kSe3;
  std::vector<double> ate_m;             ///< ATE per associated pose, metres
  Stats ate;                             ///< statistics of ate_m
  std::vector<RpePair> rpe_pairs;        ///< evaluated RPE pairs
  Stats rpe_trans_m;                     ///< translational RPE, metres
  Stats rpe_rot_deg;                     ///< rotational RPE, degrees
  AxisStats rpe_rot_axes_deg;            ///< signed rotational RPE per start-camera axis, degrees
  AxisStats rpe_trans_axes_m;            ///< signed translational RPE per start-camera axis, metres
  RpeOptions rpe_options;
};

/// Evaluates `est` against `gt` (neither is modified): checks every pose
/// (EvalError naming the trajectory and time for one that is not finite or
/// beyond kMaxAbsCoordinateM), associates them
/// (EvalError when nothing associates), aligns the estimate, and computes ATE
/// and RPE.  The RPE is computed on the associated, aligned poses; it does not
/// depend on se3/origin alignment, and with sim3 it uses the recovered scale.
EvalResult evaluate(const Trajectory& gt, const Trajectory& est, const EvalOptions& options);

/// A human-readable table of one result (association, alignment, ATE, RPE).
std::string format_report(const EvalResult& result);

/// The per-axis block of format_report: the signed RPE's mean and standard
/// deviation on each start-camera axis, rotation in degrees and translation
/// in millimetres.  With consecutive (non-overlapping) pairs it adds each
/// mean's t statistic, mean / (std / sqrt(n - 1)): |t| well above 2 is a
/// bias rather than random drift.  docs/evaluation.md, "Bias or drift".
std::string format_rpe_axes(const EvalResult& result);

/// Side-by-side table of several results against the same ground truth; every
/// metric of the second and later estimates also shows its reduction in
/// percent relative to the first estimate (positive = smaller error).
std::string format_comparison(const std::vector<EvalResult>& results);

/// Reduction of `value` relative to `reference` in percent:
/// 100 * (reference - value) / reference; 0 when reference is 0.
double reduction_percent(double reference, double value);

/// JSON object of one Stats: {"rmse", "mean", "median", "std", "min", "max", "count"}
/// on one line (non-finite values as null).
std::string stats_json(const Stats& s);

/// JSON object of a result's RPE on one line: {"delta", "unit", "pairs",
/// "trans": stats_json, "rot_deg": stats_json, "axes": {"rot_deg": {"mean":
/// [x, y, z], "std": [...]}, "trans_m": {...}}} (the "rpe" value of
/// format_json).
std::string rpe_json(const EvalResult& result);

/// JSON of one result: pairs, ate.{rmse,mean,median,std,min,max,count},
/// rpe.{delta,unit,trans.{...},rot_deg.{...}}, alignment.{kind,R,t,s}.
std::string format_json(const EvalResult& result);

/// JSON for `pvbench eval`: the first result's fields at the top level (so a
/// single estimate gives exactly format_json()), plus "gt" and, for several
/// estimates, "runs": [format_json(r) ...] with "reduction_percent" of each
/// metric against the first.
std::string format_json_document(const std::string& gt_source, const std::vector<EvalResult>& results);

}  // namespace pvb::eval
