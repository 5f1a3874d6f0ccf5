#include "pvb/report/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>

#include "pvb/common/text.hpp"
#include "pvb/eval/charts.hpp"
#include "pvb/eval/slam_mode.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/plot/png.hpp"
#include "report_inertial.hpp"
#include "report_parts.hpp"

namespace pvb::run {
namespace {

/// JSON number: finite values with enough digits, null otherwise.
std::string num(double v) { return json_number(v, 10); }

using eval::mean_of;

/// The keys one SLAM system contributes (shared by the top level and "baseline").
std::string slam_fields(const SlamRun& run, const std::string& in) {
  const std::vector<double> ms = tracking_times(run);
  std::string out;
  out += in + "\"mode\": " + json_string(run.mode) + ",\n";
  out += in + "\"sensors\": " + json_string(run.sensors) + ",\n";
  out += in + "\"frames\": " + std::to_string(run.frames) + ",\n";
  out += in + "\"lost_frames\": " + std::to_string(run.lost_frames) + ",\n";
  out += in + "\"not_initialized_frames\": " + std::to_string(run.not_initialized_frames) + ",\n";
  out += in + "\"keyframes\": " + std::to_string(run.keyframes) + ",\n";
  out += in + "\"map_points\": " + std::to_string(run.map_points) + ",\n";
  out += gravity_inertial_fields(run, in);
  if (run.eval) {
    out += in + "\"ate\": " + eval::stats_json(run.eval->ate) + ",\n";
    out += in + "\"rpe\": " + eval::rpe_json(*run.eval) + ",\n";
    out += in + "\"alignment\": " + json_string(eval::alignment_name(run.eval->alignment_kind)) + ",\n";
  } else {
    out += in + "\"ate\": null,\n" + in + "\"rpe\": null,\n" + in + "\"alignment\": null,\n";
  }
  if (!run.eval_note.empty()) out += in + "\"eval_note\": " + json_string(run.eval_note) + ",\n";
  if (run.refined_eval)
    out += in + "\"refined\": {\"ate_rmse\": " + num(run.refined_eval->ate.rmse) +
           ", \"rpe_trans_rmse\": " + num(run.refined_eval->rpe_trans_m.rmse) + "},\n";
  if (run.local_mapping) out += in + "\"local_mapping\": " + slam::to_json(*run.local_mapping) + ",\n";
  if (!run.loop_closing_json.empty()) out += in + "\"loop_closing\": " + run.loop_closing_json + ",\n";
  if (run.place) out += in + "\"place_recognition\": " + place_json(*run.place) + ",\n";
  if (run.dense_map) out += in + "\"dense_map\": " + dense_map_json(*run.dense_map, in) + ",\n";
  if (run.map) out += in + "\"map\": " + map_report_json(*run.map) + ",\n";
  if (run.blind) out += in + "\"blind\": " + blind_json(*run.blind) + ",\n";
  if (!run.costs.empty()) out += in + "\"costs\": " + costs_json(run.costs, run.cost_every_frames, in) + ",\n";
  out += in + "\"tracking_ms\": {\"median\": " + num(percentile(ms, 0.5)) +
         ", \"mean\": " + num(mean_of(ms)) + ", \"p95\": " + num(percentile(ms, 0.95)) + "},\n";
  out += in + "\"loss_events\": [";
  for (std::size_t k = 0; k < run.loss_events.size(); ++k) {
    const LossEvent& e = run.loss_events[k];
    out += (k ? ",\n" : "\n") + in + "  {\"frame\": " + std::to_string(e.frame) + ", \"t_s\": " + num(e.t_s) +
           ", \"reason\": " + json_string(e.reason) + ", \"recovered_frame\": " +
           (e.recovered_frame ? std::to_string(*e.recovered_frame) : std::string("null")) + "}";
  }
  out += run.loss_events.empty() ? "]" : "\n" + in + "]";
  return out;
}

/// Run-level keys (shared by the top level and "baseline").
std::string run_fields(const RunReport& r, const std::string& in) {
  std::string out;
  out += in + "\"scenario\": " + json_string(r.scenario) + ",\n";
  out += in + "\"scenario_file\": " + json_string(r.scenario_file) + ",\n";
  out += in + "\"seed\": " + std::to_string(r.seed) + ",\n";
  if (!r.world.empty()) out += in + "\"world\": " + r.world + ",\n";
  out += in + "\"status\": " + json_string(to_string(r.status)) + ",\n";
  if (!r.status_detail.empty()) out += in + "\"status_detail\": " + json_string(r.status_detail) + ",\n";
  out += in + "\"sync\": " + (r.sync ? "true" : "false") + ",\n";
  out += in + "\"renderer\": " + json_string(r.renderer) + ",\n";
  out += in + "\"fps\": " + num(r.fps) + ",\n";
  out += in + "\"realtime_factor\": " + num(realtime_factor(r.sim_s, r.wall_s)) + ",\n";
  out += in + "\"sim_s\": " + num(r.sim_s) + ",\n";
  out += in + "\"wall_s\": " + num(r.wall_s) + ",\n";
  out += in + "\"cpu_s\": " + num(r.cpu_s) + ",\n";
  if (r.camera_covered_frames)
    out += in + "\"camera_covered_frames\": [" + std::to_string(r.camera_covered_frames->first) + ", " +
           std::to_string(r.camera_covered_frames->second) + "],\n";
  return out;
}

}  // namespace

const std::vector<std::string>& cost_columns() {
  static const std::vector<std::string> columns = {
      "frame",     "t_s",      "keyframes",          "points",          "rss_mb",         "sparse_mb",
      "dense_mb",  "tracking_ms_median", "tracking_ms_p95", "loop_detect_ms", "mapping_ms_per_keyframe",
      "local_ba_ms", "dense_disk_mb", "sparse_disk_mb"};
  return columns;
}

std::vector<double> cost_values(const CostSample& c) {
  return {static_cast<double>(c.frame), c.t_s, static_cast<double>(c.keyframes), static_cast<double>(c.points),
          c.rss_mb, c.sparse_mb, c.dense_mb, c.tracking_ms_median, c.tracking_ms_p95, c.loop_detect_ms,
          c.mapping_ms_per_keyframe, c.local_ba_ms, c.dense_disk_mb, c.sparse_disk_mb};
}

std::string costs_json(const std::vector<CostSample>& samples, int every_frames, const std::string& in) {
  std::string out = "{\"every_frames\": " + std::to_string(every_frames) + ", \"columns\": [";
  const std::vector<std::string>& cols = cost_columns();
  for (std::size_t i = 0; i < cols.size(); ++i) out += (i ? ", " : "") + json_string(cols[i]);
  out += "], \"rows\": [";
  for (std::size_t k = 0; k < samples.size(); ++k) {
    out += (k ? ",\n" : "\n") + in + "  [";
    const std::vector<double> v = cost_values(samples[k]);
    for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + num(v[i]);
    out += "]";
  }
  return out + (samples.empty() ? "]}" : "\n" + in + "]}");
}

const MapResult* DenseMapReport::find(const std::string& name) const {
  for (const MapResult& m : maps)
    if (m.name == name) return &m;
  return nullptr;
}

std::string dense_map_json(const DenseMapReport& d, const std::string& in) {
  std::string out = "{\"keyframes\": " + std::to_string(d.keyframes) + ", \"points\": " + std::to_string(d.points) +
                    ", \"live_points\": " + std::to_string(d.live_points) +
                    ", \"pose_updates\": " + std::to_string(d.pose_updates) +
                    ", \"keyframes_moved\": " + std::to_string(d.keyframes_moved) +
                    ", \"update_ms\": {\"median\": " + num(d.update_ms_median) + ", \"max\": " + num(d.update_ms_max) +
                    "}, \"loop_update_ms\": [";
  for (std::size_t i = 0; i < d.loop_update_ms.size(); ++i) out += (i ? ", " : "") + num(d.loop_update_ms[i]);
  out += "], \"files\": [";
  for (std::size_t i = 0; i < d.files.size(); ++i) out += (i ? ", " : "") + json_string(d.files[i]);
  out += "]";
  if (!d.note.empty()) out += ", \"note\": " + json_string(d.note);
  if (!d.maps.empty()) {
    out += ",\n" + in + "  \"alignment\": " + json_string(d.alignment) +
           ", \"surface_samples\": " + std::to_string(d.surface_samples) +
           ", \"truth_s\": " + num(d.truth_s) + ",\n" + in + "  \"maps\": {";
    for (std::size_t i = 0; i < d.maps.size(); ++i)
      out += std::string(i ? "," : "") + "\n" + in + "    " + json_string(d.maps[i].name) + ": " +
             map_accuracy_json(d.maps[i].accuracy, static_cast<int>(in.size()) + 4);
    out += "\n" + in + "  }";
  }
  return out + "}";
}

namespace {

/// "refusals": {"kept", "dropped", "by_reason": {reason: n}, "verified", "verified_true"} and
/// "refusal_events": [{"t_s", "ref_t_s", "reason", "verified", "correction_m", "drift_bound_m",
/// "correct", "error_m", "error_deg"}] (the last three null unless verified and judged).
std::string refusals_json(const PlaceRecognition& p) {
  std::map<std::string, int> by_reason;
  std::string events = "[";
  int verified = 0, verified_true = 0;
  bool judged_any = false;
  for (std::size_t i = 0; i < p.refusals.size(); ++i) {
    const PlaceRecognition::Refusal& r = p.refusals[i];
    ++by_reason[r.reason];
    verified += r.verified ? 1 : 0;
    const bool judged = r.label && r.label->judged;
    judged_any = judged_any || r.label;
    verified_true += judged && r.label->correct ? 1 : 0;
    events += std::string(i ? ", " : "") + "{\"t_s\": " + json_number(r.event.t_ns * 1e-9, 12) +
              ", \"ref_t_s\": " + json_number(r.event.ref_t_ns * 1e-9, 12) + ", \"reason\": \"" + r.reason +
              "\", \"verified\": " + (r.verified ? "true" : "false") +
              ", \"correction_m\": " + num(r.correction_m) + ", \"drift_bound_m\": " + num(r.drift_bound_m) +
              ", \"correct\": " + (judged ? (r.label->correct ? "true" : "false") : "null") +
              ", \"error_m\": " + (judged ? num(r.label->error_m) : "null") +
              ", \"error_deg\": " + (judged ? num(r.label->error_deg) : "null") + "}";
  }
  std::string reasons = "{";
  for (const auto& [reason, n] : by_reason)
    reasons += std::string(reasons.size() > 1 ? ", " : "") + "\"" + reason + "\": " + std::to_string(n);
  return "\"refusals\": {\"kept\": " + std::to_string(p.refusals.size()) +
         ", \"dropped\": " + std::to_string(p.refusals_dropped) + ", \"by_reason\": " + reasons +
         "}, \"verified\": " + std::to_string(verified) + ", \"verified_true\": " +
         (!judged_any && verified > 0 ? std::string("null") : std::to_string(verified_true)) +
         "}, \"refusal_events\": " + events + "]";
}

}  // namespace

std::string place_json(const PlaceRecognition& p) {
  std::string out = "{\"loops_proposed\": " + std::to_string(p.loops_proposed) +
                    ", \"loops_accepted\": " + std::to_string(p.loops_accepted) +
                    ", \"relocalisations\": " + std::to_string(p.relocalisations) + ", " + refusals_json(p);
  if (p.labels) {
    const std::string labels = eval::to_json(*p.labels, p.label_options);  // "{...}": merged into this object
    out += ", " + labels.substr(1, labels.size() - 2);
  }
  return out + "}";
}

namespace {

std::string closed_loop_json(const ClosedLoopMetrics& c) {
  return "{\"path_error_rmse_m\": " + num(c.path_error_rmse_m) +
         ", \"path_error_max_m\": " + num(c.path_error_max_m) +
         ", \"hold_frames\": " + std::to_string(c.hold_frames) +
         ", \"frames\": " + std::to_string(c.t_s.size()) + "}";
}

}  // namespace

const char* to_string(RunStatus s) {
  switch (s) {
    case RunStatus::kCompleted:
      return "completed";
    case RunStatus::kInterrupted:
      return "interrupted";
    case RunStatus::kAborted:
      return "aborted";
    case RunStatus::kFailed:
      return "failed";
  }
  return "?";
}

int exit_code(RunStatus s) {
  switch (s) {
    case RunStatus::kCompleted:
      return 0;
    case RunStatus::kInterrupted:
      return 130;
    case RunStatus::kAborted:
      return 4;
    case RunStatus::kFailed:
      return 1;
  }
  return 1;
}

double distance_to_polyline(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& line) {
  if (line.empty()) return std::numeric_limits<double>::infinity();
  if (line.size() == 1) return (p - line.front()).norm();
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const Eigen::Vector2d a = line[i], ab = line[i + 1] - line[i];
    const double len2 = ab.squaredNorm();
    const double s = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, (p - (a + s * ab)).norm());
  }
  return best;
}

