// pvbench sheet: one frame of each of several scenarios side by side, each
// labelled with its name, its local time and sun, and its trackers' angle,
// so a person sees at a glance how a station changes from hour to hour or
// day to day (docs/scenarios.md).
//
//   pvbench sheet --scenario scenes/days/tracker_station_0800.yaml --scenario ... --frame 150 --out sheet.png
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "command.hpp"
#include "count_option.hpp"
#include "io_plan.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/plot/contact_sheet.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/sim_frame_source.hpp"

namespace pvb::cli {
namespace {

struct SheetArgs {
  std::vector<std::string> scenarios;
  std::string frame = "0";
  std::string out;
  std::string gl = "auto";
  int columns = 3;
};

/// "tracker_station_0800: sun 69/12, trackers +26" (the sun's azimuth from
/// north and elevation, the trackers' angle, in degrees).
std::string label_of(const scenes::Scenario& s) {
  std::string label = s.name + format_number(": sun %.0f", s.sun.solar_azimuth_deg) +
                      format_number("/%.0f", s.sun.elevation_deg);
  for (const scenes::PvArray& a : s.pv_arrays)
    if (a.mount == scenes::Mount::kSingleAxis) {
      label += format_number(", trackers %+.0f", a.rotation_deg);
      break;
    }
  return label;
}

/// Frame `frame` of the scenario (the physics advances without rendering up to it).
cv::Mat render_frame(const scenes::Scenario& s, sim::GlBackend backend, int frame) {
  const int n = scenes::frame_count(s);
  if (frame >= n)
    throw ConfigError(s.source_file, "--frame", "a frame below the scenario's " + std::to_string(n),
                      std::to_string(frame));
  sim::SimFrameSource source(s, backend, frame + 1);
  for (int i = 0; i < frame; ++i)
    if (!source.skip()) throw IoError(s.source_file, "the simulation ended before frame " + std::to_string(frame));
  const std::optional<sensor::RgbdFrame> f = source.next();
  if (!f) throw IoError(s.source_file, "no frame " + std::to_string(frame));
  return f->rgb.clone();
}

int run_sheet(const SheetArgs& a) {
  if (a.scenarios.empty()) throw ConfigError("command line", "--scenario", "at least one scenario file");
  const int frame = static_cast<int>(parse_count("sheet", "--frame", a.frame, 0, 10'000'000));
  const sim::GlBackend backend = sim::parse_gl_backend(a.gl);
  std::vector<scenes::Scenario> scenarios;
  for (const std::string& file : a.scenarios) scenarios.push_back(scenes::load_scenario(file));  // all, before any work
  IoPlan plan;
  for (const scenes::Scenario& s : scenarios) add_scenario_inputs(&plan, "--scenario", s);
  plan.output_file("--out", a.out).check();
  std::vector<plot::Thumbnail> thumbs;
  for (const scenes::Scenario& s : scenarios) {
    thumbs.push_back({render_frame(s, backend, frame), label_of(s)});
    std::printf("%s: frame %d\n", thumbs.back().label.c_str(), frame);
  }
  plot::write_rgb_png(plot::make_contact_sheet(thumbs, a.columns, 400), a.out);
  std::printf("wrote %s\n", a.out.c_str());
  return 0;
}

}  // namespace

Command add_sheet_command(CLI::App& app) {
  auto a = std::make_shared<SheetArgs>();
  CLI::App* sub = app.add_subcommand("sheet", "one frame of each of several scenarios side by side, labelled");
  sub->add_option("--scenario", a->scenarios, "a scenario file (repeat: one tile each)")
      ->required()
      ->check(path_check("sheet", "--scenario"));
  sub->add_option("--frame", a->frame, "the frame to show of each")->capture_default_str();
  sub->add_option("--out", a->out, "the sheet (PNG)")->required()->check(path_check("sheet", "--out"));
  sub->add_option("--columns", a->columns, "tiles per row")->capture_default_str()->check(CLI::Range(1, 12));
  sub->add_option("--gl", a->gl, "rendering backend")->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  return {sub, [a] { return run_sheet(*a); }};
}

}  // namespace pvb::cli
