#pragma once
// What a scenario's `plant:` section made, as the scenario keeps it
// (Scenario::plant): its figures, its extent and roads, the fence, the
// dock and the combiner boxes.  pvb/scenes/plant.hpp lays a plant out.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace pvb::scenes {

/// What a plant's fixtures are made of (a material of the scene each).
enum class FixtureFinish { kSteel, kEnclosure, kPlaster };

/// A box standing on the ground: the robot's dock, a combiner box and its
/// post.  Sizes are full sizes: along (the yaw's direction), across, high.
struct Fixture {
  Eigen::Vector2d centre_m{0.0, 0.0};
  double yaw_deg = 0.0;
  Eigen::Vector3d size_m{0.1, 0.1, 1.0};
  double base_m = 0.0;  ///< its bottom above the ground
  FixtureFinish finish = FixtureFinish::kSteel;
};

/// A row's number on a post at one of its ends: a plate facing out of the
/// row into the headland, the number on both faces (plant.hpp's kRowSign*).
struct RowSign {
  Eigen::Vector2d centre_m{0.0, 0.0};  ///< the post's foot
  double yaw_deg = 0.0;                ///< the direction the plate's front faces
  int label = 0;                       ///< its text in PlantSummary::sign_labels
};

/// A chain-link perimeter fence: posts and three wires along a closed
/// polygon, with gates (closed, a frame of tubes between heavier posts).
struct Fence {
  std::vector<Eigen::Vector2d> corners_m;  ///< the closed polygon, counter-clockwise
  double height_m = 2.0;
  double post_spacing_m = 3.0;
  double gate_width_m = 6.0;
  std::vector<Eigen::Vector2d> gates_m;  ///< each gate's centre, on the polygon
};

/// What a `plant:` section made (pvb/scenes/plant.hpp): its blocks are the
/// scenario's last `pv_arrays`, its inverter stations its last `walls`.
struct PlantSummary {
  int first_array = 0;  ///< the index of the first block in pv_arrays
  int blocks = 0;
  int rows_per_block = 0;
  long long modules = 0;
  double dc_mw = 0.0;
  double ground_coverage_ratio = 0.0;
  double row_pitch_m = 0.0;
  int inverter_stations = 0;
  std::vector<Eigen::Vector2d> corners_m;  ///< the plant's extent, headlands included
  /// The same extent in the first block's array frame, [u0, v0, u1, v1].
  Eigen::Vector4d extent_uv{0, 0, 0, 0};
  double road_width_m = 4.0;
  /// Where the perimeter road's centre line runs, beyond the extent (0: no
  /// fence, no perimeter road).
  double perimeter_road_m = 0.0;
  std::optional<Fence> fence;
  std::vector<Fixture> fixtures;  ///< the dock and the combiner boxes
  std::vector<RowSign> row_signs;        ///< two a row, one at each end (plant.row_signs)
  std::vector<std::string> sign_labels;  ///< a row's "B<block> R<row>", from 1, block by block
  /// The aisle of the first block whose west end holds the dock, and where
  /// the robot stands in front of it (u in the first block's frame).
  std::optional<int> dock_aisle;
  double dock_front_u_m = 0.0;
  double dock_v_m = 0.0;  ///< the dock's centre across the rows (first block's frame)
  /// In each block: how many aisles have tyre tracks, how many rows a
  /// strip of grass (plant.tyre_tracks, plant.vegetation_strips).
  int tracked_aisles = 0;
  int grass_rows = 0;
  std::vector<Eigen::Vector4d> roads_uv;  ///< the service roads, [u0, v0, u1, v1] in the first block's frame
  /// With a fence: the road centre lines around each block (PlantLayout).
  std::vector<Eigen::Vector4d> block_loops_uv;
};

}  // namespace pvb::scenes
