#include "pvb/scenes/plant.hpp"

#include <cmath>
#include <cstdio>

#include "pvb/scenes/route.hpp"

namespace pvb::scenes {
namespace {

/// The inverter skids of one block: evenly spread along the row length in
/// their own strip beyond the road behind the block (v past the last
/// row's aisle and the road), their long side along the rows, half a metre
/// from the road.  No route through the block's aisles or headlands meets them.
void add_skids(const Plant& p, const PvArray& block, double block_dc_mw, PlantLayout* out) {
  if (p.inverter_mwdc <= 0) return;
  const int n = static_cast<int>(std::ceil(block_dc_mw / p.inverter_mwdc - 1e-9));
  const double v = block.rows * block.row_pitch_m + p.road_width_m + 0.5 + kInverterSkidWidthM / 2;
  const double row_len = row_length_m(block);
  for (int k = 0; k < n; ++k) {
    const double u = row_len * (k + 0.5) / n;
    Wall w;
    w.start_m = array_to_world(block, u - kInverterSkidLengthM / 2, v);
    w.end_m = array_to_world(block, u + kInverterSkidLengthM / 2, v);
    w.height_m = kInverterSkidHeightM;
    w.thickness_m = kInverterSkidWidthM;
    w.finish = WallFinish::kPlaster;
    out->inverter_stations.push_back(w);
  }
}

/// The centre of aisle k of a block (0: in front of the first row, rows:
/// behind the last), across the rows.
Fixture box(const PvArray& frame, double u, double v, const Eigen::Vector3d& size_m, double base_m,
            FixtureFinish finish) {
  Fixture f;
  f.centre_m = array_to_world(frame, u, v);
  f.yaw_deg = frame.azimuth_deg;
  f.size_m = size_m;
  f.base_m = base_m;
  f.finish = finish;
  return f;
}

/// A combiner box on its post past the east end of every combiner_rows-th
/// row of each block, its door to the headland.
void add_combiner_boxes(const Plant& p, PlantLayout* out) {
  if (p.combiner_rows <= 0) return;
  for (const PvArray& block : out->blocks) {
    const double u_post = row_length_m(block) + 0.35 + kCombinerPostM / 2;
    const double u_box = u_post + kCombinerPostM / 2 + kCombinerBoxAlongM / 2;
    for (int row = p.combiner_rows - 1; row < block.rows; row += p.combiner_rows) {
      const double v = row * block.row_pitch_m + row_footprint_m(block) / 2;
      out->fixtures.push_back(box(block, u_post, v, {kCombinerPostM, kCombinerPostM, kCombinerBoxBaseM + kCombinerBoxHighM},
                                  0.0, FixtureFinish::kSteel));
      out->fixtures.push_back(box(block, u_box, v, {kCombinerBoxAlongM, kCombinerBoxAcrossM, kCombinerBoxHighM},
                                  kCombinerBoxBaseM, FixtureFinish::kEnclosure));
    }
  }
}

/// A sign with the row's number past both ends of every row of every
/// block: "B<block> R<row>", counted from 1 in the order the blocks are laid.
void add_row_signs(const Plant& p, PlantLayout* out) {
  if (!p.row_signs) return;
  for (std::size_t b = 0; b < out->blocks.size(); ++b) {
    const PvArray& block = out->blocks[b];
    const double u_west = -kRowSignEndM - kRowSignPostM / 2, u_east = row_length_m(block) - u_west;
    for (int row = 0; row < block.rows; ++row) {
      const double v = row * block.row_pitch_m + row_footprint_m(block) / 2 - kRowSignAsideM;
      const int label = static_cast<int>(out->sign_labels.size());
      char text[48];  // "B" and 20 digits, " R" and 11: never cut
      std::snprintf(text, sizeof text, "B%zu R%03d", b + 1, row + 1);
      out->sign_labels.emplace_back(text);
      out->row_signs.push_back({array_to_world(block, u_west, v), block.azimuth_deg + 180.0, label});
      out->row_signs.push_back({array_to_world(block, u_east, v), block.azimuth_deg, label});
    }
  }
}

/// The dock in the first block's west headland, on its aisle's centre line:
/// a cabinet half a metre from the headland's outer edge, a canopy over it
/// on a post behind it.
void add_dock(const Plant& p, const PvArray& base, double aisle_m, PlantLayout* out) {
  if (!p.dock_aisle) return;
  const double v = *p.dock_aisle * base.row_pitch_m - aisle_m / 2;
  const double u_back = -p.headland_m + 0.5, u_cab = u_back + kDockCabinetAlongM / 2;
  out->fixtures.push_back(box(base, u_cab, v, {kDockCabinetAlongM, kDockCabinetAcrossM, kDockCabinetHighM}, 0.0,
                              FixtureFinish::kEnclosure));
  out->fixtures.push_back(box(base, u_back - kCombinerPostM / 2, v, {kCombinerPostM, kCombinerPostM, kDockCanopyBaseM},
                              0.0, FixtureFinish::kSteel));
  out->fixtures.push_back(box(base, u_back + kDockCanopyAlongM / 2 - kCombinerPostM, v,
                              {kDockCanopyAlongM, kDockCanopyAcrossM, 0.06}, kDockCanopyBaseM, FixtureFinish::kSteel));
  out->dock_front_u_m = u_back + kDockCabinetAlongM + kDockStandoffM;
  out->dock_v_m = v;
}

/// The service roads: between blocks along the rows, behind each line of
/// blocks, and (with a fence) around the plant, 1 m inside the fence; with
/// a fence also the loop of roads around each block.
void add_roads(const Plant& p, double stride_u, double stride_v, double rows_depth_m, int columns, int lines,
               PlantLayout* out) {
  const Eigen::Vector4d e = out->extent_uv;
  const double w = p.road_width_m;
  for (int c = 1; c < columns; ++c)
    out->roads_uv.emplace_back(c * stride_u - p.headland_m - w, e[1], c * stride_u - p.headland_m, e[3]);
  for (int l = 0; l < lines; ++l) out->roads_uv.emplace_back(e[0], l * stride_v + rows_depth_m, e[2], l * stride_v + rows_depth_m + w);
  if (!out->fence) return;
  const double a = 1.0, b = 1.0 + w;
  out->roads_uv.emplace_back(e[0] - b, e[1] - b, e[2] + b, e[1] - a);  // south
  out->roads_uv.emplace_back(e[0] - b, e[3] + a, e[2] + b, e[3] + b);  // north
  out->roads_uv.emplace_back(e[0] - b, e[1] - a, e[0] - a, e[3] + a);  // west
  out->roads_uv.emplace_back(e[2] + a, e[1] - a, e[2] + b, e[3] + a);  // east
  out->perimeter_road_m = 1.0 + w / 2;
  // Around each block: the perimeter road on the plant's edges, the roads
  // between blocks elsewhere (the road behind its line on the far side).
  const double d = out->perimeter_road_m;
  for (int k = 0; k < p.blocks; ++k) {
    const int c = k % p.blocks_along, l = k / p.blocks_along;
    const double west = c == 0 ? e[0] - d : c * stride_u - p.headland_m - w / 2;
    const double east = c == columns - 1 ? e[2] + d : (c + 1) * stride_u - p.headland_m - w / 2;
    const double south = l == 0 ? e[1] - d : (l - 1) * stride_v + rows_depth_m + w / 2;
    out->block_loops_uv.emplace_back(west, south, east, l * stride_v + rows_depth_m + w / 2);
  }
}

/// The fence around the extent at its setback, counter-clockwise, with a
/// gate wherever a road meets it and on the dock's aisle at both ends.
void add_fence(const Plant& p, const PvArray& base, double aisle_m, double stride_u, double stride_v, int columns,
               int lines, double rows_depth_m, PlantLayout* out) {
  if (!p.fence.on) return;
  const double sb = fence_setback_m(p);
  const Eigen::Vector4d e = out->extent_uv;
  const double u0 = e[0] - sb, v0 = e[1] - sb, u1 = e[2] + sb, v1 = e[3] + sb;
  Fence f;
  f.height_m = p.fence.height_m;
  f.post_spacing_m = p.fence.post_spacing_m;
  f.gate_width_m = p.fence.gate_width_m;
  for (const auto& [u, v] : {std::pair{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}})
    f.corners_m.push_back(array_to_world(base, u, v));
  const double v_main = p.dock_aisle.value_or(0) * base.row_pitch_m - aisle_m / 2;
  for (const double u : {u0, u1}) f.gates_m.push_back(array_to_world(base, u, v_main));
  for (int c = 1; c < columns; ++c)
    for (const double v : {v0, v1})
      f.gates_m.push_back(array_to_world(base, c * stride_u - p.headland_m - p.road_width_m / 2, v));
  for (int l = 0; l < lines; ++l)
    for (const double u : {u0, u1})
      f.gates_m.push_back(array_to_world(base, u, l * stride_v + rows_depth_m + p.road_width_m / 2));
  out->fence = f;
}

}  // namespace

double fence_setback_m(const Plant& p) {
  return p.fence.setback_m > 0 ? p.fence.setback_m : p.road_width_m + 2.0;
}

std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> fence_sections(const Fence& f) {
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> out;
  for (std::size_t i = 0; i < f.corners_m.size(); ++i) {
    const Eigen::Vector2d a = f.corners_m[i], b = f.corners_m[(i + 1) % f.corners_m.size()];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / kFenceSectionM - 1e-9)));
    for (int k = 0; k < n; ++k) out.emplace_back(a + (b - a) * (double(k) / n), a + (b - a) * (double(k + 1) / n));
  }
  return out;
}

