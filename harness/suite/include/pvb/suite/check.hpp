#pragma once
// The scenario checker: compares a run's metrics.json with the bounds in the
// scenario's `expect:` section (scenes::Expectations).  Used by
// `pvbench check` and by the scenario CTest suite.
#include <string>
#include <vector>

#include "pvb/scenes/scenario.hpp"
#include "pvb/suite/aggregate.hpp"
#include "pvb/suite/metrics_file.hpp"

namespace pvb::suite {

/// One violated bound: the `expect:` key and a one-line explanation with the
/// measured value and the bound, e.g. "ATE RMSE 0.0143 m > 0.01 m".
struct Violation {
  std::string key;
  std::string message;
  std::string line() const { return key + ": " + message; }
};

/// Checks `metrics` against `expect`'s single-run bounds; an empty list means
/// every bound holds.  Rules:
/// - unless tracking_loss_expected, the run must have status "completed";
/// - ate_rmse_m_max / rpe_trans_rmse_m_max: the primary run's RMSE <= bound
///   (a null ate / rpe is a violation);
/// - lost_frames_max: the primary run's lost_frames <= bound;
/// - keyframes_max: the primary run's final map has at most this many
///   keyframes (a file without the count is a violation);
/// - refined_ate_rmse_m_max: the refined trajectory's ATE RMSE <= bound;
/// - false_loops_max: loops_false <= bound and relocalisations_false <=
///   bound (the run must carry ground-truth labels);
/// - loops_min: loops_true >= bound;
/// - relocalised_within_frames: every loss recovered, by a relocalisation,
///   within the bound of the camera's return (the loss's frame, or the
///   last covered frame + 1 when camera_covered_frames overlaps the loss);
/// - blind_poses_all, blind_after_error_m_max / _deg_max,
///   blind_no_global_relocalisation: on the run's "blind" object (absent:
///   a violation): every covered frame has a pose; the motion across the
///   stretch within the bounds of the truth; tracking resumes on the first
///   frame after the cover (state "ok", method neither "reloc" nor "init")
///   and no covered frame was tracked by a relocalisation;
/// - tracking_loss_expected: the run must report at least one loss event,
///   each with a frame and a non-empty reason, and must not be "interrupted".
/// PE-SLAM against the baseline is never judged on one run: when both ATEs
/// are present, their difference goes to `notes` (expect.sweep judges it over
/// seeds, check_sweep below).
std::vector<Violation> check_expectations(const scenes::Expectations& expect, const MetricsFile& metrics,
                                          std::vector<std::string>* notes = nullptr);

/// Same, reading the metrics from a file (throws IoError as read_metrics_file).
std::vector<Violation> check_expectations(const scenes::Expectations& expect,
                                          const std::string& metrics_json_path,
                                          std::vector<std::string>* notes = nullptr);

/// Checks a seed sweep: every seed's run against the single-run bounds (keys
/// "seed S: KEY") and, when expect.sweep.pe_not_significantly_worse is set,
/// the paired verdict (key "sweep.pe_not_significantly_worse"): at least
/// expect.sweep.min_seeds seeds with both ATEs, and the paired comparison's
/// not_worse (aggregate.hpp).  What held goes to `notes`.
std::vector<Violation> check_sweep(const scenes::Expectations& expect, const SweepAggregate& sweep,
                                   std::vector<std::string>* notes = nullptr);

}  // namespace pvb::suite
