#pragma once
// The scenario checker: compares a run's metrics.json with the bounds in the
// scenario's `expect:` section (scenes::Expectations).  Used by
// `pvbench check` and by the scenario CTest suite.
#include <string>
#include <vector>

#include "pvb/scenes/scenario.hpp"
#include "pvb/suite/metrics_file.hpp"

namespace pvb::suite {

/// One violated bound: the `expect:` key and a one-line explanation with the
/// measured value and the bound, e.g. "ATE RMSE 0.0143 m > 0.01 m".
struct Violation {
  std::string key;
  std::string message;
  std::string line() const { return key + ": " + message; }
};

/// Checks `metrics` against `expect`; an empty list means every bound holds.
/// Rules:
/// - unless tracking_loss_expected, the run must have status "completed";
/// - ate_rmse_m_max / rpe_trans_rmse_m_max: the primary run's RMSE <= bound
///   (a null ate / rpe is a violation);
/// - lost_frames_max: the primary run's lost_frames <= bound;
/// - pe_not_worse_than_baseline: a "baseline" must be present and the
///   primary (PE-SLAM) ATE RMSE <= the baseline's.  The bound is a claim
///   about the whole scenario: when `scenario_frames` > 0 and the run
///   tracked fewer frames (cut short with --frames, as the fast CI subset
///   does), it is not judged and a note with both values goes to `notes`.
///   On a cut run the two differ by hundredths of a millimetre either way
///   (docs/scenarios.md), which says nothing about the scenario;
/// - tracking_loss_expected: the run must report at least one loss event,
///   each with a frame and a non-empty reason, and must not be "interrupted".
std::vector<Violation> check_expectations(const scenes::Expectations& expect, const MetricsFile& metrics,
                                          int scenario_frames = 0, std::vector<std::string>* notes = nullptr);

/// Same, reading the metrics from a file (throws IoError as read_metrics_file).
std::vector<Violation> check_expectations(const scenes::Expectations& expect,
                                          const std::string& metrics_json_path, int scenario_frames = 0,
                                          std::vector<std::string>* notes = nullptr);

}  // namespace pvb::suite
