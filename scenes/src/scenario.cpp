#include "pvb/scenes/scenario.hpp"

#include <sys/stat.h>
#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/route.hpp"

namespace pvb::scenes {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Strict reader over one YAML map: every key read is recorded, and finish()
// rejects any key that was not read.  Errors name file:line and the full key.
class MapReader {
 public:
  MapReader(const YAML::Node& node, std::string origin, std::string path)
      : node_(node), origin_(std::move(origin)), path_(std::move(path)) {
    if (!node_.IsMap()) fail(path_.empty() ? "(top level)" : path_, node_, "a mapping of keys");
  }

  bool has(const std::string& key) const { return node_[key].IsDefined() && !node_[key].IsNull(); }

  double number(const std::string& key, double def, double lo, double hi) {
    const YAML::Node n = take(key);
    if (!n) return def;
    double v = 0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
      fail(full(key), n, "a number", scalar_text(n));
    check_range(key, n, v, lo, hi);
    return v;
  }

  int integer(const std::string& key, int def, int lo, int hi) {
    const YAML::Node n = take(key);
    if (!n) return def;
    long long v = 0;
    if (!n.IsScalar() || !YAML::convert<long long>::decode(n, v))
      fail(full(key), n, "an integer", scalar_text(n));
    check_range(key, n, static_cast<double>(v), lo, hi);
    return static_cast<int>(v);
  }

  std::uint64_t seed(const std::string& key, std::uint64_t def) {
    const YAML::Node n = take(key);
    if (!n) return def;
    unsigned long long v = 0;
    if (!n.IsScalar() || n.Scalar().empty() || n.Scalar()[0] == '-' ||
        !YAML::convert<unsigned long long>::decode(n, v))
      fail(full(key), n, "a non-negative integer", scalar_text(n));
    return v;
  }

  bool boolean(const std::string& key, bool def) {
    const YAML::Node n = take(key);
    if (!n) return def;
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
      fail(full(key), n, "true or false", scalar_text(n));
    return v;
  }

  std::string string(const std::string& key, const std::string& def) {
    const YAML::Node n = take(key);
    if (!n) return def;
    if (!n.IsScalar()) fail(full(key), n, "a string");
    return n.Scalar();
  }

  template <typename Enum>
  Enum choice(const std::string& key, Enum def, const std::vector<std::pair<std::string, Enum>>& options) {
    const YAML::Node n = take(key);
    if (!n) return def;
    std::string names;
    for (const auto& o : options) names += (names.empty() ? "" : ", ") + o.first;
    if (!n.IsScalar()) fail(full(key), n, "one of " + names);
    for (const auto& o : options)
      if (o.first == n.Scalar()) return o.second;
    fail(full(key), n, "one of " + names, n.Scalar());
  }

  /// A list of `size` numbers each in [lo, hi].
  std::vector<double> numbers(const std::string& key, std::size_t size, double lo, double hi) {
    const YAML::Node n = take(key);
    if (!n) return {};
    const std::string what = "a list of " + std::to_string(size) + " numbers";
    if (!n.IsSequence() || n.size() != size) fail(full(key), n, what);
    std::vector<double> out;
    for (std::size_t i = 0; i < size; ++i) {
      double v = 0;
      if (!n[i].IsScalar() || !YAML::convert<double>::decode(n[i], v) || !std::isfinite(v))
        fail(full(key) + "[" + std::to_string(i) + "]", n[i], "a number", scalar_text(n[i]));
      check_range(key + "[" + std::to_string(i) + "]", n[i], v, lo, hi);
      out.push_back(v);
    }
    return out;
  }

  Eigen::Vector2d vec2(const std::string& key, const Eigen::Vector2d& def, double lo, double hi) {
    const auto v = numbers(key, 2, lo, hi);
    return v.empty() ? def : Eigen::Vector2d(v[0], v[1]);
  }

  /// A (min, max) pair with min <= max.
  Eigen::Vector2d range(const std::string& key, const Eigen::Vector2d& def, double lo, double hi) {
    const YAML::Node n = node_[key];
    const Eigen::Vector2d v = vec2(key, def, lo, hi);
    if (v.x() > v.y()) fail(full(key), n, "[min, max] with min <= max");
    return v;
  }

