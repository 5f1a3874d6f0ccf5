#pragma once
// A whole plant as a plant designer describes it (the `plant:` section of a
// scenario): blocks of identical rows of one module, one mount and one
// table layout, separated by service roads, with a headland at the rows'
// ends and an inverter station per few megawatts.  lay_out_plant turns it
// into the arrays and inverter stations the scene is built from.  Each
// default is a published figure; scenes/SCHEMA.md names its source.
#include <Eigen/Core>
#include <optional>
#include <utility>
#include <vector>

#include "pvb/scenes/scenario.hpp"

namespace pvb::scenes {

/// A 20-foot container skid: the inverter and its medium-voltage
/// transformer on one steel base (length along its long side, width, height).
inline constexpr double kInverterSkidLengthM = 6.06;
inline constexpr double kInverterSkidWidthM = 2.44;
inline constexpr double kInverterSkidHeightM = 2.90;

/// A chain-link fence's figures, and gates (a gate is an opening, closed
/// by a gate of tubes).
struct PlantFence {
  bool on = true;
  /// From the plant's extent to the fence; the perimeter road (road_width_m)
  /// runs in between, 1 m from each.  0: road_width_m + 2.
  double setback_m = 0.0;
  double height_m = 2.0;        ///< 2 m chain link (utility plants: 1.8-2.4 m)
  double post_spacing_m = 3.0;  ///< line posts every 3 m (10 ft)
  double gate_width_m = 6.0;    ///< a double gate a truck passes
};

/// A string combiner box on its own post, past a row's east end.
inline constexpr double kCombinerBoxAlongM = 0.25, kCombinerBoxAcrossM = 0.60, kCombinerBoxHighM = 0.50;
inline constexpr double kCombinerBoxBaseM = 0.70, kCombinerPostM = 0.08;
/// A row sign: a post kRowSignEndM past each end of a row, kRowSignAsideM
/// from the row's centre line towards its front (clear of a combiner box),
/// and a plate across the row on it, its foot kRowSignPlateBaseM up.
inline constexpr double kRowSignEndM = 0.35, kRowSignAsideM = 0.6, kRowSignPostM = 0.05, kRowSignPostHighM = 1.1;
inline constexpr double kRowSignPlateWideM = 0.30, kRowSignPlateHighM = 0.20, kRowSignPlateThickM = 0.012;
inline constexpr double kRowSignPlateBaseM = 0.85;
/// Tyre tracks in an aisle: two bands of compacted soil kTrackWidthM wide,
/// kTrackGaugeM apart (a service vehicle's), on the aisle's centre line
/// along the rows.  A strip of grass under a row: kGrassStripShare of the
/// row's footprint wide, on its centre line.  Both lie kGroundCoverM above
/// the soil, along the rows' length.
inline constexpr double kTrackWidthM = 0.35, kTrackGaugeM = 1.6, kGrassStripShare = 0.6, kGroundCoverM = 0.004;
/// The dock: a charging cabinet (along the rows x across x high) under a
/// canopy; the robot stands kDockStandoffM in front of the cabinet.
inline constexpr double kDockCabinetAlongM = 0.8, kDockCabinetAcrossM = 1.2, kDockCabinetHighM = 1.1;
inline constexpr double kDockCanopyAlongM = 1.6, kDockCanopyAcrossM = 2.0, kDockCanopyBaseM = 2.1;
inline constexpr double kDockStandoffM = 2.0;

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

  PlantFence fence;
  /// The aisle (of the first block) at whose west end the dock stands; none: no dock.
  std::optional<int> dock_aisle = 0;
  /// A combiner box past the east end of every this many rows; 0: none.
  int combiner_rows = 6;
  /// A sign with the row's number at both ends of every row.
  bool row_signs = true;
  /// The share of each block's aisles with tyre tracks, and of its rows
  /// with a strip of grass under them, which ones from the station's seed.
  double tyre_tracks = 0.0;
  double vegetation_strips = 0.0;

  double dirt = 0.2;
  double row_soiling = 0.0;  ///< the spread of the rows' dust (PvArray::row_soiling); 0: rows alike
  int broken_modules = 0;    ///< modules shown broken in each block (PvArray::broken_modules)
  int missing_modules = 0;   ///< modules gone from each block (PvArray::missing_modules)
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
  /// The perimeter road's centre line beyond the extent, and the fence (none
  /// when the plant has no fence).
  double perimeter_road_m = 0.0;
  std::optional<Fence> fence;
  std::vector<Fixture> fixtures;  ///< the dock and the combiner boxes
  std::vector<RowSign> row_signs;        ///< two a row (Plant::row_signs)
  std::vector<std::string> sign_labels;  ///< their texts, a row's each
  double dock_front_u_m = 0.0;    ///< where the robot stands at the dock (u, first block's frame)
  double dock_v_m = 0.0;          ///< the dock's centre across the rows
  /// Where a service road runs (rectangles [u0, v0, u1, v1] in the first
  /// block's frame): between blocks, behind each line of blocks, around the
  /// plant inside the fence.
  std::vector<Eigen::Vector4d> roads_uv;
  /// With a fence: for each block, the centre lines of the roads around
  /// it, as a rectangle [u0, v0, u1, v1] in the first block's frame (the
  /// perimeter road where the block lies at the plant's edge, else the road
  /// between it and its neighbour).
  std::vector<Eigen::Vector4d> block_loops_uv;
};

/// The array a plant's blocks share (rows, origin and azimuth aside).
PvArray plant_block_array(const Plant& p);
/// The collector width: a fixed table's slope length, a tracker's width flat.
double plant_collector_width_m(const Plant& p);
/// Rows of one block that hold at least `mwdc` of DC power.
int rows_for_block_mwdc(const Plant& p, double mwdc);
/// The fence's setback from the extent (its default resolved).
double fence_setback_m(const Plant& p);
/// A fence is drawn in straight sections of at most this length (one geom
/// each, so that the view cull can leave out the ones not in view).
inline constexpr double kFenceSectionM = 40.0;
/// The fence's sections, [start, end] in the world.
std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> fence_sections(const Fence& f);
/// The blocks, the skids, the fence, the dock, the combiner boxes and the
/// plant's figures.
PlantLayout lay_out_plant(const Plant& p);

}  // namespace pvb::scenes
