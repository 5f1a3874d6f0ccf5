#include "report_inertial.hpp"

#include <cmath>

#include "pvb/common/text.hpp"
#include "pvb/eval/charts.hpp"
#include "pvb/eval/slam_mode.hpp"
#include "pvb/plot/dashes.hpp"
#include "pvb/plot/png.hpp"

namespace pvb::run {
namespace {

std::string fixed_or_dash(double v, int decimals) {
  return std::isfinite(v) ? format_fixed(v, decimals) : "-";
}

std::vector<const SlamRun*> report_systems(const RunReport& r) {
  std::vector<const SlamRun*> runs{&r.primary};
  if (r.baseline) runs.push_back(&*r.baseline);
  return runs;
}

std::string summary_row(const std::string& key, const std::string& value) {
  return "<tr><th>" + html_escape(key) + "</th><td>" + html_escape(value) + "</td></tr>\n";
}

std::string td_cell(const std::string& v) { return "<td>" + html_escape(v) + "</td>"; }

std::string trusted_text(const InertialReport& in) {
  if (!in.trusted) return "not trusted by the end";
  return "trusted at t = " + fixed_or_dash(in.trusted_t_s, 2) + " s (keyframe " +
         std::to_string(in.trusted_keyframe) + "), gravity " + fixed_or_dash(in.gravity_tilt_deg, 2) +
         " deg off the map's -z" +
         (in.gravity_true_deg ? ", " + fixed_or_dash(*in.gravity_true_deg, 2) + " deg off the true down"
                              : "") +
         ", whitened RMS " + fixed_or_dash(in.init_rms, 2);
}

std::string bias_text(const BiasComparison& b) {
  return (b.has_gyro ? fixed_or_dash(b.gyro_rms_radps, 5) : std::string("-")) + " rad/s / " +
         fixed_or_dash(b.accel_rms_mps2, 4) + " m/s^2 over " + std::to_string(b.t_s.size()) + " keyframes";
}

void write_inertial_figure(const eval::Figure& f, const std::string& dir, const std::string& name,
                           std::vector<std::string>* written) {
  write_file(dir + "/" + name + ".svg", eval::format_svg(f));
  plot::write_png(f, dir + "/" + name + ".png");
  written->push_back(name);
}

/// A darker shade of `c`: the true values' colour beside the estimate's.
eval::Rgb darker_shade(eval::Rgb c) {
  const auto d = [](unsigned char v) { return static_cast<unsigned char>(v * 0.55); };
  return {d(c.r), d(c.g), d(c.b)};
}

/// Per axis: the estimate dashed in the axis colour, the truth solid in a darker shade.
eval::Figure bias_chart(const std::string& title, const std::string& y_label, const std::vector<double>& t_s,
                        const Axes& est, const Axes& truth) {
  static const char* kAxis[] = {"x", "y", "z"};
  std::vector<eval::Series> series;
  for (int k = 0; k < 3; ++k) {
    series.push_back({std::string(kAxis[k]) + " true", t_s, truth[k], darker_shade(eval::series_color(k))});
    series.push_back({std::string(kAxis[k]) + " estimated", t_s, est[k], eval::series_color(k)});
  }
  eval::Figure f = eval::make_line_chart(title, "keyframe time [s]", y_label, series);
  for (int k = 0; k < 3; ++k) plot::dash_polylines(&f, eval::series_color(k));
  return f;
}

void write_bias_figures(const RunReport& r, const SlamRun& run, const std::string& suffix,
                        const std::string& dir, std::vector<std::string>* written) {
  const BiasComparison& b = *run.inertial->biases;
  const std::string who = system_label(r, run) + ": ";
  if (b.has_gyro)
    write_inertial_figure(bias_chart(who + "gyroscope bias per keyframe, estimated (dashed) and true",
                                     "gyro bias [rad/s]", b.t_s, b.gyro_est_radps, b.gyro_true_radps),
                          dir, "imu_gyro_bias" + suffix, written);
  write_inertial_figure(bias_chart(who + "accelerometer bias per keyframe, estimated (dashed) and true",
                                   "accel bias [m/s^2]", b.t_s, b.accel_est_mps2, b.accel_true_mps2),
                        dir, "imu_accel_bias" + suffix, written);
}

}  // namespace

bool compares_sensors(const RunReport& r) {
  return r.baseline && r.baseline->mode == r.primary.mode && r.baseline->sensors != r.primary.sensors;
}

std::string system_label(const RunReport& r, const SlamRun& run) {
  return compares_sensors(r) ? run.sensors : eval::mode_label(run.mode);
}

std::string comparison_heading(const RunReport& r) {
  if (!r.baseline) return system_label(r, r.primary);
  return system_label(r, r.primary) + " against " + (compares_sensors(r) ? "" : "the ") +
         system_label(r, *r.baseline);
}

std::string gravity_inertial_fields(const SlamRun& run, const std::string& in) {
  std::string out = in + "\"dead_reckoned_frames\": " + std::to_string(run.dead_reckoned_frames) + ",\n";
  if (run.gravity) out += in + "\"gravity\": " + eval::gravity_json(*run.gravity) + ",\n";
  if (run.tilt) out += in + "\"tilt\": " + eval::tilt_json(*run.tilt) + ",\n";
  if (run.inertial) out += in + "\"inertial\": " + inertial_json(*run.inertial) + ",\n";
  return out;
}

std::string inertial_summary_rows(const SlamRun& p) {
  std::string h = summary_row("sensors fused", p.sensors);
  h += summary_row("dead-reckoned frames", std::to_string(p.dead_reckoned_frames));
  if (p.gravity && !p.gravity->angle_deg.empty())
    h += summary_row("gravity error median / p95 / final [deg]",
                     fixed_or_dash(p.gravity->median_deg, 2) + " / " + fixed_or_dash(p.gravity->p95_deg, 2) +
                         " / " + fixed_or_dash(p.gravity->final_deg, 2) +
                         " (map frame: " + p.gravity->map_frame + ")");
  if (p.tilt && !p.tilt->pitch_deg.empty())
    h += summary_row("keyframe pitch / roll error slope [deg/keyframe]",
                     format_fixed(p.tilt->pitch_slope_deg_per_kf, 4) + " / " +
                         format_fixed(p.tilt->roll_slope_deg_per_kf, 4) + " (mean " +
                         fixed_or_dash(p.tilt->pitch_mean_deg, 3) + " / " +
                         fixed_or_dash(p.tilt->roll_mean_deg, 3) + " deg over " +
                         std::to_string(p.tilt->pitch_deg.size()) + " keyframes)");
  if (p.inertial) {
    h += summary_row("inertial state", trusted_text(*p.inertial));
    if (p.inertial->biases) h += summary_row("bias error RMS gyro / accel", bias_text(*p.inertial->biases));
  }
  return h;
}

std::string inertial_section(const RunReport& r) {
  bool any = false;
  for (const SlamRun* run : report_systems(r)) any = any || run->gravity || run->inertial;
  if (!any) return {};
  std::string h =
      "<h2>Gravity and inertial state</h2>\n<table><tr><th></th><th>sensors</th><th>dead-reckoned frames</th>"
      "<th>gravity error median / p95 / final [deg]</th><th>pitch / roll slope [deg/keyframe]</th>"
      "<th>inertial state</th><th>bias error RMS gyro / accel</th></tr>\n";
  for (const SlamRun* run : report_systems(r)) {
    h += "<tr>" + td_cell(system_label(r, *run)) + td_cell(run->sensors) +
         td_cell(std::to_string(run->dead_reckoned_frames));
    h += td_cell(run->gravity
                     ? fixed_or_dash(run->gravity->median_deg, 2) + " / " +
                           fixed_or_dash(run->gravity->p95_deg, 2) + " / " +
                           fixed_or_dash(run->gravity->final_deg, 2) + " (" + run->gravity->map_frame + ")"
                     : "-");
    h += td_cell(run->tilt ? format_fixed(run->tilt->pitch_slope_deg_per_kf, 4) + " / " +
                                 format_fixed(run->tilt->roll_slope_deg_per_kf, 4)
                           : "-");
    h += td_cell(run->inertial ? trusted_text(*run->inertial) : "camera alone");
    h +=
        td_cell(run->inertial && run->inertial->biases ? bias_text(*run->inertial->biases) : "-") + "</tr>\n";
  }
  return h + "</table>\n";
}

void write_inertial_figures(const RunReport& r, const std::string& dir, std::vector<std::string>* written) {
  std::vector<eval::Series> gravity, tilt;
  for (const SlamRun* run : report_systems(r)) {
    const std::string label = system_label(r, *run);
    if (run->gravity && !run->gravity->angle_deg.empty())
      gravity.push_back({label + " (" + run->gravity->map_frame + ")", run->gravity->t_s,
                         run->gravity->angle_deg, eval::series_color(gravity.size())});
    if (run->tilt && !run->tilt->pitch_deg.empty()) {
      tilt.push_back(
          {label + " pitch", run->tilt->t_s, run->tilt->pitch_deg, eval::series_color(tilt.size())});
      tilt.push_back({label + " roll", run->tilt->t_s, run->tilt->roll_deg, eval::series_color(tilt.size())});
    }
  }
  if (!gravity.empty())
    write_inertial_figure(
        eval::make_line_chart("gravity error: estimated against true down, in the camera frame", "time [s]",
                              "gravity error [deg]", gravity),
        dir, "gravity_error", written);
  if (!tilt.empty())
    write_inertial_figure(eval::make_line_chart("keyframe pitch and roll error (after the ATE alignment)",
                                                "keyframe time [s]", "error [deg]", tilt),
                          dir, "tilt_error", written);
  for (const SlamRun* run : report_systems(r))
    if (run->inertial && run->inertial->biases && !run->inertial->biases->t_s.empty())
      write_bias_figures(r, *run, run == &r.primary ? "" : "_baseline", dir, written);
}

}  // namespace pvb::run
