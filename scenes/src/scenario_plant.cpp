// The plant: section (scenes/SCHEMA.md, "plant"): read, checked, laid out
// into blocks (the scenario's last arrays) and inverter stations (its last
// walls); and the checks of a plant's route.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/plant.hpp"
#include "pvb/scenes/route.hpp"
#include "scenario_sections.hpp"

namespace pvb::scenes::detail {
namespace {

/// Ground coverage ratios when the file gives neither a pitch nor a ratio
/// (SCHEMA.md gives their sources).
constexpr double kFixedGcr = 0.45, kTrackerGcr = 0.35;

void read_module_and_mount(MapReader& r, Plant& p) {
  p.cells = r.integer("cells", p.cells, 60, 144);
  if (p.cells != 60 && p.cells != 72 && p.cells != 144)
    r.fail(r.full("cells"), YAML::Node(), "one of 60, 72, 144", std::to_string(p.cells));
  p.module_power_w = r.number("module_power_w", p.module_power_w, 100, 1000);
  PvArray mount;
  read_mount(r, mount);
  p.mount = mount.mount;
  p.tilt_deg = mount.tilt_deg;
  p.tracker = mount.tracker;
  if (p.mount == Mount::kSingleAxis) p.modules_high = 1;  // 1P: the usual tracker
  p.modules_high = r.integer("modules_high", p.modules_high, 1, 4);
  p.orientation = r.choice<PanelOrientation>(
      "orientation", p.orientation,
      {{"portrait", PanelOrientation::kPortrait}, {"landscape", PanelOrientation::kLandscape}});
  if (p.mount == Mount::kSingleAxis) p.modules_per_table = 28;  // 84 modules a row in 3 tables (3 strings of 28)
  p.modules_per_table = r.integer("modules_per_table", p.modules_per_table, 1, 120);
  p.tables_per_row = r.integer("tables_per_row", p.tables_per_row, 1, 50);
  p.table_gap_m = r.number("table_gap_m", p.table_gap_m, 0, 50);
  p.clearance_m = r.number("clearance_m", p.clearance_m, 0.1, 5);
}

/// The pitch, given or from the ground coverage ratio; rows at least half a
/// metre apart.
void read_pitch(MapReader& r, Plant& p) {
  if (r.has("row_pitch_m") && r.has("ground_coverage_ratio"))
    r.fail(r.full("ground_coverage_ratio"), r.child("ground_coverage_ratio"),
           "row_pitch_m or ground_coverage_ratio, not both");
  const PvArray a = plant_block_array(p);
  const double width = a.table_depth_m(), min_pitch = row_footprint_m(a) + 0.5;
  if (r.has("row_pitch_m")) {
    p.row_pitch_m = r.number("row_pitch_m", 0, min_pitch, 100);
    return;
  }
  const double gcr = r.number("ground_coverage_ratio", p.mount == Mount::kFixed ? kFixedGcr : kTrackerGcr, 0.01, kInf);
  if (gcr >= 1)
    r.fail(r.full("ground_coverage_ratio"), r.child("ground_coverage_ratio"),
           "a ratio below 1 (the collector width over the row pitch, as pvlib defines it)", format_exact(gcr));
  p.row_pitch_m = width / gcr;
  if (p.row_pitch_m < min_pitch)
    r.fail(r.full("ground_coverage_ratio"), r.child("ground_coverage_ratio"),
           "at most " + format_number("%.3f", width / min_pitch) + " (a pitch of at least " +
               format_number("%.2f m", min_pitch) + ": the row's footprint and half a metre)",
           format_exact(gcr));
}

void read_blocks(MapReader& r, Plant& p) {
  p.blocks = r.integer("blocks", p.blocks, 1, 400);
  p.blocks_along = r.integer("blocks_along", p.blocks_along, 1, p.blocks);
  if (r.has("rows") && r.has("block_mwdc"))
    r.fail(r.full("block_mwdc"), r.child("block_mwdc"), "rows or block_mwdc, not both");
  if (r.has("block_mwdc")) {
    const double mwdc = r.number("block_mwdc", 0, 0.001, 1000);
    p.rows_per_block = rows_for_block_mwdc(p, mwdc);
    if (p.rows_per_block > 400)
      r.fail(r.full("block_mwdc"), YAML::Node(),
             "a block of at most 400 rows (this layout holds " +
                 format_number("%.2f MWdc", 400.0 * p.tables_per_row * p.modules_per_table * p.modules_high *
                                                p.module_power_w / 1e6) + ")", format_exact(mwdc));
  } else {
    p.rows_per_block = r.integer("rows", 10, 1, 400);
  }
  p.road_width_m = r.number("road_width_m", p.road_width_m, 2, 30);
  p.inverter_mwdc = r.number("inverter_mwdc", p.inverter_mwdc, 0, 50);
  p.headland_m = r.number("headland_m", p.headland_m, 2, 100);
}

/// A switch that is either `false` (off) or a map of its settings
/// (`fn` reads it; `{}` or `true` keep the defaults).  Returns whether it is on.
bool read_switch(MapReader& r, const std::string& key, const std::function<void(MapReader&)>& fn) {
  if (!r.has(key)) return true;
  const YAML::Node n = r.node()[key];
  if (n.IsScalar()) return r.boolean(key, true);
  if (!n.IsMap()) r.fail(r.full(key), n, "false, true or a map of its settings");
  with_map(r, key, fn);
  return true;
}

/// The fence, the dock and the combiner boxes.
void read_fixtures(MapReader& r, Plant& p) {
  p.fence.on = read_switch(r, "fence", [&](MapReader& q) {
    p.fence.setback_m = q.number("setback_m", p.road_width_m + 2.0, p.road_width_m + 1.0, 100);
    p.fence.height_m = q.number("height_m", p.fence.height_m, 0.5, 5);
    p.fence.post_spacing_m = q.number("post_spacing_m", p.fence.post_spacing_m, 1, 10);
    p.fence.gate_width_m = q.number("gate_width_m", p.fence.gate_width_m, 1, 20);
  });
  int aisle = 0;
  const bool dock = read_switch(r, "dock", [&](MapReader& q) { aisle = q.integer("aisle", 0, 0, p.rows_per_block); });
  p.dock_aisle = dock ? std::optional<int>(aisle) : std::nullopt;
  const double dock_needs_m = 0.5 + kDockCabinetAlongM + kDockStandoffM + 0.5;
  if (dock && p.headland_m < dock_needs_m)
    r.fail(r.full("dock"), r.node()["dock"],
           "a headland_m of at least " + format_number("%.1f m", dock_needs_m) +
               " to hold the dock and the robot in front of it (or dock: false)",
           "a headland of " + format_exact(p.headland_m) + " m");
  p.combiner_rows = r.integer("combiner_rows", p.combiner_rows, 0, 400);
  p.row_signs = r.boolean("row_signs", p.row_signs);
}

Plant read_plant_section(MapReader& r) {
  Plant p;
  p.origin_m = r.vec2("origin_m", p.origin_m, -1e4, 1e4);
  p.azimuth_deg = r.number("azimuth_deg", p.azimuth_deg, -360, 360);
  read_module_and_mount(r, p);
  read_pitch(r, p);
  read_blocks(r, p);
  read_fixtures(r, p);
  p.dirt = r.number("dirt", p.dirt, 0, 1);
  p.row_soiling = r.number("row_soiling", p.row_soiling, 0, 1);
  p.tyre_tracks = r.number("tyre_tracks", p.tyre_tracks, 0, 1);
  p.vegetation_strips = r.number("vegetation_strips", p.vegetation_strips, 0, 1);
  const long long block_modules =
      static_cast<long long>(p.rows_per_block) * p.tables_per_row * p.modules_per_table * p.modules_high;
  p.broken_modules = r.integer("broken_modules", 0, 0, static_cast<int>(std::min<long long>(block_modules, 1000)));
  p.missing_modules = r.integer(
      "missing_modules", 0, 0, static_cast<int>(std::min<long long>(block_modules - p.broken_modules, 1000)));
  p.specular_glass = r.choice<bool>("glass", p.specular_glass, {{"diffuse", false}, {"specular", true}});
  p.identical_tables = r.boolean("identical_tables", p.identical_tables);
  return p;
}

/// Refuses a plant that reaches beyond the ground (centred on the origin),
/// naming its farthest corner and the ground that would hold it.
void check_on_ground(const Scenario& s, const PlantLayout& layout, const MapReader& top) {
  Eigen::Vector2d need = Eigen::Vector2d::Zero(), far = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& c : layout.fence ? layout.fence->corners_m : layout.corners_m) {
    need = need.cwiseMax(2 * c.cwiseAbs());
    if (c.cwiseAbs().maxCoeff() > far.cwiseAbs().maxCoeff()) far = c;
  }
  if (need.x() <= s.ground.size_m.x() && need.y() <= s.ground.size_m.y()) return;
  top.fail("plant", top.node()["plant"],
           "a plant inside ground.size_m [" + format_exact(s.ground.size_m.x()) + ", " +
               format_exact(s.ground.size_m.y()) + "] (centred on the origin, headlands and fence included)",
           "a plant reaching (x, y) = (" + format_number("%.1f", far.x()) + ", " + format_number("%.1f", far.y()) +
               ") m: a ground of at least [" + format_number("%.0f", std::ceil(need.x())) + ", " +
               format_number("%.0f", std::ceil(need.y())) + "]");
}

/// Whether a quadrilateral (convex, in order) overlaps an axis-aligned
/// rectangle [u0, v0, u1, v1]: separating axes of both.
bool overlaps(const std::array<Eigen::Vector2d, 4>& quad, const Eigen::Vector4d& rect) {
  const std::array<Eigen::Vector2d, 4> box = {Eigen::Vector2d(rect[0], rect[1]), Eigen::Vector2d(rect[2], rect[1]),
                                              Eigen::Vector2d(rect[2], rect[3]), Eigen::Vector2d(rect[0], rect[3])};
  const Eigen::Vector2d axes[4] = {Eigen::Vector2d::UnitX(), Eigen::Vector2d::UnitY(),
                                   (quad[1] - quad[0]).normalized(), (quad[3] - quad[0]).normalized()};
  for (const Eigen::Vector2d& ax : axes) {
    double a0 = kInf, a1 = -kInf, b0 = kInf, b1 = -kInf;
    for (const Eigen::Vector2d& p : quad) a0 = std::min(a0, p.dot(ax)), a1 = std::max(a1, p.dot(ax));
    for (const Eigen::Vector2d& p : box) b0 = std::min(b0, p.dot(ax)), b1 = std::max(b1, p.dot(ax));
    if (a1 <= b0 || b1 <= a0) return false;
  }
  return true;
}

/// Refuses a row of a hand-written array that crosses one of the plant's
/// roads or its fence, naming the array, the row and what it crosses.
void check_rows_clear(const Scenario& s, const PlantLayout& layout, const PvArray& base, MapReader& top) {
  std::vector<std::pair<Eigen::Vector4d, std::string>> keep_out;
  if (layout.fence) {  // the fence as four strips 10 cm wide
    const Eigen::Vector2d a = world_to_array(base, layout.fence->corners_m[0]);
    const Eigen::Vector2d b = world_to_array(base, layout.fence->corners_m[2]);
    const double w = 0.05;
    for (const Eigen::Vector4d& r : {Eigen::Vector4d(a.x(), a.y() - w, b.x(), a.y() + w),
                                     Eigen::Vector4d(a.x(), b.y() - w, b.x(), b.y() + w),
                                     Eigen::Vector4d(a.x() - w, a.y(), a.x() + w, b.y()),
                                     Eigen::Vector4d(b.x() - w, a.y(), b.x() + w, b.y())})
      keep_out.emplace_back(r, "the fence");
  }
  for (const Eigen::Vector4d& r : layout.roads_uv) keep_out.emplace_back(r, "a service road");
  for (std::size_t i = 0; i < s.pv_arrays.size(); ++i) {
    const PvArray& a = s.pv_arrays[i];
    const double len = row_length_m(a), depth = row_footprint_m(a);
    for (int row = 0; row < a.rows; ++row) {
      const double v = row * a.row_pitch_m;
      std::array<Eigen::Vector2d, 4> quad;
      int k = 0;
      for (const auto& [du, dv] : {std::pair{0.0, 0.0}, {len, 0.0}, {len, depth}, {0.0, depth}})
        quad[static_cast<std::size_t>(k++)] = world_to_array(base, array_to_world(a, du, v + dv));
      for (const auto& [rect, what] : keep_out)
        if (overlaps(quad, rect))
          top.fail("pv_arrays[" + std::to_string(i) + "]", top.node()["pv_arrays"][i],
                   "rows clear of the plant's service roads and its fence",
                   "row " + std::to_string(row) + " crossing " + what);
    }
  }
}

}  // namespace