  /// Sub-map reader (empty node -> absent).
  YAML::Node child(const std::string& key) { return take(key); }
  std::string full(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const std::string& origin() const { return origin_; }

  /// Rejects keys that were never read.
  void finish() const {
    for (const auto& kv : node_) {
      if (!kv.first.IsScalar()) fail(full("?"), kv.first, "a key name", "a list or a map as a key");
      const std::string key = kv.first.as<std::string>();
      if (read_.count(key) == 0) {
        std::string known;
        for (const auto& k : read_) known += (known.empty() ? "" : ", ") + k;
        fail(full(key), kv.first, "a known key (" + known + ")", "unknown key");
      }
    }
  }

  [[noreturn]] void fail(const std::string& key, const YAML::Node& at, const std::string& expected,
                         const std::string& got = {}) const {
    const YAML::Mark m = at.Mark();
    const std::string where = m.line >= 0 ? origin_ + ":" + std::to_string(m.line + 1) : origin_;
    throw ConfigError(where, key, expected, got);
  }

 private:
  YAML::Node take(const std::string& key) {
    read_.insert(key);
    const YAML::Node n = node_[key];
    if (!n.IsDefined() || n.IsNull()) return YAML::Node(YAML::NodeType::Undefined);
    return n;
  }
  static std::string scalar_text(const YAML::Node& n) { return n.IsScalar() ? n.Scalar() : "a non-scalar"; }
  void check_range(const std::string& key, const YAML::Node& n, double v, double lo, double hi) const {
    if (v < lo || v > hi) {
      std::ostringstream ss;
      if (hi == kInf)
        ss << "a value >= " << lo;
      else if (lo == -kInf)
        ss << "a value <= " << hi;
      else
        ss << "a value in [" << lo << ", " << hi << "]";
      fail(full(key), n, ss.str(), n.IsScalar() ? n.Scalar() : std::string());
    }
  }

  const YAML::Node node_;  // a handle; const so operator[] never inserts keys
  std::string origin_;
  std::string path_;
  std::set<std::string> read_;
};

// Runs `fn` on the map under `key` of `parent` if present.
void with_map(MapReader& parent, const std::string& key, const std::function<void(MapReader&)>& fn) {
  const YAML::Node n = parent.child(key);
  if (!n) return;
  MapReader r(n, parent.origin(), parent.full(key));
  fn(r);
  r.finish();
}

PvArray read_array(MapReader& r) {
  PvArray a;
  a.origin_m = r.vec2("origin_m", a.origin_m, -1e4, 1e4);
  a.azimuth_deg = r.number("azimuth_deg", a.azimuth_deg, -360, 360);
  a.rows = r.integer("rows", a.rows, 1, 50);
  a.tables_per_row = r.integer("tables_per_row", a.tables_per_row, 1, 50);
  a.panels_per_table = r.integer("panels_per_table", a.panels_per_table, 1, 60);
  a.panel_lines = r.integer("panel_lines", a.panel_lines, 1, 4);
  a.orientation = r.choice<PanelOrientation>(
      "orientation", a.orientation,
      {{"portrait", PanelOrientation::kPortrait}, {"landscape", PanelOrientation::kLandscape}});
  a.cells = r.integer("cells", a.cells, 60, 144);
  if (a.cells != 60 && a.cells != 72 && a.cells != 144)
    r.fail(r.full("cells"), YAML::Node(), "one of 60, 72, 144", std::to_string(a.cells));
  a.tilt_deg = r.number("tilt_deg", a.tilt_deg, 0, 60);
  a.table_gap_m = r.number("table_gap_m", a.table_gap_m, 0, 50);
  a.clearance_m = r.number("clearance_m", a.clearance_m, 0.1, 5);
  a.posts = r.boolean("posts", a.posts);
  a.rails = r.boolean("rails", a.rails);
  a.dirt = r.number("dirt", a.dirt, 0, 1);
  a.identical_tables = r.boolean("identical_tables", a.identical_tables);
  const double min_pitch = a.table_depth_m() * std::cos(a.tilt_deg * M_PI / 180.0) + 0.5;
  a.row_pitch_m = r.number("row_pitch_m", std::max(a.row_pitch_m, min_pitch), min_pitch, 100);
  return a;
}

// ---- scene size ----------------------------------------------------------

/// Geoms the scene builder makes for what the scenario asks for (keep in step
/// with sim/src/scene_builder.cpp): per table its panels, one backsheet, two
/// rails and four posts; one per wall; two per shrub or tree.  The ground and
/// the robot add about ten.
long long table_geoms(const PvArray& a) {
  const long long backsheet = 1, rails = a.rails ? 2 : 0, posts = a.posts ? 4 : 0;
  return static_cast<long long>(a.panels_per_table) * a.panel_lines + backsheet + rails + posts;
}

/// MuJoCo's renderer draws at most 4000 geoms a frame (sim/src/renderer.cpp)
/// and leaves the rest out of the image, with one warning.  Far larger scenes
/// also take minutes in MuJoCo's compiler: 50 x 50 tables of 240 panels
/// (617 500 geoms) were not compiled after 5 minutes.
constexpr long long kMaxSceneGeoms = 3800;
/// A scenario file's largest size: 3800 walls of 100 bytes each fit in 400 KiB.
constexpr std::size_t kMaxScenarioBytes = 1024 * 1024;

/// Refuses a scenario whose scene would not fit the renderer: one line naming
/// the limit, the total and the largest array.
void check_scene_size(const Scenario& s, const std::string& origin) {
  long long total = 2LL * (s.vegetation.shrubs + s.vegetation.trees) + static_cast<long long>(s.walls.size());
  long long largest = -1;
  std::size_t largest_index = 0;
  for (std::size_t i = 0; i < s.pv_arrays.size(); ++i) {
    const PvArray& a = s.pv_arrays[i];
    const long long n = static_cast<long long>(a.rows) * a.tables_per_row * table_geoms(a);
    total += n;
    if (n > largest) {
      largest = n;
      largest_index = i;
    }
  }
  if (total <= kMaxSceneGeoms) return;
  std::string got = std::to_string(total);
  if (largest >= 0) {
    const PvArray& a = s.pv_arrays[largest_index];
    got += " (pv_arrays[" + std::to_string(largest_index) + "]: " + std::to_string(a.rows) + " rows x " +
           std::to_string(a.tables_per_row) + " tables x " + std::to_string(table_geoms(a)) + " geoms)";
  }
  throw ConfigError(origin, "pv_arrays",
                    "at most " + std::to_string(kMaxSceneGeoms) +
                        " geoms in the scene (MuJoCo's renderer draws 4000; a table is panels_per_table x "
                        "panel_lines panels + up to 7 parts, a wall 1, a shrub or tree 2)",
                    got);
}

}  // namespace

double Camera::fovy_deg() const { return 2.0 * std::atan(0.5 * height / fy) * 180.0 / M_PI; }

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

namespace {

/// The sections of a scenario file, one reader each.
void read_arrays(MapReader& top, const std::string& origin, std::vector<PvArray>& out) {
  if (const YAML::Node arrays = top.child("pv_arrays")) {
    if (!arrays.IsSequence()) top.fail("pv_arrays", arrays, "a list of arrays");
    if (arrays.size() > static_cast<std::size_t>(kMaxSceneGeoms))
      top.fail("pv_arrays", arrays, "at most " + std::to_string(kMaxSceneGeoms) + " arrays (the renderer's geom limit)",
               std::to_string(arrays.size()));
    for (std::size_t i = 0; i < arrays.size(); ++i) {
      MapReader r(arrays[i], origin, "pv_arrays[" + std::to_string(i) + "]");
      out.push_back(read_array(r));
      r.finish();
    }
  }
}

void read_walls(MapReader& top, const std::string& origin, std::vector<Wall>& out) {
  if (const YAML::Node walls = top.child("walls")) {
    if (!walls.IsSequence()) top.fail("walls", walls, "a list of walls");
    if (walls.size() > static_cast<std::size_t>(kMaxSceneGeoms))  // one geom each: refused before reading them
      top.fail("walls", walls, "at most " + std::to_string(kMaxSceneGeoms) + " walls (the renderer's geom limit)",
               std::to_string(walls.size()));
    for (std::size_t i = 0; i < walls.size(); ++i) {
      MapReader r(walls[i], origin, "walls[" + std::to_string(i) + "]");
      Wall w;
      w.start_m = r.vec2("start_m", w.start_m, -1e4, 1e4);
      w.end_m = r.vec2("end_m", w.end_m, -1e4, 1e4);
      w.height_m = r.number("height_m", w.height_m, 0.2, 10);
      w.thickness_m = r.number("thickness_m", w.thickness_m, 0.05, 2);
      w.finish = r.choice<WallFinish>("finish", w.finish,
                                      {{"brick", WallFinish::kBrick}, {"plaster", WallFinish::kPlaster}});
      if ((w.end_m - w.start_m).norm() < 0.2)
        r.fail(r.full("end_m"), walls[i]["end_m"], "an end at least 0.2 m from start_m");
      r.finish();
      out.push_back(w);
    }
  }
}

void read_vegetation(MapReader& r, Vegetation& v) {
  v.shrubs = r.integer("shrubs", v.shrubs, 0, 500);
  v.shrub_size_m = r.range("shrub_size_m", v.shrub_size_m, 0.05, 5);
  v.trees = r.integer("trees", v.trees, 0, 200);
  v.tree_height_m = r.range("tree_height_m", v.tree_height_m, 0.5, 30);
  const auto area = r.numbers("area_m", 4, -1e4, 1e4);
  if (!area.empty()) {
    v.area_m = Eigen::Vector4d(area[0], area[1], area[2], area[3]);
    if (area[0] >= area[2] || area[1] >= area[3])
      r.fail(r.full("area_m"), YAML::Node(), "[xmin, ymin, xmax, ymax] with xmin < xmax and ymin < ymax");
  }
  v.keep_out_m = r.number("keep_out_m", v.keep_out_m, 0, 50);
}

void read_light(MapReader& r, Light& l) {
  l.sun_azimuth_deg = r.number("sun_azimuth_deg", l.sun_azimuth_deg, -360, 360);
  l.sun_elevation_deg = r.number("sun_elevation_deg", l.sun_elevation_deg, 1, 90);
  l.intensity = r.number("intensity", l.intensity, 0, 1);
  l.ambient = r.number("ambient", l.ambient, 0, 1);
  l.shadows = r.boolean("shadows", l.shadows);
  l.shadow_map_px = r.integer("shadow_map_px", l.shadow_map_px, 256, 8192);
  l.shadow_follows_robot = r.boolean("shadow_follows_robot", l.shadow_follows_robot);
  l.box_quads = r.integer("box_quads", l.box_quads, 1, 16);
}

void read_route(MapReader& r, Route& rt) {
  rt.pattern = r.choice<RoutePattern>("pattern", rt.pattern,
                                      {{"waypoints", RoutePattern::kWaypoints},
                                       {"along_row", RoutePattern::kAlongRow},
                                       {"lawnmower", RoutePattern::kLawnmower},
                                       {"loop", RoutePattern::kLoop}});
  if (const YAML::Node wps = r.child("waypoints_m")) {
    if (!wps.IsSequence() || wps.size() < 2)
      r.fail(r.full("waypoints_m"), wps, "a list of at least 2 [x, y] points");
    for (std::size_t i = 0; i < wps.size(); ++i) {
      double x = 0, y = 0;
      if (!wps[i].IsSequence() || wps[i].size() != 2 || !YAML::convert<double>::decode(wps[i][0], x) ||
          !YAML::convert<double>::decode(wps[i][1], y))
        r.fail(r.full("waypoints_m") + "[" + std::to_string(i) + "]", wps[i], "[x, y] in metres");
      rt.waypoints_m.emplace_back(x, y);
    }
  }
  rt.array = r.integer("array", rt.array, 0, 1000);
  rt.aisle = r.integer("aisle", rt.aisle, 0, 1000);
  rt.aisles = r.integer("aisles", rt.aisles, 1, 100);
  rt.return_to_start = r.boolean("return_to_start", rt.return_to_start);
  if (rt.return_to_start && rt.pattern != RoutePattern::kLawnmower)
    r.fail(r.full("return_to_start"), r.child("return_to_start"), "false unless route.pattern is lawnmower",
           "true");
  if (!rt.return_to_start && r.has("return_overlap_m"))
    r.fail(r.full("return_overlap_m"), r.child("return_overlap_m"),
           "no return_overlap_m unless route.return_to_start is true (it would be ignored)",
           r.child("return_overlap_m").Scalar());
  rt.return_overlap_m = r.number("return_overlap_m", rt.return_overlap_m, 0.5, 100);
  rt.offset_m = r.number("offset_m", rt.offset_m, 0.3, 20);
  rt.margin_m = r.number("margin_m", rt.margin_m, 0, 50);
  rt.speed_mps = r.number("speed_mps", rt.speed_mps, 0.05, 3);
  rt.lookahead_m = r.number("lookahead_m", rt.lookahead_m, 0.1, 5);
  rt.on_loss = r.choice<OnLoss>("on_loss", rt.on_loss, {{"wait", OnLoss::kWait}, {"abort", OnLoss::kAbort}});
}

void read_robot(MapReader& r, Robot& rb) {
  rb.wheel_radius_m = r.number("wheel_radius_m", rb.wheel_radius_m, 0.03, 0.5);
  rb.track_m = r.number("track_m", rb.track_m, 0.1, 2);
  rb.max_wheel_speed_radps = r.number("max_wheel_speed_radps", rb.max_wheel_speed_radps, 1, 100);
}

void read_camera(MapReader& r, Camera& c) {
  c.width = r.integer("width", c.width, 32, 4096);
  c.height = r.integer("height", c.height, 32, 4096);
  const bool has_fx = r.has("fx");
  c.fy = r.number("fy", c.fy, 10, 1e5);
  c.fx = r.number("fx", has_fx ? c.fx : c.fy, 10, 1e5);
  if (std::abs(c.fx - c.fy) > 1e-9)
    r.fail(r.full("fx"), YAML::Node(), "fx equal to fy (MuJoCo 2.2.2 renders square pixels)");
  c.fps = r.number("fps", c.fps, 1, 240);
  c.mount_height_m = r.number("mount_height_m", c.mount_height_m, 0.1, 5);
  c.mount_forward_m = r.number("mount_forward_m", c.mount_forward_m, -1, 1);
  c.pitch_deg = r.number("pitch_deg", c.pitch_deg, -89, 89);
  c.yaw_deg = r.number("yaw_deg", c.yaw_deg, -180, 180);
  c.depth_range_m = r.range("depth_range_m", c.depth_range_m, 0.05, 100);
  with_map(r, "depth_noise", [&](MapReader& n) {
    DepthNoise& d = c.depth_noise;
    d.model = n.choice<DepthNoiseModel>(
        "model", d.model, {{"none", DepthNoiseModel::kNone}, {"kinect", DepthNoiseModel::kKinect}});
    d.baseline_m = n.number("baseline_m", d.baseline_m, 0.01, 1);
    d.disparity_step_px = n.number("disparity_step_px", d.disparity_step_px, 0, 1);
    d.lateral_sigma_px = n.number("lateral_sigma_px", d.lateral_sigma_px, 0, 5);
    d.axial_scale = n.number("axial_scale", d.axial_scale, 0, 100);
    d.max_incidence_deg = n.number("max_incidence_deg", d.max_incidence_deg, 1, 90);
  });
  with_map(r, "rgb", [&](MapReader& n) {
    RgbNoise& g = c.rgb;
    g.sigma = n.number("sigma", g.sigma, 0, 100);
    g.exposure = n.number("exposure", g.exposure, 0.05, 10);
    g.glare = n.number("glare", g.glare, 0, 1);
  });
}

void read_slam(MapReader& r, SlamTuning& t) {
  t.orb_features = r.integer("orb_features", t.orb_features, 100, 20000);
  if (r.has("keyframe_min_tracked_close"))
    t.keyframe_min_tracked_close = r.integer("keyframe_min_tracked_close", 0, 1, 100000);
  if (r.has("keyframe_ref_overlap"))
    t.keyframe_ref_overlap = r.number("keyframe_ref_overlap", 0.0, 0.01, 0.99);
}

void read_expect(MapReader& r, Expectations& e) {
  if (r.has("ate_rmse_m_max")) e.ate_rmse_m_max = r.number("ate_rmse_m_max", 0.0, 1e-6, 100);
  if (r.has("rpe_trans_rmse_m_max"))
    e.rpe_trans_rmse_m_max = r.number("rpe_trans_rmse_m_max", 0.0, 1e-6, 100);
  if (r.has("lost_frames_max")) e.lost_frames_max = r.integer("lost_frames_max", 0, 0, 1000000);
  if (r.has("refined_ate_rmse_m_max"))
    e.refined_ate_rmse_m_max = r.number("refined_ate_rmse_m_max", 0.0, 1e-6, 100);
  if (r.has("false_loops_max")) e.false_loops_max = r.integer("false_loops_max", 0, 0, 1000000);
  if (r.has("relocalised_within_frames"))
    e.relocalised_within_frames = r.integer("relocalised_within_frames", 0, 1, 1000000);
  if (r.has("loops_min")) e.loops_min = r.integer("loops_min", 0, 1, 1000000);
  if (r.has("map_accuracy_m_max")) e.map_accuracy_m_max = r.number("map_accuracy_m_max", 0.0, 1e-6, 100);
  if (r.has("map_completeness_min")) e.map_completeness_min = r.number("map_completeness_min", 0.0, 0.0, 1.0);
  if (r.has("pe_not_worse_than_baseline"))
    r.fail(r.full("pe_not_worse_than_baseline"), r.child("pe_not_worse_than_baseline"),
           "expect.sweep.pe_not_significantly_worse instead (PE-SLAM against the baseline is judged over "
           "a seed sweep, not one run; docs/scenarios.md)",
           "a single-run comparison");
  e.tracking_loss_expected = r.boolean("tracking_loss_expected", e.tracking_loss_expected);
  e.ci_frames = r.integer("ci_frames", e.ci_frames, 0, 1000000);
  if (e.ci_frames == 1)
    r.fail(r.full("ci_frames"), YAML::Node(), "0 (not in the fast subset) or at least 2 frames", "1");
  if (e.tracking_loss_expected && e.lost_frames_max == 0)
    r.fail(r.full("lost_frames_max"), YAML::Node(), "a value >= 1 when tracking_loss_expected is true", "0");
  with_map(r, "sweep", [&](MapReader& w) {
    SweepExpectations& sw = e.sweep;
    sw.pe_not_significantly_worse = w.boolean("pe_not_significantly_worse", sw.pe_not_significantly_worse);
    sw.min_seeds = w.integer("min_seeds", sw.min_seeds, 10, 100000);
  });
}

/// Where `key` of the map `n` is in the file (the map itself when the key is absent).
YAML::Node node_of(const YAML::Node& n, const char* key) {
  const YAML::Node& cn = n;  // const: operator[] must not insert the key
  const YAML::Node v = cn[key];
  return v.IsDefined() ? v : n;
}

/// The kidnap: section.  Read after duration_s and camera, which bound it.
void read_kidnap(MapReader& top, const std::string& origin, Scenario& s) {
  const YAML::Node n = top.child("kidnap");
  if (!n) return;
  MapReader r(n, origin, "kidnap");
  for (const char* key : {"at_s", "to_route_s"})
    if (!r.has(key)) r.fail(r.full(key), n, "a time in seconds (required in kidnap)");
  Kidnap k;
  k.at_s = r.number("at_s", k.at_s, 0, 3600);
  k.covered_s = r.number("covered_s", k.covered_s, 1e-3, 3600);
  k.to_route_s = r.number("to_route_s", k.to_route_s, 0, 3600);
  r.finish();
  const double frame_s = 1.0 / s.camera.fps;
  if (!(k.at_s < s.duration_s))
    r.fail(r.full("at_s"), node_of(n, "at_s"),
           "a time before duration_s (" + format_number("%g", s.duration_s) + " s)", format_number("%g", k.at_s));
  // At least one frame period (1e-9 s: a period written in decimals).
  if (k.covered_s < frame_s - 1e-9)
    r.fail(r.full("covered_s"), node_of(n, "covered_s"),
           "at least one frame period (1 / camera.fps = " + format_number("%g", frame_s) + " s)",
           format_number("%g", k.covered_s));
  const KidnapFrames f = kidnap_frames(k, s.camera.fps);
  if (!(k.to_route_s < k.at_s) || f.target >= f.cover_begin)
    r.fail(r.full("to_route_s"), node_of(n, "to_route_s"),
           "a time at least one frame before kidnap.at_s (" + format_number("%g", k.at_s) + " s)",
           format_number("%g", k.to_route_s));
  if (!(k.at_s + k.covered_s < s.duration_s))
    r.fail(r.full("covered_s"), node_of(n, "covered_s"),
           "at_s + covered_s before duration_s (" + format_number("%g", s.duration_s) + " s)",
           format_number("%g", k.at_s + k.covered_s) + " s");
  if (f.cover_end <= f.cover_begin)
    r.fail(r.full("covered_s"), node_of(n, "covered_s"),
           "at least one frame period (1 / camera.fps = " + format_number("%g", 1.0 / s.camera.fps) + " s)",
           format_number("%g", k.covered_s));
  s.kidnap = k;
}

/// "FILE:LINE" of `section`.`key` in the document (FILE when not there).
std::string where(const YAML::Node& root, const std::string& origin, const char* section, const char* key) {
  const YAML::Node& croot = root;  // const: operator[] must not insert keys
  const YAML::Node sec = croot[section];
  if (!sec.IsDefined() || !sec.IsMap()) return origin;
  const YAML::Node& csec = sec;
  const YAML::Node v = csec[key];
  return v.IsDefined() && v.Mark().line >= 0 ? origin + ":" + std::to_string(v.Mark().line + 1) : origin;
}

/// Checks between fields: the route against the arrays it names.
void check_route(const Scenario& s, const std::string& origin, const YAML::Node& root) {
  const Route& rt = s.route;
  const auto at = [&](const char* key) { return where(root, origin, "route", key); };
  if (rt.pattern == RoutePattern::kWaypoints && rt.waypoints_m.size() < 2)
    throw ConfigError(at("pattern"), "route.waypoints_m", "at least 2 points when route.pattern is waypoints");
  if (rt.pattern != RoutePattern::kWaypoints) {
    if (s.pv_arrays.empty())
      throw ConfigError(at("pattern"), "route.pattern", "a waypoints route when the scenario has no pv_arrays",
                        to_string(rt.pattern));
    if (rt.array >= static_cast<int>(s.pv_arrays.size()))
      throw ConfigError(at("array"), "route.array", "an index below " + std::to_string(s.pv_arrays.size()),
                        std::to_string(rt.array));
    const PvArray& a = s.pv_arrays[static_cast<std::size_t>(rt.array)];
    if (rt.pattern == RoutePattern::kAlongRow && rt.aisle > a.rows)
      throw ConfigError(at("aisle"), "route.aisle", "an aisle in [0, " + std::to_string(a.rows) + "]",
                        std::to_string(rt.aisle));
    if (rt.pattern == RoutePattern::kLawnmower && rt.aisles > a.rows + 1)
      throw ConfigError(at("aisles"), "route.aisles", "at most rows + 1 = " + std::to_string(a.rows + 1),
                        std::to_string(rt.aisles));
    const double first_aisle_m = row_length_m(a) + 2 * rt.margin_m;
    if (rt.pattern == RoutePattern::kLawnmower && rt.return_to_start && rt.return_overlap_m > first_aisle_m)
      throw ConfigError(at("return_overlap_m"), "route.return_overlap_m",
                        "at most the first aisle's length, " + format_number("%.2f m", first_aisle_m),
                        format_number("%g", rt.return_overlap_m));
  }
}

/// yaml-cpp keeps both of two equal keys in a map and finds the first, so
/// a second value would go unread and unchecked: a key given twice is an
/// error naming both lines.
void check_no_duplicate_keys(const YAML::Node& n, const std::string& origin, const std::string& path) {
  if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i)
      check_no_duplicate_keys(n[i], origin, path + "[" + std::to_string(i) + "]");
    return;
  }
  if (!n.IsMap()) return;
  std::map<std::string, int> first_line;
  for (const auto& kv : n) {
    if (!kv.first.IsScalar()) continue;  // MapReader::finish() names a non-scalar key
    const std::string key = kv.first.Scalar();
    const std::string full = path.empty() ? key : path + "." + key;
    const int line = kv.first.Mark().line + 1;
    const auto [at, fresh] = first_line.emplace(key, line);
    if (!fresh)
      throw ConfigError(origin + ":" + std::to_string(line), full,
                        "each key once in its section (first given at line " + std::to_string(at->second) + ")",
                        "a second " + key);
    check_no_duplicate_keys(kv.second, origin, full);
  }
}

}  // namespace