PvArray plant_block_array(const Plant& p) {
  PvArray a;
  a.origin_m = p.origin_m;
  a.azimuth_deg = p.azimuth_deg;
  a.rows = p.rows_per_block;
  a.tables_per_row = p.tables_per_row;
  a.panels_per_table = p.modules_per_table;
  a.panel_lines = p.modules_high;
  a.orientation = p.orientation;
  a.cells = p.cells;
  a.mount = p.mount;
  a.tilt_deg = p.mount == Mount::kFixed ? p.tilt_deg : 0.0;
  a.rails = p.mount == Mount::kFixed;
  a.tracker = p.tracker;
  a.row_pitch_m = p.row_pitch_m;
  a.table_gap_m = p.table_gap_m;
  a.clearance_m = p.clearance_m;
  a.dirt = p.dirt;
  a.row_soiling = p.row_soiling;
  a.broken_modules = p.broken_modules;
  a.missing_modules = p.missing_modules;
  a.specular_glass = p.specular_glass;
  a.identical_tables = p.identical_tables;
  a.panel_slabs = true;
  return a;
}

double plant_collector_width_m(const Plant& p) { return plant_block_array(p).table_depth_m(); }

int rows_for_block_mwdc(const Plant& p, double mwdc) {
  const double row_w = static_cast<double>(p.tables_per_row) * p.modules_per_table * p.modules_high * p.module_power_w;
  return std::max(1, static_cast<int>(std::ceil(mwdc * 1e6 / row_w - 1e-9)));
}

