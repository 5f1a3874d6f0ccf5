// The plant: section (scenes/SCHEMA.md, "plant"): read, checked, laid out
// into blocks (the scenario's last arrays) and inverter stations (its last
// walls); and the checks of a plant's route.
#include <cmath>

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

Plant read_plant_section(MapReader& r) {
  Plant p;
  p.origin_m = r.vec2("origin_m", p.origin_m, -1e4, 1e4);
  p.azimuth_deg = r.number("azimuth_deg", p.azimuth_deg, -360, 360);
  read_module_and_mount(r, p);
  read_pitch(r, p);
  read_blocks(r, p);
  p.dirt = r.number("dirt", p.dirt, 0, 1);
  p.specular_glass = r.choice<bool>("glass", p.specular_glass, {{"diffuse", false}, {"specular", true}});
  p.identical_tables = r.boolean("identical_tables", p.identical_tables);
  return p;
}

/// Refuses a plant that reaches beyond the ground (centred on the origin),
/// naming its farthest corner and the ground that would hold it.
void check_on_ground(const Scenario& s, const PlantLayout& layout, const MapReader& top) {
  Eigen::Vector2d need = Eigen::Vector2d::Zero(), far = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& c : layout.corners_m) {
    need = need.cwiseMax(2 * c.cwiseAbs());
    if (c.cwiseAbs().maxCoeff() > far.cwiseAbs().maxCoeff()) far = c;
  }
  if (need.x() <= s.ground.size_m.x() && need.y() <= s.ground.size_m.y()) return;
  top.fail("plant", top.node()["plant"],
           "a plant inside ground.size_m [" + format_exact(s.ground.size_m.x()) + ", " +
               format_exact(s.ground.size_m.y()) + "] (centred on the origin, headlands included)",
           "a plant reaching (x, y) = (" + format_number("%.1f", far.x()) + ", " + format_number("%.1f", far.y()) +
               ") m: a ground of at least [" + format_number("%.0f", std::ceil(need.x())) + ", " +
               format_number("%.0f", std::ceil(need.y())) + "]");
}

}  // namespace

void read_plant(MapReader& top, Scenario& s) {
  std::optional<Plant> plant;
  with_map(top, "plant", [&](MapReader& r) { plant = read_plant_section(r); });
  if (!plant) return;
  const Plant& p = *plant;
  const PlantLayout layout = lay_out_plant(p);
  check_on_ground(s, layout, top);
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

}  // namespace

void check_plant_route(const Scenario& s, const ReadContext& ctx) {
  if (!s.plant) return;
  const PlantSummary& plant = *s.plant;
  const std::string key = s.route.pattern == RoutePattern::kWaypoints ? "route.waypoints_m" : "route.pattern";
  const auto refuse = [&](const std::string& expected, const Eigen::Vector2d& p, double along_m) {
    throw ConfigError(ctx.origins->where(key, ctx.file), key, expected,
                      "a route through (x, y) = (" + format_number("%.2f", p.x()) + ", " +
                          format_number("%.2f", p.y()) + ") m, " + format_number("%.1f m", along_m) + " along it");
  };
  const Eigen::Vector2d c0 = plant.corners_m[0];
  const Eigen::Vector2d eu = plant.corners_m[1] - c0, ev = plant.corners_m[3] - c0;
  const std::vector<Eigen::Vector2d> route = route_polyline(s);
  double along_m = 0;
  for (std::size_t i = 0; i < route.size(); ++i) {
    const Eigen::Vector2d& p = route[i];
    if (i > 0) along_m += (p - route[i - 1]).norm();
    const double u = (p - c0).dot(eu) / eu.squaredNorm(), v = (p - c0).dot(ev) / ev.squaredNorm();
    if (u < 0 || u > 1 || v < 0 || v > 1)
      refuse("a route inside the plant (its blocks, their headlands and the aisles beside them)", p, along_m);
    for (int b = plant.first_array; b < plant.first_array + plant.blocks; ++b)
      if (in_a_table(s.pv_arrays[static_cast<std::size_t>(b)], p, kRouteTableClearanceM))
        refuse("a route that keeps " + format_number("%.2f m", kRouteTableClearanceM) +
                   " from every table (the robot's half width)", p, along_m);
  }
}

}  // namespace pvb::scenes::detail
