// index.html (a RunReport's page: summary, loss events, comparison,
// figures, dense map, profile, files and log) and the comparison table.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "pvb/common/text.hpp"
#include "pvb/eval/slam_mode.hpp"
#include "pvb/report/report.hpp"
#include "pvb/sim/truth_surface.hpp"
#include "report_inertial.hpp"
#include "report_parts.hpp"

namespace pvb::run {

using eval::mean_of;

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

}  // namespace pvb::run
