#include "pvb/suite/check.hpp"

#include <algorithm>
#include <cstdio>

#include "pvb/common/text.hpp"

namespace pvb::suite {
namespace {

std::string metres(double v) { return format_number("%.4g m", v); }

/// Millimetres with two decimals; `sign` writes + before a positive value.
std::string millimetres(double v_m, bool sign = true) {
  return format_number(sign ? "%+.2f mm" : "%.2f mm", v_m * 1000.0);
}

std::string pe_against_baseline_note(double pe_m, double baseline_m) {
  return "PE-SLAM − baseline ATE RMSE " + millimetres(pe_m - baseline_m) + " (PE-SLAM " + metres(pe_m) +
         ", baseline " + metres(baseline_m) +
         "); one run does not judge this, a seed sweep does (expect.sweep, pvbench sweep --compare --check)";
}

/// The place-recognition bounds: labels must be there to judge them.
void check_place(const scenes::Expectations& expect, const RunMetrics& run, std::vector<Violation>* out) {
  const bool wanted = expect.false_loops_max || expect.loops_min;
  if (!wanted) return;
  const std::string key = expect.false_loops_max ? "false_loops_max" : "loops_min";
  if (!run.place || !run.place->loops_false || !run.place->relocalisations_false) {
    out->push_back({key, "no ground-truth labels of loops in the metrics (place_recognition)"});
    return;
  }
  const PlaceMetrics& p = *run.place;
  if (expect.false_loops_max && *p.loops_false > *expect.false_loops_max)
    out->push_back({"false_loops_max", std::to_string(*p.loops_false) + " false loops > " +
                                           std::to_string(*expect.false_loops_max)});
  if (expect.false_loops_max && *p.relocalisations_false > *expect.false_loops_max)
    out->push_back({"false_loops_max", std::to_string(*p.relocalisations_false) + " false relocalisations > " +
                                           std::to_string(*expect.false_loops_max)});
  if (expect.loops_min && p.loops_true.value_or(0) < *expect.loops_min)
    out->push_back({"loops_min", std::to_string(p.loops_true.value_or(0)) + " true loops < " +
                                     std::to_string(*expect.loops_min)});
}

/// relocalised_within_frames: each loss, counted from the camera's return.
void check_relocalisation(const scenes::Expectations& expect, const RunMetrics& run, std::vector<Violation>* out) {
  if (!expect.relocalised_within_frames) return;
  const int bound = *expect.relocalised_within_frames;
  // Lost frames without their loss events cannot be judged: a violation,
  // never a silent pass.
  if (run.lost_frames > 0 && run.loss_events.empty()) {
    out->push_back({"relocalised_within_frames", "not judged: " + std::to_string(run.lost_frames) +
                                                     " lost frames but no loss_events in the metrics"});
    return;
  }
  for (const LossEvent& e : run.loss_events) {
    int from = e.frame;
    if (run.camera_covered_frames && run.camera_covered_frames->first <= e.frame + bound &&
        run.camera_covered_frames->second + 1 > from)
      from = std::max(from, run.camera_covered_frames->second + 1);
    if (!e.recovered_frame) {
      out->push_back({"relocalised_within_frames", "the loss at frame " + std::to_string(e.frame) +
                                                       " was never recovered"});
    } else if (*e.recovered_frame - from > bound) {
      out->push_back({"relocalised_within_frames",
                      "the loss at frame " + std::to_string(e.frame) + " was recovered at frame " +
                          std::to_string(*e.recovered_frame) + ", " + std::to_string(*e.recovered_frame - from) +
                          " frames after the camera's return at frame " + std::to_string(from) + " > " +
                          std::to_string(bound)});
    }
  }
}

/// blind_no_global_relocalisation: tracking resumes on the first frame
/// after the cover (state ok) in the same map, and neither it nor a covered
/// frame was tracked by a global relocalisation.
void check_blind_relocalisation(const BlindMetrics& b, std::vector<Violation>* out) {
  const std::string key = "blind_no_global_relocalisation";
  if (!b.first_after) {
    out->push_back({key, "the run ended before the first frame after the cover"});
    return;
  }
  const std::string frame = "the first frame after the cover (" + std::to_string(*b.first_after) + ")";
  if (!b.first_after_tracked)
    out->push_back({key, frame + " has no pose (state " + b.first_after_state + ")"});
  else if (b.first_after_method == "reloc")
    out->push_back({key, frame + " was tracked by a global relocalisation"});
  else if (b.first_after_method == "init")
    out->push_back({key, frame + " began a new map"});
  else if (b.first_after_state != "ok")
    out->push_back({key, frame + " has a pose but tracking has not resumed (state " + b.first_after_state + ")"});
  if (b.relocalised_frames > 0 && b.first_after_method != "reloc")
    out->push_back({key, std::to_string(b.relocalised_frames) + " covered frames were tracked by a global "
                                                                "relocalisation"});
}

/// The bounds on the blind stretch (a cover, or a kidnap's covered frames).
void check_blind(const scenes::Expectations& expect, const RunMetrics& run, std::vector<Violation>* out) {
  if (!expect.any_blind_bound()) return;
  if (!run.blind) {
    const std::string key = expect.blind_poses_all             ? "blind_poses_all"
                            : expect.blind_after_error_m_max   ? "blind_after_error_m_max"
                            : expect.blind_after_error_deg_max ? "blind_after_error_deg_max"
                                                               : "blind_no_global_relocalisation";
    out->push_back({key, "no blind stretch in the metrics (blind is absent)"});
    return;
  }
  const BlindMetrics& b = *run.blind;
  if (expect.blind_poses_all && b.covered_with_pose < b.covered_frames())
    out->push_back({"blind_poses_all", std::to_string(b.covered_with_pose) + " of " +
                                           std::to_string(b.covered_frames()) +
                                           " covered frames have a pose"});
  const std::string no_error =
      "no error across the stretch in the metrics (the first frame after it or the "
      "last before it has no pose)";
  if (expect.blind_after_error_m_max) {
    if (!b.first_after_error_m)
      out->push_back({"blind_after_error_m_max", no_error});
    else if (!(*b.first_after_error_m <= *expect.blind_after_error_m_max))
      out->push_back({"blind_after_error_m_max", "error across the stretch " +
                                                     metres(*b.first_after_error_m) + " > " +
                                                     metres(*expect.blind_after_error_m_max)});
  }
  if (expect.blind_after_error_deg_max) {
    if (!b.first_after_error_deg)
      out->push_back({"blind_after_error_deg_max", no_error});
    else if (!(*b.first_after_error_deg <= *expect.blind_after_error_deg_max))
      out->push_back({"blind_after_error_deg_max",
                      "error across the stretch " + format_number("%.4g deg", *b.first_after_error_deg) +
                          " > " + format_number("%.4g deg", *expect.blind_after_error_deg_max)});
  }
  if (expect.blind_no_global_relocalisation) check_blind_relocalisation(b, out);
}

/// The dense-map bounds, on the corrected map's scores.
void check_map(const scenes::Expectations& expect, const RunMetrics& run, std::vector<Violation>* out) {
  if (!expect.map_accuracy_m_max && !expect.map_completeness_min) return;
  const MapMetrics* m = run.map("corrected");
  const std::string key = expect.map_accuracy_m_max ? "map_accuracy_m_max" : "map_completeness_min";
  if (m == nullptr) {
    out->push_back({key, "no scores of the corrected dense map in the metrics (dense_map.maps.corrected)"});
    return;
  }
  if (expect.map_accuracy_m_max && !m->accuracy_median_m)
    out->push_back({"map_accuracy_m_max", "not judged: the corrected dense map has no points"});
  else if (expect.map_accuracy_m_max && !(*m->accuracy_median_m <= *expect.map_accuracy_m_max))
    out->push_back({"map_accuracy_m_max", "dense map median accuracy " + metres(*m->accuracy_median_m) + " > " +
                                              metres(*expect.map_accuracy_m_max)});
  if (expect.map_completeness_min && !(m->completeness_5cm >= *expect.map_completeness_min))
    out->push_back({"map_completeness_min", "dense map complete within 5 cm " +
                                                format_number("%.1f %%", 100 * m->completeness_5cm) + " < " +
                                                format_number("%.1f %%", 100 * *expect.map_completeness_min)});
}

}  // namespace

std::vector<Violation> check_expectations(const scenes::Expectations& expect, const MetricsFile& metrics,
                                          std::vector<std::string>* notes) {
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
  if (expect.keyframes_max) {
    if (!run.keyframes)
      out.push_back({"keyframes_max", "no keyframe count in the metrics (keyframes is absent)"});
    else if (*run.keyframes > *expect.keyframes_max)
      out.push_back({"keyframes_max", std::to_string(*run.keyframes) + " keyframes in the final map > " +
                                          std::to_string(*expect.keyframes_max)});
  }
  if (expect.refined_ate_rmse_m_max) {
    if (!run.refined_ate_rmse_m)
      out.push_back({"refined_ate_rmse_m_max", "no refined ATE in the metrics (refined is absent)"});
    else if (!(*run.refined_ate_rmse_m <= *expect.refined_ate_rmse_m_max))
      out.push_back({"refined_ate_rmse_m_max", "refined ATE RMSE " + metres(*run.refined_ate_rmse_m) + " > " +
                                                   metres(*expect.refined_ate_rmse_m_max)});
  }
  check_place(expect, run, &out);
  check_relocalisation(expect, run, &out);
  check_map(expect, run, &out);
  check_blind(expect, run, &out);

  if (notes != nullptr && metrics.baseline && metrics.baseline->ate_rmse_m && run.ate_rmse_m)
    notes->push_back(pe_against_baseline_note(*run.ate_rmse_m, *metrics.baseline->ate_rmse_m));
  return out;
}

std::vector<Violation> check_expectations(const scenes::Expectations& expect,
                                          const std::string& metrics_json_path,
                                          std::vector<std::string>* notes) {
  return check_expectations(expect, read_metrics_file(metrics_json_path), notes);
}

std::vector<Violation> check_sweep(const scenes::Expectations& expect, const SweepAggregate& sweep,
                                   std::vector<std::string>* notes) {
  std::vector<Violation> out;
  for (const SeedRun& r : sweep.runs) {
    const std::string seed = "seed " + std::to_string(r.seed) + ": ";
    if (!r.metrics) {
      out.push_back({seed + "metrics", "none (" + r.error + ")"});
      continue;
    }
    for (Violation v : check_expectations(expect, *r.metrics)) out.push_back({seed + v.key, v.message});
  }
  if (!expect.sweep.pe_not_significantly_worse) return out;
  const std::string key = "sweep.pe_not_significantly_worse";
  const PairedComparison& p = sweep.paired;
  if (!sweep.has_baseline) {
    out.push_back({key, "no baseline in the sweep (run it with --compare)"});
  } else if (p.count < expect.sweep.min_seeds) {
    out.push_back({key, "needs " + std::to_string(expect.sweep.min_seeds) + " seeds with both ATEs, got " +
                            std::to_string(p.count)});
  } else if (!p.not_worse) {
    out.push_back({key, "the paired 95 % interval of PE-SLAM − baseline ATE reaches " +
                            millimetres(p.ci_high_m) + " > margin " + millimetres(p.margin_m, false) +
                            " over " + std::to_string(p.count) + " seeds"});
  } else if (notes != nullptr) {
    notes->push_back(key + ": holds, the paired 95 % interval of PE-SLAM − baseline ATE reaches " +
                     millimetres(p.ci_high_m) + " <= margin " + millimetres(p.margin_m, false) + " over " +
                     std::to_string(p.count) + " seeds");
  }
  return out;
}

}  // namespace pvb::suite