void read_plant(MapReader& top, Scenario& s) {
  std::optional<Plant> plant;
  with_map(top, "plant", [&](MapReader& r) { plant = read_plant_section(r); });
  if (!plant) return;
  const Plant& p = *plant;
  const PlantLayout layout = lay_out_plant(p);
  check_on_ground(s, layout, top);
  check_rows_clear(s, layout, plant_block_array(p), top);
  PlantSummary sum;
  sum.first_array = static_cast<int>(s.pv_arrays.size());
  sum.blocks = p.blocks;
  sum.rows_per_block = p.rows_per_block;
  sum.modules = layout.modules;
  sum.dc_mw = layout.dc_mw;
  sum.ground_coverage_ratio = layout.ground_coverage_ratio;
  sum.row_pitch_m = p.row_pitch_m;
  sum.inverter_stations = static_cast<int>(layout.inverter_stations.size());
  sum.corners_m = layout.corners_m;
  sum.extent_uv = layout.extent_uv;
  sum.road_width_m = p.road_width_m;
  sum.perimeter_road_m = layout.perimeter_road_m;
  sum.fence = layout.fence;
  sum.fixtures = layout.fixtures;
  sum.row_signs = layout.row_signs;
  sum.sign_labels = layout.sign_labels;
  sum.dock_aisle = p.dock_aisle;
  sum.dock_front_u_m = layout.dock_front_u_m;
  sum.dock_v_m = layout.dock_v_m;
  sum.roads_uv = layout.roads_uv;
  sum.block_loops_uv = layout.block_loops_uv;
  sum.tracked_aisles = static_cast<int>(std::lround(p.tyre_tracks * (p.rows_per_block + 1)));
  sum.grass_rows = static_cast<int>(std::lround(p.vegetation_strips * p.rows_per_block));
  if ((sum.tracked_aisles > 0 || sum.grass_rows > 0) && s.ground.relief)
    top.fail("plant", top.child("plant"), "tyre_tracks and vegetation_strips on a flat ground (no ground.relief)",
             "a relief");
  s.pv_arrays.insert(s.pv_arrays.end(), layout.blocks.begin(), layout.blocks.end());
  s.walls.insert(s.walls.end(), layout.inverter_stations.begin(), layout.inverter_stations.end());
  s.plant = sum;
}