Scenario parse_scenario(const std::string& yaml_text, const std::string& origin) {
  // The parser takes about 100 bytes of memory per byte of text: a file far
  // larger than any scene the renderer draws is refused before it is parsed.
  if (yaml_text.size() > kMaxScenarioBytes)
    throw ConfigError(origin, "(file)",
                      "a scenario file of at most " + std::to_string(kMaxScenarioBytes / 1024) +
                          " KiB (the largest scene the renderer draws takes far less)",
                      std::to_string(yaml_text.size() / 1024) + " KiB");
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::DeepRecursion& e) {
    throw ConfigError(origin + ":" + std::to_string(e.mark.line + 1), "(syntax)",
                      "YAML nested at most a few hundred levels deep", "nesting too deep for the parser");
  } catch (const YAML::Exception& e) {
    throw ConfigError(origin + ":" + std::to_string(e.mark.line + 1), "(syntax)", "valid YAML", e.msg);
  }
  check_no_duplicate_keys(root, origin, "");
  if (!root.IsDefined() || root.IsNull())
    throw ConfigError(origin, "(top level)", "a scenario mapping", "an empty file");
  Scenario s;
  s.source_file = origin;
  MapReader top(root, origin, "");
  s.name = top.string("name", s.name);
  s.description = top.string("description", s.description);
  s.seed = top.seed("seed", s.seed);
  s.duration_s = top.number("duration_s", s.duration_s, 0.1, 3600);

  with_map(top, "ground", [&](MapReader& r) {
    s.ground.type = r.choice<GroundType>("type", s.ground.type,
                                         {{"soil", GroundType::kSoil}, {"gravel", GroundType::kGravel}});
    s.ground.size_m = r.vec2("size_m", s.ground.size_m, 5, 2000);
  });

  read_arrays(top, origin, s.pv_arrays);
  read_walls(top, origin, s.walls);
  with_map(top, "vegetation", [&](MapReader& r) { read_vegetation(r, s.vegetation); });
  with_map(top, "light", [&](MapReader& r) { read_light(r, s.light); });
  with_map(top, "route", [&](MapReader& r) { read_route(r, s.route); });
  with_map(top, "robot", [&](MapReader& r) { read_robot(r, s.robot); });
  with_map(top, "camera", [&](MapReader& r) { read_camera(r, s.camera); });
  with_map(top, "slam", [&](MapReader& r) { read_slam(r, s.slam); });
  read_kidnap(top, origin, s);
  with_map(top, "expect", [&](MapReader& r) { read_expect(r, s.expect); });
  top.finish();
  check_scene_size(s, origin);

  check_route(s, origin, root);
  return s;
}

