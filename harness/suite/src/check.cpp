#include "pvb/suite/check.hpp"

#include <cstdio>

namespace pvb::suite {
namespace {

std::string metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g m", v);
  return buf;
}

}  // namespace

std::vector<Violation> check_expectations(const scenes::Expectations& expect, const MetricsFile& metrics,
                                          int scenario_frames, std::vector<std::string>* notes) {
  std::vector<Violation> out;
  const RunMetrics& run = metrics.primary;

  if (expect.tracking_loss_expected) {
    if (run.status == "interrupted")
      out.push_back({"tracking_loss_expected", "the run was interrupted before it ended"});
    if (run.loss_events.empty()) {
      out.push_back({"tracking_loss_expected", "no tracking loss was reported (" +
                                                   std::to_string(run.lost_frames) +
                                                   " lost frames, no loss_events)"});
    }
    for (std::size_t i = 0; i < run.loss_events.size(); ++i) {
      const LossEvent& e = run.loss_events[i];
      if (e.reason.empty())
        out.push_back({"tracking_loss_expected", "loss event " + std::to_string(i) + " (frame " +
                                                     std::to_string(e.frame) + ") gives no reason"});
      if (e.frame < 0)
        out.push_back({"tracking_loss_expected", "loss event " + std::to_string(i) + " has no frame number"});
    }
  } else if (run.status != "completed") {
    out.push_back({"status", "the run ended " + run.status + ", expected completed"});
  }

  if (expect.ate_rmse_m_max) {
    if (!run.ate_rmse_m)
      out.push_back({"ate_rmse_m_max", "no ATE in the metrics (ate is null)"});
    else if (!(*run.ate_rmse_m <= *expect.ate_rmse_m_max))
      out.push_back(
          {"ate_rmse_m_max", "ATE RMSE " + metres(*run.ate_rmse_m) + " > " + metres(*expect.ate_rmse_m_max)});
  }
  if (expect.rpe_trans_rmse_m_max) {
    if (!run.rpe_trans_rmse_m)
      out.push_back({"rpe_trans_rmse_m_max", "no RPE in the metrics (rpe is null)"});
    else if (!(*run.rpe_trans_rmse_m <= *expect.rpe_trans_rmse_m_max))
      out.push_back({"rpe_trans_rmse_m_max", "RPE translation RMSE " + metres(*run.rpe_trans_rmse_m) + " > " +
                                                 metres(*expect.rpe_trans_rmse_m_max)});
  }
  if (expect.lost_frames_max && run.lost_frames > *expect.lost_frames_max)
    out.push_back({"lost_frames_max", std::to_string(run.lost_frames) + " lost frames > " +
                                          std::to_string(*expect.lost_frames_max)});

  const bool cut_short = scenario_frames > 0 && run.frames < scenario_frames;
  if (expect.pe_not_worse_than_baseline && cut_short) {
    if (notes != nullptr) {
      std::string both = "no ATE";
      if (metrics.baseline && metrics.baseline->ate_rmse_m && run.ate_rmse_m)
        both = "PE-SLAM ATE RMSE " + metres(*run.ate_rmse_m) + ", baseline " + metres(*metrics.baseline->ate_rmse_m);
      notes->push_back("pe_not_worse_than_baseline: not judged on a run cut to " + std::to_string(run.frames) +
                       " of " + std::to_string(scenario_frames) + " frames (" + both + ")");
    }
  } else if (expect.pe_not_worse_than_baseline) {
    if (!metrics.baseline)
      out.push_back({"pe_not_worse_than_baseline", "no baseline in the metrics (run with --compare)"});
    else if (!metrics.baseline->ate_rmse_m)
      out.push_back({"pe_not_worse_than_baseline", "the baseline has no ATE (ate is null)"});
    else if (!run.ate_rmse_m)
      out.push_back({"pe_not_worse_than_baseline", "PE-SLAM has no ATE (ate is null)"});
    else if (!(*run.ate_rmse_m <= *metrics.baseline->ate_rmse_m))
      out.push_back({"pe_not_worse_than_baseline", "PE-SLAM ATE RMSE " + metres(*run.ate_rmse_m) +
                                                       " > baseline " +
                                                       metres(*metrics.baseline->ate_rmse_m)});
  }
  return out;
}

std::vector<Violation> check_expectations(const scenes::Expectations& expect,
                                          const std::string& metrics_json_path, int scenario_frames,
                                          std::vector<std::string>* notes) {
  return check_expectations(expect, read_metrics_file(metrics_json_path), scenario_frames, notes);
}

}  // namespace pvb::suite