namespace {

/// A route point `clear_m` or less from a table's footprint in `block`.
bool in_a_table(const PvArray& block, const Eigen::Vector2d& p, double clear_m) {
  const Eigen::Vector2d uv = world_to_array(block, p);
  const double u = uv.x(), v = uv.y();
  const double footprint = row_footprint_m(block), tl = block.table_length_m();
  const int row = static_cast<int>(std::floor((v + clear_m) / block.row_pitch_m));
  if (row < 0 || row >= block.rows || v - row * block.row_pitch_m > footprint + clear_m) return false;
  const double stride = tl + block.table_gap_m;
  const int table = static_cast<int>(std::floor((u + clear_m) / stride));
  return table >= 0 && table < block.tables_per_row && u - table * stride <= tl + clear_m;
}

/// A fixture this high above the ground (the dock's canopy) is above the robot.
constexpr double kOverheadM = 1.5;

/// A footprint a route keeps clear of: a box turned by its yaw, grown by the
/// clearance, with the radius of the circle around it.
struct KeepOutBox {
  Eigen::Vector2d centre_m;
  double cos_yaw, sin_yaw, half_u_m, half_v_m, radius2_m2;
  bool holds(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d q = p - centre_m;
    if (q.squaredNorm() > radius2_m2) return false;
    const double u = q.x() * cos_yaw + q.y() * sin_yaw, v = -q.x() * sin_yaw + q.y() * cos_yaw;
    return std::abs(u) <= half_u_m && std::abs(v) <= half_v_m;
  }
};

/// The footprints of the fixtures and the inverter stations, each grown by `clear_m`.
std::vector<KeepOutBox> fixture_boxes(const Scenario& s, const PlantSummary& plant, double clear_m) {
  std::vector<KeepOutBox> boxes;
  const auto add = [&](const Eigen::Vector2d& c, double yaw_deg, double along, double across) {
    const double a = yaw_deg * M_PI / 180.0, hu = along / 2 + clear_m, hv = across / 2 + clear_m;
    // The circle is a hair wider than the box's corners, so rounding never rejects a point inside.
    boxes.push_back({c, std::cos(a), std::sin(a), hu, hv, (hu * hu + hv * hv) * (1 + 1e-9) + 1e-12});
  };
  for (const Fixture& f : plant.fixtures)  // the dock's canopy stands over the robot
    if (f.base_m < kOverheadM) add(f.centre_m, f.yaw_deg, f.size_m.x(), f.size_m.y());
  for (const RowSign& r : plant.row_signs)  // the post, the plate across it
    add(r.centre_m, r.yaw_deg, kRowSignPostM, kRowSignPlateWideM);
  for (std::size_t i = s.walls.size() - static_cast<std::size_t>(plant.inverter_stations); i < s.walls.size(); ++i) {
    const Wall& w = s.walls[i];
    const Eigen::Vector2d d = w.end_m - w.start_m;
    add(0.5 * (w.start_m + w.end_m), std::atan2(d.y(), d.x()) * 180.0 / M_PI, d.norm(), w.thickness_m);
  }
  return boxes;
}

/// The keep-out boxes in a grid of cells as wide as the widest box's circle:
/// a point can lie in a box only if the box's centre is in the point's cell
/// or one of the eight around it, so a point is tested against a few boxes,
/// not a plant's hundreds of row signs.
class KeepOutGrid {
 public:
  explicit KeepOutGrid(std::vector<KeepOutBox> boxes) : boxes_(std::move(boxes)) {
    for (const KeepOutBox& b : boxes_) cell_m_ = std::max(cell_m_, std::sqrt(b.radius2_m2));
    for (std::size_t i = 0; i < boxes_.size(); ++i) {
      const auto [cx, cy] = cell_of(boxes_[i].centre_m);
      cells_[key(cx, cy)].push_back(i);
    }
  }
  bool holds(const Eigen::Vector2d& p) const {
    const auto [cx, cy] = cell_of(p);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = cells_.find(key(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (const std::size_t i : it->second)
          if (boxes_[i].holds(p)) return true;
      }
    return false;
  }

 private:
  std::pair<std::int64_t, std::int64_t> cell_of(const Eigen::Vector2d& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x() / cell_m_)),
            static_cast<std::int64_t>(std::floor(p.y() / cell_m_))};
  }
  static std::int64_t key(std::int64_t cx, std::int64_t cy) { return cx * 1000003 + cy; }

  std::vector<KeepOutBox> boxes_;
  double cell_m_ = 1.0;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells_;
};

}  // namespace