Scenario load_scenario(const std::string& path) {
  require_regular_file(path);
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && static_cast<std::size_t>(st.st_size) > kMaxScenarioBytes)
    throw ConfigError(path, "(file)", "a scenario file of at most " + std::to_string(kMaxScenarioBytes / 1024) + " KiB",
                      std::to_string(st.st_size / 1024) + " KiB");
  return parse_scenario(read_file(path), path);
}

int frame_count(const Scenario& s, int max_frames) {
  const int n = static_cast<int>(std::floor(s.duration_s * s.camera.fps + 1e-9)) + 1;
  return max_frames > 0 ? std::min(n, max_frames) : n;
}

KidnapFrames kidnap_frames(const Kidnap& k, double fps) {
  // Frame i is at i / fps; the small tolerance keeps a time that is a whole
  // number of frames (40 s at 30 fps) on that frame.
  const auto at_or_after = [fps](double t_s) { return static_cast<int>(std::ceil(t_s * fps - 1e-6)); };
  KidnapFrames f;
  f.cover_begin = at_or_after(k.at_s);
  f.cover_end = at_or_after(k.at_s + k.covered_s);
  f.teleport = f.cover_begin + (f.cover_end - f.cover_begin) / 2;
  f.target = static_cast<int>(std::floor(k.to_route_s * fps + 1e-6));
  return f;
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
  }
  return "?";
}

}  // namespace pvb::scenes
