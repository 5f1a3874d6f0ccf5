// The figures of a run's report (SVG and PNG) and the report folder as a
// whole: metrics.json, the figures, contact_sheet.png and index.html.
#include <limits>
#include <string>
#include <vector>

#include "pvb/common/text.hpp"
#include "pvb/eval/charts.hpp"
#include "pvb/eval/slam_mode.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/plot/png.hpp"
#include "pvb/report/report.hpp"
#include "report_inertial.hpp"
#include "report_parts.hpp"

namespace pvb::run {

void write_figure(const eval::Figure& f, const std::string& dir, const std::string& name,
                  std::vector<std::string>* written) {
  write_file(dir + "/" + name + ".svg", eval::format_svg(f));
  plot::write_png(f, dir + "/" + name + ".png");
  written->push_back(name);
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

/// Memory and each stage's time against the map's keyframes, from the
/// run's cost samples.
void write_cost_figures(const SlamRun& run, const std::string& dir, std::vector<std::string>* written) {
  if (run.costs.size() < 2) return;
  std::vector<double> kf;
  std::vector<double> rss, sparse, dense, disk, sparse_disk, track, loop, mapping, ba;
  for (const CostSample& c : run.costs) {
    kf.push_back(static_cast<double>(c.keyframes));
    rss.push_back(c.rss_mb);
    sparse.push_back(c.sparse_mb);
    dense.push_back(c.dense_mb);
    disk.push_back(c.dense_disk_mb);
    sparse_disk.push_back(c.sparse_disk_mb);
    track.push_back(c.tracking_ms_median);
    loop.push_back(c.loop_detect_ms);
    mapping.push_back(c.mapping_ms_per_keyframe);
    ba.push_back(c.local_ba_ms);
  }
  write_figure(eval::make_line_chart("memory as the map grows", "keyframes in the map", "memory [MB]",
                                     {{"process (RSS)", kf, rss, eval::series_color(0)},
                                      {"sparse map", kf, sparse, eval::series_color(1)},
                                      {"dense map", kf, dense, eval::series_color(2)},
                                      {"dense map spilled to disk", kf, disk, eval::series_color(3)},
                                      {"keyframe features on disk", kf, sparse_disk, eval::series_color(4)}}),
               dir, "cost_memory", written);
  write_figure(eval::make_line_chart("time as the map grows (each over the frames since the sample before)",
                                     "keyframes in the map", "time [ms]",
                                     {{"tracking, median per frame", kf, track, eval::series_color(0)},
                                      {"loop detection, mean per keyframe", kf, loop, eval::series_color(1)},
                                      {"local mapping, per keyframe", kf, mapping, eval::series_color(2)},
                                      {"local BA, per adjustment", kf, ba, eval::series_color(3)}}),
               dir, "cost_time", written);
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
  write_cost_figures(r.primary, dir, &written);
  return written;
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