/// The checks of a route that needs a plant: a loop along its roads, a
/// route from its dock.
void check_plant_pattern(const Scenario& s, const ReadContext& ctx) {
  const Route& rt = s.route;
  const auto at = [&](const char* key) { return ctx.origins->where(std::string("route.") + key, ctx.file); };
  if (rt.pattern == RoutePattern::kRoads && (!s.plant || !s.plant->fence))
    throw ConfigError(at("pattern"), "route.pattern",
                      "roads only in a plant with a fence (the loop follows the perimeter road inside it)", "roads");
  if (rt.block > 0 && rt.block > s.plant->blocks)
    throw ConfigError(at("block"), "route.block",
                      "a block of the plant, from 1 to " + std::to_string(s.plant->blocks),
                      std::to_string(rt.block));
  if (!rt.from_dock) return;
  if (!s.plant || !s.plant->dock_aisle)
    throw ConfigError(at("from_dock"), "route.from_dock", "false unless the plant has a dock (plant.dock)", "true");
  const PlantSummary& plant = *s.plant;
  if (rt.array != plant.first_array)
    throw ConfigError(at("array"), "route.array",
                      "the plant's first block, " + std::to_string(plant.first_array) + ", which holds the dock",
                      std::to_string(rt.array));
  if (rt.first_aisle != *plant.dock_aisle)
    throw ConfigError(at("first_aisle"), "route.first_aisle",
                      "the dock's aisle, " + std::to_string(*plant.dock_aisle) + " (plant.dock.aisle)",
                      std::to_string(rt.first_aisle));
  if (!(plant.dock_front_u_m < -rt.margin_m))
    throw ConfigError(at("margin_m"), "route.margin_m",
                      "a run-out that starts past the dock: below " +
                          format_number("%.2f m", -plant.dock_front_u_m) + " (a wider plant.headland_m makes room)",
                      format_exact(rt.margin_m));
}