double realtime_factor(double sim_s, double wall_s) { return wall_s > 0 ? sim_s / wall_s : 0.0; }

namespace {

/// How metrics.json's comparison names a system: its setup under
/// --compare-sensors, else its mode ("pe-slam", "baseline").
std::string comparison_key(const RunReport& r, const SlamRun& run) {
  return compares_sensors(r) ? run.sensors : run.mode;
}

/// metrics.json's "comparison": the primary's reductions against the
/// reference (the baseline or the reference setup) and per system figures.
std::string comparison_json(const RunReport& r) {
  const SlamRun &p = r.primary, &b = *r.baseline;
  const bool both = p.eval && b.eval;
  const std::string kp = json_string(comparison_key(r, p)), kb = json_string(comparison_key(r, b));
  const auto pair = [&](const std::string& vp, const std::string& vb) {
    return "{" + kp + ": " + vp + ", " + kb + ": " + vb + "}";
  };
  return "{\"primary\": " + kp + ", \"reference\": " + kb + ", \"ate_rmse_reduction_pct\": " +
         (both ? num(eval::reduction_percent(b.eval->ate.rmse, p.eval->ate.rmse)) : "null") +
         ", \"rpe_trans_rmse_reduction_pct\": " +
         (both ? num(eval::reduction_percent(b.eval->rpe_trans_m.rmse, p.eval->rpe_trans_m.rmse)) : "null") +
         ", \"tracking_ms_median\": " +
         pair(num(percentile(tracking_times(p), 0.5)), num(percentile(tracking_times(b), 0.5))) +
         ", \"dead_reckoned_frames\": " +
         pair(std::to_string(p.dead_reckoned_frames), std::to_string(b.dead_reckoned_frames)) + "}";
}

}  // namespace

