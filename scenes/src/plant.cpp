#include "pvb/scenes/plant.hpp"

#include <cmath>

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

}  // namespace

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
  return out;
}

}  // namespace pvb::scenes