void check_plant_route(const Scenario& s, const ReadContext& ctx) {
  if (!s.plant) return;
  const PlantSummary& plant = *s.plant;
  const std::string key = s.route.pattern == RoutePattern::kWaypoints ? "route.waypoints_m" : "route.pattern";
  const auto refuse = [&](const std::string& expected, const Eigen::Vector2d& p, double along_m) {
    throw ConfigError(ctx.origins->where(key, ctx.file), key, expected,
                      "a route through (x, y) = (" + format_number("%.2f", p.x()) + ", " +
                          format_number("%.2f", p.y()) + ") m, " + format_number("%.1f m", along_m) + " along it");
  };
  // Inside the fence by the robot's half width, or without one inside the extent.
  const std::vector<Eigen::Vector2d>& bound = plant.fence ? plant.fence->corners_m : plant.corners_m;
  const double inset_m = plant.fence ? kRouteTableClearanceM : 0.0;
  const Eigen::Vector2d c0 = bound[0];
  const Eigen::Vector2d eu = bound[1] - c0, ev = bound[3] - c0;
  const std::vector<Eigen::Vector2d> route = route_polyline(s);
  const KeepOutGrid fixtures(fixture_boxes(s, plant, kRouteTableClearanceM));
  double along_m = 0;
  for (std::size_t i = 0; i < route.size(); ++i) {
    const Eigen::Vector2d& p = route[i];
    if (i > 0) along_m += (p - route[i - 1]).norm();
    const double u = (p - c0).dot(eu) / eu.norm(), v = (p - c0).dot(ev) / ev.norm();
    if (u < inset_m || u > eu.norm() - inset_m || v < inset_m || v > ev.norm() - inset_m)
      refuse(plant.fence ? "a route inside the plant's fence, the robot's half width from it"
                         : "a route inside the plant (its blocks, their headlands and the aisles beside them)",
             p, along_m);
    for (int b = plant.first_array; b < plant.first_array + plant.blocks; ++b)
      if (in_a_table(s.pv_arrays[static_cast<std::size_t>(b)], p, kRouteTableClearanceM))
        refuse("a route that keeps " + format_number("%.2f m", kRouteTableClearanceM) +
                   " from every table (the robot's half width)", p, along_m);
    if (fixtures.holds(p))
      refuse("a route that keeps " + format_number("%.2f m", kRouteTableClearanceM) +
                 " from the dock, the combiner boxes, the row signs and the inverter stations", p, along_m);
  }
}

}  // namespace pvb::scenes::detail
