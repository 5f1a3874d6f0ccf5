#pragma once
// A whole plant as a plant designer describes it (the `plant:` section of a
// scenario): blocks of identical rows of one module, one mount and one
// table layout, separated by service roads, with a headland at the rows'
// ends and an inverter station per few megawatts.  lay_out_plant turns it
// into the arrays and inverter stations the scene is built from.  Each
// default is a published figure; scenes/SCHEMA.md names its source.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "pvb/scenes/scenario.hpp"

namespace pvb::scenes {

/// A 20-foot container skid: the inverter and its medium-voltage
/// transformer on one steel base (length along its long side, width, height).
inline constexpr double kInverterSkidLengthM = 6.06;
inline constexpr double kInverterSkidWidthM = 2.44;
inline constexpr double kInverterSkidHeightM = 2.90;

struct Plant {
  /// Front-left corner of the first block's first row, and the rows'
  /// direction (counter-clockwise from world x), as for an array.
  Eigen::Vector2d origin_m{0.0, 0.0};
  double azimuth_deg = 0.0;

  int cells = 144;              ///< the module: 144 half-cut cells (2.27 x 1.13 m) or 72 (1.96 x 0.99 m)
  double module_power_w = 580;  ///< its rated DC power (STC)

  Mount mount = Mount::kFixed;
  double tilt_deg = 25.0;  ///< fixed tables
  TrackerMount tracker;    ///< single_axis
  int modules_high = 2;    ///< modules across the table: 1P, 2P, ...
  PanelOrientation orientation = PanelOrientation::kPortrait;
  int modules_per_table = 28;  ///< modules along the row, per line
  int tables_per_row = 3;
  double table_gap_m = 1.0;
  double clearance_m = 0.6;
  /// The row pitch, resolved by the loader from `row_pitch_m` or from the
  /// ground coverage ratio (collector width over pitch, as pvlib defines it).
  double row_pitch_m = 0.0;

  int blocks = 1;        ///< blocks of rows
  int blocks_along = 1;  ///< blocks side by side along the rows; the rest stack across them
  int rows_per_block = 0;  ///< resolved by the loader from `rows` or `block_mwdc`
  double road_width_m = 4.0;  ///< the gravel service road between blocks
  double headland_m = 8.0;    ///< open ground between a block's row ends and the road
  /// An inverter station (a skid) per this much DC power of a block; 0: none.
  double inverter_mwdc = 2.0;

  double dirt = 0.2;
  bool specular_glass = false;
  bool identical_tables = false;
};

/// What lay_out_plant makes: one array per block (rows of tables in the
/// array frame of PvArray) and the inverter skids, as plaster boxes.
struct PlantLayout {
  std::vector<PvArray> blocks;
  std::vector<Wall> inverter_stations;
  long long modules = 0;
  double dc_mw = 0.0;
  double ground_coverage_ratio = 0.0;  ///< collector width over row pitch
  /// The plant's extent in the array frame (u along the rows, v across
  /// them): every block with its headlands, the aisle before the first row,
  /// and behind the last block line its road and skids, [u0, v0, u1, v1].
  Eigen::Vector4d extent_uv{0, 0, 0, 0};
  /// The same extent's corners in the world.
  std::vector<Eigen::Vector2d> corners_m;
};

/// The array a plant's blocks share (rows, origin and azimuth aside).
PvArray plant_block_array(const Plant& p);
/// The collector width: a fixed table's slope length, a tracker's width flat.
double plant_collector_width_m(const Plant& p);
/// Rows of one block that hold at least `mwdc` of DC power.
int rows_for_block_mwdc(const Plant& p, double mwdc);
/// The blocks, the skids and the plant's figures.
PlantLayout lay_out_plant(const Plant& p);

}  // namespace pvb::scenes
