#include "pvb/run/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

#include "pvb/common/text.hpp"
#include "pvb/eval/charts.hpp"
#include "pvb/eval/slam_mode.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/plot/png.hpp"
#include "report_inertial.hpp"

namespace pvb::run {
namespace {

/// JSON number: finite values with enough digits, null otherwise.
std::string num(double v) { return json_number(v, 10); }

std::vector<double> tracking_times(const SlamRun& run) {
  std::vector<double> v;
  v.reserve(run.per_frame.size());
  for (const FrameRecord& r : run.per_frame) v.push_back(r.tracking_ms);
  return v;
}

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

std::string place_json(const PlaceRecognition& p) {
  std::string out = "{\"loops_proposed\": " + std::to_string(p.loops_proposed) +
                    ", \"loops_accepted\": " + std::to_string(p.loops_accepted) +
                    ", \"relocalisations\": " + std::to_string(p.relocalisations);
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

std::string fixed(double v, int decimals) { return std::isfinite(v) ? format_fixed(v, decimals) : "-"; }

void write_figure(const eval::Figure& f, const std::string& dir, const std::string& name,
                  std::vector<std::string>* written) {
  write_file(dir + "/" + name + ".svg", eval::format_svg(f));
  plot::write_png(f, dir + "/" + name + ".png");
  written->push_back(name);
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

std::string comparison_table(const RunReport& r) {
  if (!r.baseline || !r.baseline->eval || !r.primary.eval) return {};
  eval::EvalResult base = *r.baseline->eval, pe = *r.primary.eval;
  // Short column names: the heading above the table names the baseline in
  // full; the sensor setups under --compare-sensors.
  const bool by_setup = compares_sensors(r);
  base.est_source = by_setup ? r.baseline->sensors : eval::kBaselineMode;
  pe.est_source = by_setup ? r.primary.sensors : eval::kPeSlamLabel;
  std::string out = eval::format_comparison({base, pe});
  // Tracking time and lost frames go above format_comparison's footnote.
  std::string footnote;
  const std::size_t note = out.rfind("\n(");
  if (note != std::string::npos) {
    footnote = out.substr(note + 1);
    out.erase(note + 1);
  }
  const std::vector<double> pe_ms = tracking_times(r.primary), base_ms = tracking_times(*r.baseline);
  char line[256];
  std::snprintf(line, sizeof line, "%-22s%24s%24s\n", "tracking ms median",
                fixed(percentile(base_ms, 0.5), 2).c_str(), fixed(percentile(pe_ms, 0.5), 2).c_str());
  out += line;
  std::snprintf(line, sizeof line, "%-22s%24s%24s\n", "tracking ms mean", fixed(mean_of(base_ms), 2).c_str(),
                fixed(mean_of(pe_ms), 2).c_str());
  out += line;
  std::snprintf(line, sizeof line, "%-22s%24zu%24zu\n", "lost frames", r.baseline->lost_frames,
                r.primary.lost_frames);
  out += line;
  std::snprintf(line, sizeof line, "%-22s%24zu%24zu\n", "dead-reckoned frames",
                r.baseline->dead_reckoned_frames, r.primary.dead_reckoned_frames);
  out += line;
  return out + footnote;
}

/// The IMU's yaw rate against the truth, the wheel odometry's path against
/// the base's, and the odometry's drift over the distance driven.
void write_motion_figures(const MotionSensorsReport& m, const std::string& dir, std::vector<std::string>* written) {
  if (!m.imu_t_s.empty())
    write_figure(eval::make_line_chart("IMU: the base's yaw rate, measured and true", "time [s]", "yaw rate [rad/s]",
                                       {{"gyroscope", m.imu_t_s, m.yaw_rate_measured, eval::series_color(0)},
                                        {"truth", m.imu_t_s, m.yaw_rate_true, eval::series_color(1)}}),
                 dir, "imu_yaw_rate", written);
  if (m.odo_t_s.empty()) return;
  write_figure(eval::make_line_chart("wheel odometry alone against the truth (odometry frame, top view)", "x [m]",
                                     "y [m]",
                                     {{"wheel odometry", m.odo_x_m, m.odo_y_m, eval::series_color(0)},
                                      {"truth", m.true_x_m, m.true_y_m, eval::series_color(1)}}),
               dir, "odometry_top", written);
  write_figure(eval::make_line_chart("wheel odometry drift over the distance driven", "distance driven [m]",
                                     "position error [m]", {{"drift", m.distance_m, m.drift_m, eval::series_color(0)}}),
               dir, "odometry_drift", written);
}

std::vector<std::string> write_figures(const RunReport& r, const std::string& dir) {
  std::vector<std::string> written;
  std::vector<const SlamRun*> runs{&r.primary};
  if (r.baseline) runs.push_back(&*r.baseline);
  // Trajectory with error (top view + ATE over time), one per run.
  for (const SlamRun* run : runs)
    if (run->eval)
      write_figure(eval::make_error_figure(*run->eval, r.scenario + ": " + system_label(r, *run)), dir,
                   run == &r.primary ? "trajectory_error" : "trajectory_error_" + run->mode, &written);
  // ATE over time, every run on one chart.
  {
    std::vector<eval::Series> series;
    for (const SlamRun* run : runs) {
      if (!run->eval) continue;
      eval::Series s{system_label(r, *run), {}, {}, eval::series_color(series.size())};
      for (std::size_t i = 0; i < run->eval->t_ns.size(); ++i) {
        s.x.push_back(geom::ns_to_seconds(run->eval->t_ns[i]));
        s.y.push_back(run->eval->ate_m[i]);
      }
      series.push_back(std::move(s));
    }
    if (!series.empty())
      write_figure(
          eval::make_line_chart("absolute trajectory error over time", "time [s]", "ATE [m]", series), dir,
          "ate_over_time", &written);
  }
  // Localisation in a loaded map: the error of every frame in the map's frame.
  if (r.primary.map && r.primary.map->localisation) {
    const eval::LocalisationScores& l = *r.primary.map->localisation;
    eval::Series t{"translation error [m]", {}, {}, eval::series_color(0)};
    for (std::size_t i = 0; i < l.translation_error_m.size(); ++i) {
      t.x.push_back(static_cast<double>(i));
      t.y.push_back(l.translation_error_m[i] >= 0 ? l.translation_error_m[i]
                                                   : std::numeric_limits<double>::quiet_NaN());
    }
    write_figure(eval::make_line_chart("localisation in the map's frame (no alignment; gaps: no pose)", "frame",
                                       "translation error [m]", {t}),
                 dir, "localisation_error", &written);
  }
  // Tracking time histogram, one per run.
  for (const SlamRun* run : runs) {
    const std::vector<double> ms = tracking_times(*run);
    write_figure(eval::make_histogram("tracking time per frame: " + system_label(r, *run),
                                      "tracking time [ms]", ms, 40),
                 dir, run == &r.primary ? "tracking_time_hist" : "tracking_time_hist_" + run->mode, &written);
  }
  // Coarse and kept motion-model matches per frame (gaps: other methods or lost).
  {
    std::vector<eval::Series> series;
    for (const SlamRun* run : runs) {
      const std::string label = system_label(r, *run);
      eval::Series coarse{label + " coarse", {}, {}, eval::series_color(series.size())};
      eval::Series kept{label + " kept", {}, {}, eval::series_color(series.size() + 1)};
      for (const FrameRecord& f : run->per_frame) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        coarse.x.push_back(f.frame);
        kept.x.push_back(f.frame);
        coarse.y.push_back(f.coarse_matches > 0 ? f.coarse_matches : nan);
        kept.y.push_back(f.coarse_matches > 0 ? f.matches_kept : nan);
      }
      series.push_back(std::move(coarse));
      if (run->mode == eval::kPeSlamMode)
        series.push_back(std::move(kept));  // the baseline keeps every coarse match
    }
    write_figure(eval::make_line_chart("motion-model matches per frame (coarse, and kept by PE-match)",
                                       "frame", "matches", series),
                 dir, "matches", &written);
  }
  if (r.closed_loop) {
    eval::Series s{"path error", r.closed_loop->t_s, r.closed_loop->path_error_m, eval::series_color(0)};
    write_figure(eval::make_line_chart("closed loop: ground-truth robot distance from the route", "time [s]",
                                       "path error [m]", {s}),
                 dir, "path_error", &written);
  }
  write_inertial_figures(r, dir, &written);
  if (r.motion) write_motion_figures(*r.motion, dir, &written);
  return written;
}

namespace {

/// One row of a two-column HTML table, escaped.
std::string table_row(const std::string& key, const std::string& value) {
  return "<tr><th>" + html_escape(key) + "</th><td>" + html_escape(value) + "</td></tr>\n";
}

/// The page's head, its title and the run's status.
std::string html_head(const RunReport& r) {
  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>pvbench run: " +
       html_escape(r.scenario) +
       "</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:1100px}"
       "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px;text-align:left}"
       "img{max-width:100%;border:1px solid #ddd}pre{background:#f6f6f6;padding:8px;overflow-x:auto}"
       ".bad{color:#b00}</style></head><body>\n";
  h += "<h1>pvbench run: " + html_escape(r.scenario) + "</h1>\n";
  const std::string status_class = r.status == RunStatus::kCompleted ? "" : " class=\"bad\"";
  h += "<p>Status: <b" + status_class + ">" + to_string(r.status) + "</b>";
  if (!r.status_detail.empty()) h += " (" + html_escape(r.status_detail) + ")";
  h += "</p>\n";
  return h;
}

/// Summary rows: what ran, and the primary system's map.
/// Place recognition: the detectors' counts and, with ground truth, the labels.
std::string place_rows(const PlaceRecognition& pr) {
  std::string h = table_row("loops proposed / accepted", std::to_string(pr.loops_proposed) + " / " +
                                                            std::to_string(pr.loops_accepted));
  if (!pr.labels) return h + table_row("relocalisations", std::to_string(pr.relocalisations));
  const eval::PlaceLabels& l = *pr.labels;
  h += table_row("loops true / false / missed",
                 std::to_string(l.loops_true) + " / " + std::to_string(l.loops_false) + " / " +
                     std::to_string(l.loops_missed) + " (" + std::to_string(l.revisits.size()) +
                     " true revisits; a match is true within " + fixed(pr.label_options.max_translation_m, 2) +
                     " m and " + fixed(pr.label_options.max_rotation_deg, 1) + " deg of ground truth)");
  h += table_row("relocalisations true / false",
                 std::to_string(l.relocalisations_true) + " / " + std::to_string(l.relocalisations_false));
  return h;
}

std::string run_rows(const RunReport& r) {
  const SlamRun& p = r.primary;
  std::string h;
  h += table_row("scenario file", r.scenario_file);
  h += table_row("seed", std::to_string(r.seed));
  h += table_row(
      "mode",
      eval::mode_label(p.mode) +
          (!r.baseline           ? std::string()
           : compares_sensors(r) ? " (compared with the same system fusing " + r.baseline->sensors + ")"
                                 : " (compared with the " + eval::mode_label(r.baseline->mode) + ")") +
          (r.closed_loop ? ", closed loop" : ", open loop") + (r.sync ? ", synchronous" : ", pipelined"));
  h += table_row("renderer", r.renderer);
  h += table_row("frames", std::to_string(p.frames) + " (" + fixed(r.sim_s, 2) + " s simulated)");
  h += table_row("lost frames", std::to_string(p.lost_frames));
  h +=
      table_row("keyframes / map points", std::to_string(p.keyframes) + " / " + std::to_string(p.map_points));
  if (p.local_mapping) {
    const slam::LocalMappingStats& lm = *p.local_mapping;
    h += table_row("local mapping",
                   std::to_string(lm.keyframes) + " keyframes processed, " + std::to_string(lm.local_ba) +
                       " local BAs (" + std::to_string(lm.local_ba_stopped) +
                       " stopped by a new keyframe), " + fixed(lm.busy_ms / 1000.0, 1) + " s busy");
  }
  if (!p.loop_closing_json.empty()) h += table_row("loops closed", std::to_string(p.loops_closed));
  if (p.place) h += place_rows(*p.place);
  return h;
}

/// Summary rows: the primary system's accuracy and speed, and the closed loop's path error.
std::string accuracy_rows(const RunReport& r) {
  const SlamRun& p = r.primary;
  std::string h;
  if (p.eval) {
    h += table_row("ATE rmse / mean / max [m]",
                   fixed(p.eval->ate.rmse, 4) + " / " + fixed(p.eval->ate.mean, 4) + " / " +
                       fixed(p.eval->ate.max, 4) + " (" + eval::alignment_name(p.eval->alignment_kind) +
                       " alignment, " + std::to_string(p.eval->ate.count) + " poses)");
    h += table_row("RPE trans rmse [m] / rot rmse [deg]",
                   fixed(p.eval->rpe_trans_m.rmse, 4) + " / " + fixed(p.eval->rpe_rot_deg.rmse, 3));
  } else {
    h += table_row("ATE", "not evaluated: " + p.eval_note);
  }
  if (p.refined_eval)
    h += table_row(
        "refined trajectory ATE rmse [m]",
        fixed(p.refined_eval->ate.rmse, 4) + " (every frame re-anchored on its keyframe's final pose)");
  const std::vector<double> ms = tracking_times(p);
  h += table_row(
      "tracking ms median / mean / p95",
      fixed(percentile(ms, 0.5), 2) + " / " + fixed(mean_of(ms), 2) + " / " + fixed(percentile(ms, 0.95), 2));
  h += inertial_summary_rows(p);
  h += table_row("realtime factor", fixed(realtime_factor(r.sim_s, r.wall_s), 2) + " (" + fixed(r.sim_s, 2) +
                                        " s simulated in " + fixed(r.wall_s, 2) + " s)");
  if (r.motion && r.motion->distance_driven_m() > 0)
    h += table_row("wheel odometry alone", fixed(r.motion->end_drift_m(), 3) + " m off after " +
                                               fixed(r.motion->distance_driven_m(), 2) + " m (" +
                                               fixed(100 * r.motion->end_drift_m() / r.motion->distance_driven_m(), 1) +
                                               " %); mean |slip| " + fixed(r.motion->mean_abs_slip, 3));
  if (r.closed_loop)
    h += table_row("path error rmse / max [m]", fixed(r.closed_loop->path_error_rmse_m, 4) + " / " +
                                                    fixed(r.closed_loop->path_error_max_m, 4) + " (held " +
                                                    std::to_string(r.closed_loop->hold_frames) + " frames)");
  return h;
}

/// Every loss of every system, with its reason and recovery.
std::string loss_section(const RunReport& r) {
  std::vector<const SlamRun*> runs{&r.primary};
  if (r.baseline) runs.push_back(&*r.baseline);
  std::string h = "<h2>Tracking loss</h2>\n";
  for (const SlamRun* run : runs) {
    if (run->loss_events.empty()) {
      h += "<p>" + html_escape(system_label(r, *run)) + ": tracking was never lost.</p>\n";
      continue;
    }
    h += "<p>" + html_escape(system_label(r, *run)) +
         ":</p>\n<table><tr><th>frame</th><th>t [s]</th><th>reason</th>"
         "<th>recovered at frame</th></tr>\n";
    for (const LossEvent& e : run->loss_events)
      h += "<tr><td>" + std::to_string(e.frame) + "</td><td>" + fixed(e.t_s, 3) + "</td><td>" +
           html_escape(e.reason) + "</td><td>" +
           (e.recovered_frame ? std::to_string(*e.recovered_frame) : std::string("never")) + "</td></tr>\n";
    h += "</table>\n";
  }
  return h;
}

/// The blind stretch of every system: the covered frames, their poses, and
/// the first frame after them.
std::string blind_section(const RunReport& r) {
  std::vector<const SlamRun*> runs;
  for (const SlamRun* run : {&r.primary, r.baseline ? &*r.baseline : nullptr})
    if (run && run->blind) runs.push_back(run);
  if (runs.empty()) return {};
  std::string h =
      "<h2>Blind stretch</h2>\n<table><tr><th></th><th>covered frames</th><th>with a pose</th>"
      "<th>first frame after</th><th>tracked (method)</th>"
      "<th>error across the stretch [m / deg]</th><th>error, ATE-aligned [m / deg]</th></tr>\n";
  const auto error_cell = [](const std::optional<PoseError>& e) {
    return e ? fixed(e->trans_m, 4) + " / " + fixed(e->rot_deg, 3) : std::string("-");
  };
  for (const SlamRun* run : runs) {
    const BlindStretch& b = *run->blind;
    const std::string tracked = !b.first_after          ? "-"
                                : b.first_after_tracked ? "yes (" + b.first_after_method + ")"
                                                        : "no (" + b.first_after_state + ")";
    h += "<tr><td>" + html_escape(eval::mode_label(run->mode)) + "</td><td>" +
         std::to_string(b.first_covered) + "-" + std::to_string(b.last_covered) + "</td><td>" +
         std::to_string(b.covered_with_pose) + " of " + std::to_string(b.covered_frames()) + "</td><td>" +
         (b.first_after ? std::to_string(*b.first_after) : std::string("not reached")) + "</td><td>" +
         html_escape(tracked) + "</td><td>" + error_cell(b.first_after_error) + "</td><td>" +
         error_cell(b.first_after_ate) + "</td></tr>\n";
  }
  return h + "</table>\n";
}

/// The figures (PNG linking to the SVG) and the contact sheet.
std::string figures_section(const std::vector<std::string>& figures) {
  std::string h = "<h2>Figures</h2>\n";
  for (const std::string& f : figures)
    h += "<p><a href=\"" + f + ".svg\"><img src=\"" + f + ".png\" alt=\"" + f + "\"></a><br>" + f +
         " (<a href=\"" + f + ".svg\">SVG</a>, <a href=\"" + f + ".png\">PNG</a>)</p>\n";
  h += "<h2>Frames</h2>\n<p><img src=\"contact_sheet.png\" alt=\"contact sheet\"></p>\n";
  return h;
}

/// One row of a map-scores table.
std::string map_scores_row(const std::string& name, const eval::MapScores& m) {
  auto pct = [](const std::vector<double>& v, std::size_t i) { return i < v.size() ? fixed(100 * v[i], 1) : "-"; };
  return "<tr><td>" + html_escape(name) + "</td><td>" + std::to_string(m.accuracy.count) + "</td><td>" +
         fixed(1000 * m.accuracy.median, 1) + " / " + fixed(1000 * m.accuracy.mean, 1) + " / " +
         fixed(1000 * m.accuracy.p95, 1) + "</td><td>" + pct(m.completeness_at, 1) + " / " +
         pct(m.completeness_at, 2) + "</td><td>" + (m.fscore_at.size() > 1 ? fixed(m.fscore_at[1], 3) : "-") +
         "</td><td>" + fixed(100 * m.ghosting, 2) + "</td></tr>\n";
}

const char* const kMapTableHead =
    "<table><tr><th></th><th>points</th><th>accuracy median / mean / p95 [mm]</th>"
    "<th>complete within 2 / 5 cm [%]</th><th>F at 2 cm</th><th>ghosting [%]</th></tr>\n";

/// One system's dense map: its versions, the corrected map per class, the figure.
std::string dense_map_part(const SlamRun& run) {
  const DenseMapReport& d = *run.dense_map;
  std::string h = "<h3>" + html_escape(eval::mode_label(run.mode)) + "</h3>\n<p>" + std::to_string(d.keyframes) +
                  " keyframes; corrected map " + std::to_string(d.points) + " points, live map " +
                  std::to_string(d.live_points) + "; " + std::to_string(d.pose_updates) + " pose updates re-binned " +
                  std::to_string(d.keyframes_moved) + " keyframes (median " + fixed(d.update_ms_median, 1) +
                  " ms, max " + fixed(d.update_ms_max, 1) + " ms)";
  for (double ms : d.loop_update_ms) h += "; a loop correction reached the map in " + fixed(ms, 1) + " ms";
  h += ".</p>\n";
  if (d.maps.empty()) return h + "<p>Not scored: " + html_escape(d.note) + "</p>\n";
  h += "<p>Against the true surface (" + std::to_string(d.surface_samples) + " samples; maps put into the world by " +
       (d.alignment == "first" ? std::string("the first frame's pose") : "the ATE's alignment") + "):</p>\n" +
       kMapTableHead;
  for (const MapResult& m : d.maps) h += map_scores_row(m.name, m.accuracy.all);
  h += "</table>\n";
  if (const MapResult* c = d.find("corrected")) {
    h += "<p>The corrected map per surface class:</p>\n" + std::string(kMapTableHead);
    for (const auto& [cls, scores] : c->accuracy.per_class)
      h += map_scores_row(sim::to_string(static_cast<sim::SurfaceClass>(cls)), scores);
    h += "</table>\n";
  }
  if (!d.top_view.empty())
    h += "<p><img src=\"" + html_escape(d.top_view) + "\" alt=\"map error, top view\"></p>\n";
  return h;
}

/// "Dense map": every system's maps and scores (nothing without dense mapping).
std::string dense_map_section(const RunReport& r) {
  std::string h;
  for (const SlamRun* run : {&r.primary, r.baseline ? &*r.baseline : nullptr})
    if (run && run->dense_map) h += dense_map_part(*run);
  return h.empty() ? h : "<h2>Dense map</h2>\n" + h;
}

/// "Where the time went": the profile (nothing when there is none).
std::string profile_section(const RunReport& r) {
  if (r.profile.empty()) return {};
  std::string h =
      "<h2>Where the time went</h2>\n<table><tr><th>stage</th><th>thread</th><th>total [ms]</th>"
      "<th>per frame [ms]</th></tr>\n";
  const double frames = std::max<double>(1.0, static_cast<double>(r.primary.frames));
  for (const StageTime& s : r.profile)
    h += "<tr><td>" + html_escape(s.name) + "</td><td>" + html_escape(s.thread) + "</td><td>" +
         fixed(s.total_ms, 1) + "</td><td>" + fixed(s.total_ms / frames, 2) + "</td></tr>\n";
  h += "</table>\n";
  return h;
}

/// Links to the report's files, then the log; closes the page.
std::string files_and_log(const RunReport& r) {
  std::string h = "<h2>Files</h2>\n<ul>\n";
  for (const char* f : {"metrics.json", "groundtruth.txt", "CameraTrajectory.txt", "KeyFrameTrajectory.txt",
                        "timing.csv", "camera.yaml", "run.log"})
    h += std::string("<li><a href=\"") + f + "\">" + f + "</a></li>\n";
  if (r.primary.dense_map) {
    std::vector<std::string> maps = r.primary.dense_map->files;
    if (!r.primary.dense_map->maps.empty()) maps.push_back("map_errors.ply");
    for (const std::string& f : maps) h += "<li><a href=\"" + f + "\">" + f + "</a></li>\n";
  }
  if (r.baseline)
    for (const char* f :
         {"baseline/CameraTrajectory.txt", "baseline/KeyFrameTrajectory.txt", "baseline/timing.csv"})
      h += std::string("<li><a href=\"") + f + "\">" + f + "</a></li>\n";
  h += "</ul>\n<h2>Log</h2>\n<pre>";
  for (const std::string& l : r.log_lines) h += html_escape(l) + "\n";
  h += "</pre>\n</body></html>\n";
  return h;
}

}  // namespace

std::string index_html(const RunReport& r, const std::vector<std::string>& figures) {
  std::string h = html_head(r);
  h += "<table>\n" + run_rows(r) + accuracy_rows(r) + "</table>\n";
  h += loss_section(r);
  h += blind_section(r);
  const std::string table = comparison_table(r);
  if (!table.empty())
    h += "<h2>" + html_escape(comparison_heading(r)) + "</h2>\n<pre>" + html_escape(table) + "</pre>\n";
  h += inertial_section(r);
  h += figures_section(figures);
  h += dense_map_section(r);
  h += profile_section(r);
  h += files_and_log(r);
  return h;
}

std::vector<std::string> write_report(const RunReport& r, const std::string& dir) {
  write_file(dir + "/metrics.json", metrics_json(r));
  const std::vector<std::string> figures = write_figures(r, dir);
  std::vector<plot::Thumbnail> thumbs = r.thumbnails;
  if (thumbs.empty()) thumbs.push_back({cv::Mat(240, 320, CV_8UC3, cv::Scalar(255, 255, 255)), "no frames"});
  plot::write_rgb_png(plot::make_contact_sheet(thumbs, 4, 320), dir + "/contact_sheet.png");
  write_file(dir + "/index.html", index_html(r, figures));
  return figures;
}

}  // namespace pvb::run