std::string metrics_json(const RunReport& r) {
  std::string out = "{\n  \"metrics_version\": " + std::to_string(eval::kMetricsVersion) + ",\n";
  out += run_fields(r, "  ");
  out += slam_fields(r.primary, "  ");
  if (r.closed_loop) out += ",\n  \"closed_loop\": " + closed_loop_json(*r.closed_loop);
  if (r.motion)
    out += ",\n  \"wheel_odometry\": {\"distance_m\": " + json_number(r.motion->distance_driven_m(), 9) +
           ", \"end_error_m\": " + json_number(r.motion->end_drift_m(), 9) +
           ", \"mean_abs_slip\": " + json_number(r.motion->mean_abs_slip, 9) + "}";
  if (r.baseline) {
    out += ",\n  \"baseline\": {\n" + run_fields(r, "    ") + slam_fields(*r.baseline, "    ") + "\n  }";
    out += ",\n  \"comparison\": " + comparison_json(r);
  }
  out += ",\n  \"profile\": {";
  const double frames = std::max<double>(1.0, static_cast<double>(r.primary.frames));
  for (std::size_t k = 0; k < r.profile.size(); ++k) {
    const StageTime& s = r.profile[k];
    out += (k ? ",\n    " : "\n    ") + json_string(s.name) + ": {\"total_ms\": " + num(s.total_ms) +
           ", \"per_frame_ms\": " + num(s.total_ms / frames) + ", \"count\": " + std::to_string(s.count) +
           ", \"thread\": " + json_string(s.thread) + "}";
  }
  out += r.profile.empty() ? "}" : "\n  }";
  out += "\n}\n";
  return out;
}

std::vector<double> tracking_times(const SlamRun& run) {
  std::vector<double> v;
  v.reserve(run.per_frame.size());
  for (const FrameRecord& r : run.per_frame) v.push_back(r.tracking_ms);
  return v;
}

std::string fixed(double v, int decimals) { return std::isfinite(v) ? format_fixed(v, decimals) : "-"; }

}  // namespace pvb::run
