#pragma once
// Soil without a repeat near the camera.  On a ground of shared soil images
// (ground.soil_images), every tile within ground.unique_within_m of the
// camera shows an image of its own instead of its shared one.  The image is
// drawn from the tile's seed when the camera nears the tile and held in one
// of a fixed number of slot textures (unique_ground_slots), so memory is
// bounded by the slots, not by the ground, and no two places of a route of
// any length look alike up close.
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/scene_builder.hpp"

namespace pvb::sim {

class GroundStream {
 public:
  /// Whether a scene of `s` built with `detail` streams its ground: shared
  /// soil images, unique_within_m > 0, colour textures, tiles along the route.
  static bool wanted(const scenes::Scenario& s, SceneDetail detail);

  /// For `model`, the compiled whole scene of `s` (build_scene with
  /// SceneDetail::kFull), whose slot textures it fills.  Throws Error when
  /// the model does not hold the scene's tiles and slots.
  GroundStream(mjModel* model, const scenes::Scenario& s);

  /// Gives every tile near `eye_w` (its centre within unique_within_m plus
  /// half a tile's diagonal, across the ground) its own image, drawing the
  /// images it lacks; the nearest ones where the scene had room for fewer
  /// slots than tiles can be near (kMaxSceneTextures).  A slot whose tile is no longer near keeps its image
  /// until a near tile needs the slot.  Which tiles show their own image
  /// depends on the eye alone, never on the eyes before it.  Returns how
  /// many images it drew.
  int update(const Eigen::Vector3d& eye_w);

  /// The texture model geom `geom_id` shows now instead of its material's
  /// (a near tile's slot, for the tile or its far version), or -1.
  int texture_of_geom(int geom_id) const;
  /// The slot textures, and how many times each was drawn: a renderer
  /// uploads a slot whose count changed since it last drew.
  const std::vector<int>& slot_textures() const { return slot_tex_; }
  const std::vector<std::uint64_t>& slot_versions() const { return slot_version_; }
  const mjModel* model() const { return model_; }
  /// The seed of the image tile k shows near the camera (ground_tiles order).
  std::uint64_t tile_seed(int k) const { return tiles_[static_cast<std::size_t>(k)].own_seed; }
  int tile_count() const { return static_cast<int>(tiles_.size()); }
  /// The tiles near the eye of the last update, in tile order.
  std::vector<int> near_tiles() const;
  /// Images drawn since construction.
  std::uint64_t images_drawn() const { return drawn_; }

 private:
  void draw(const std::vector<int>& slots);

  mjModel* model_;
  scenes::GroundType type_;
  std::vector<GroundTile> tiles_;
  int first_tile_geom_ = -1;
  int first_far_geom_ = -1;  ///< a tiled relief's first far tile (after the tiles), or -1
  double near_m_ = 0;
  std::vector<int> slot_tex_;
  std::vector<std::uint64_t> slot_version_;
  std::vector<int> slot_tile_;                ///< the tile whose image a slot holds, -1: none
  std::vector<std::uint64_t> slot_used_;      ///< the update that last needed the slot
  std::vector<int> tile_slot_;                ///< the slot holding a tile's image, -1: none
  std::vector<unsigned char> tile_near_;      ///< near the last update's eye
  std::uint64_t updates_ = 0;
  std::uint64_t drawn_ = 0;
};

}  // namespace pvb::sim