PlantLayout lay_out_plant(const Plant& p) {
  PlantLayout out;
  const PvArray base = plant_block_array(p);
  const double row_len = row_length_m(base), footprint = row_footprint_m(base);
  const double aisle_m = base.row_pitch_m - footprint;
  const double stride_u = row_len + 2 * p.headland_m + p.road_width_m;
  // Behind a block: its last aisle, the road, the skids' strip, then the
  // next block's first aisle.
  const double strip_m = p.inverter_mwdc > 0 ? kInverterSkidWidthM + 1.0 : 0.0;
  const double stride_v = base.rows * base.row_pitch_m + p.road_width_m + strip_m + aisle_m;
  const long long modules_per_block =
      static_cast<long long>(base.rows) * p.tables_per_row * p.modules_per_table * p.modules_high;
  const double block_dc_mw = static_cast<double>(modules_per_block) * p.module_power_w / 1e6;
  const int lines = (p.blocks + p.blocks_along - 1) / p.blocks_along;
  for (int b = 0; b < p.blocks; ++b) {
    PvArray block = base;
    block.origin_m = array_to_world(base, (b % p.blocks_along) * stride_u, (b / p.blocks_along) * stride_v);
    add_skids(p, block, block_dc_mw, &out);
    out.blocks.push_back(block);
  }
  out.modules = modules_per_block * p.blocks;
  out.dc_mw = block_dc_mw * p.blocks;
  out.ground_coverage_ratio = base.table_depth_m() / base.row_pitch_m;
  const int columns = std::min(p.blocks, p.blocks_along);
  out.extent_uv = {-p.headland_m, -aisle_m, (columns - 1) * stride_u + row_len + p.headland_m,
                   (lines - 1) * stride_v + base.rows * base.row_pitch_m + p.road_width_m + strip_m};
  const Eigen::Vector4d& e = out.extent_uv;
  for (const auto& [u, v] : {std::pair{e[0], e[1]}, {e[2], e[1]}, {e[2], e[3]}, {e[0], e[3]}})
    out.corners_m.push_back(array_to_world(base, u, v));
  const double rows_depth_m = base.rows * base.row_pitch_m;
  add_fence(p, base, aisle_m, stride_u, stride_v, columns, lines, rows_depth_m, &out);
  add_roads(p, stride_u, stride_v, rows_depth_m, columns, lines, &out);
  add_dock(p, base, aisle_m, &out);
  add_combiner_boxes(p, &out);
  add_row_signs(p, &out);
  return out;
}

}  // namespace pvb::scenes
