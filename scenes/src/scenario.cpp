#include "pvb/scenes/scenario.hpp"

#include <cmath>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "scenario_document.hpp"
#include "scenario_sections.hpp"

namespace pvb::scenes {
namespace {

/// The top level: who and when, then the station, then the day.
void read_top(detail::MapReader& top, Scenario& s) {
  s.name = top.string("name", s.name);
  s.description = top.string("description", s.description);
  s.seed = top.seed("seed", s.seed);
  if (top.has("station_seed")) s.station_seed = top.seed("station_seed", 0);
  s.duration_s = top.number("duration_s", s.duration_s, 0.1, detail::kMaxScenarioTime_s);
  detail::with_map(top, "ground", [&](detail::MapReader& r) { detail::read_ground(r, s.ground); });
  detail::read_arrays(top, s.pv_arrays);
  detail::read_walls(top, s.walls);
  detail::read_plant(top, s);
  detail::with_map(top, "vegetation", [&](detail::MapReader& r) { detail::read_vegetation(r, s.vegetation); });
  detail::with_map(top, "light", [&](detail::MapReader& r) { detail::read_light(r, s.light); });
  detail::read_site(top, s);
  detail::with_map(top, "route", [&](detail::MapReader& r) { detail::read_route(r, s.route); });
  detail::with_map(top, "robot", [&](detail::MapReader& r) { detail::read_robot(r, s.robot); });
  detail::with_map(top, "camera", [&](detail::MapReader& r) { detail::read_camera(r, s.camera); });
  detail::read_body(top, s);
  detail::with_map(top, "slam", [&](detail::MapReader& r) { detail::read_slam(r, s.slam); });
  detail::read_kidnap(top, s);
  detail::read_cover(top, s);
  detail::with_map(top, "expect", [&](detail::MapReader& r) { detail::read_expect(r, s.expect); });
}

Scenario read_scenario(const detail::ScenarioDocument& doc) {
  Scenario s;
  s.source_file = doc.file;
  s.base_files = doc.bases;
  const detail::ReadContext ctx{doc.file, &doc.origins};
  detail::MapReader top(doc.root, ctx, "");
  read_top(top, s);
  top.finish();
  detail::refuse_station_keys(doc);  // after the reader named any unknown key as one
  detail::check_scene_size(s, ctx);
  detail::check_plant_pattern(s, ctx);
  detail::check_route(s, ctx);
  detail::check_plant_route(s, ctx);
  detail::check_blind_bounds(s, ctx);
  detail::check_ground_relief(s, ctx);
  detail::resolve_day(s, ctx);
  return s;
}

}  // namespace

double Camera::fovy_deg() const { return 2.0 * std::atan(0.5 * height / fy) * 180.0 / M_PI; }

double ActiveStereo::ir_fovy_deg() const { return 2.0 * std::atan(0.5 * ir_height / ir_fx) * 180.0 / M_PI; }

double PvArray::panel_width_m() const {
  // Typical module sizes: 60 cells 1.65 x 0.99 m, 72 cells 1.96 x 0.99 m,
  // 144 half-cut cells 2.27 x 1.13 m (long side x short side).
  const double long_m = cells == 60 ? 1.65 : cells == 72 ? 1.96 : 2.27;
  const double short_m = cells == 144 ? 1.13 : 0.99;
  return orientation == PanelOrientation::kPortrait ? short_m : long_m;
}
double PvArray::panel_height_m() const {
  const double long_m = cells == 60 ? 1.65 : cells == 72 ? 1.96 : 2.27;
  const double short_m = cells == 144 ? 1.13 : 0.99;
  return orientation == PanelOrientation::kPortrait ? long_m : short_m;
}
constexpr double kPanelGapM = 0.02;
double PvArray::table_length_m() const {
  return panels_per_table * (panel_width_m() + kPanelGapM) - kPanelGapM;
}
double PvArray::table_depth_m() const { return panel_lines * (panel_height_m() + kPanelGapM) - kPanelGapM; }

double PvArray::axis_height_m() const {
  // The lowest edge, half the table's depth down the slope from the axis
  // and kTrackerPanelAboveAxisM out along the normal, at the largest angle.
  const double max_rad = tracker.max_angle_deg * M_PI / 180.0;
  return clearance_m + 0.5 * table_depth_m() * std::sin(max_rad) - kTrackerPanelAboveAxisM * std::cos(max_rad);
}

Scenario parse_scenario(const std::string& yaml_text, const std::string& origin) {
  return read_scenario(detail::parse_document(yaml_text, origin));
}

Scenario load_scenario(const std::string& path) { return read_scenario(detail::load_document(path)); }

int frame_count(const Scenario& s, int max_frames) {
  const int n = static_cast<int>(std::floor(s.duration_s * s.camera.fps + 1e-9)) + 1;
  return max_frames > 0 ? std::min(n, max_frames) : n;
}

CoverFrames cover_frames(const Cover& c, double fps) {
  // Frame i is at i / fps; the small tolerance keeps a time that is a whole
  // number of frames (40 s at 30 fps) on that frame.
  const auto at_or_after = [fps](double t_s) { return static_cast<int>(std::ceil(t_s * fps - 1e-6)); };
  return {at_or_after(c.at_s), at_or_after(c.at_s + c.covered_s)};
}

KidnapFrames kidnap_frames(const Kidnap& k, double fps) {
  const CoverFrames c = cover_frames(Cover{k.at_s, k.covered_s}, fps);
  KidnapFrames f;
  f.cover_begin = c.begin;
  f.cover_end = c.end;
  f.teleport = f.cover_begin + (f.cover_end - f.cover_begin) / 2;
  f.target = static_cast<int>(std::floor(k.to_route_s * fps + 1e-6));
  return f;
}

std::optional<CoverFrames> camera_cover_frames(const Scenario& s) {
  if (s.cover) return cover_frames(*s.cover, s.camera.fps);
  if (s.kidnap) return cover_frames(Cover{s.kidnap->at_s, s.kidnap->covered_s}, s.camera.fps);
  return std::nullopt;
}

const char* to_string(RoutePattern p) {
  switch (p) {
    case RoutePattern::kWaypoints:
      return "waypoints";
    case RoutePattern::kAlongRow:
      return "along_row";
    case RoutePattern::kLawnmower:
      return "lawnmower";
    case RoutePattern::kLoop:
      return "loop";
    case RoutePattern::kRoads:
      return "roads";
  }
  return "?";
}

}  // namespace pvb::scenes
