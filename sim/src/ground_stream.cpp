#include "pvb/sim/ground_stream.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <string>
#include <utility>

#include "pvb/common/error.hpp"
#include "pvb/sim/textures.hpp"

namespace pvb::sim {

bool GroundStream::wanted(const scenes::Scenario& s, SceneDetail detail) {
  return detail == SceneDetail::kFull && s.ground.soil_images > 0 && s.ground.unique_within_m > 0 &&
         s.ground.drawn_tiling() == scenes::GroundTiling::kVaried;
}

GroundStream::GroundStream(mjModel* model, const scenes::Scenario& s)
    : model_(model), type_(s.ground.type), tiles_(ground_tiles(s)) {
  near_m_ = s.ground.unique_within_m + kGroundTileM / std::sqrt(2.0);
  tile_slot_.assign(tiles_.size(), -1);
  tile_near_.assign(tiles_.size(), 0);
  if (tiles_.empty()) return;
  // The tiles follow the ground's two planes, in ground_tiles order; on a
  // tiled relief they are height fields, the first one named.
  const int ground = mj_name2id(model, mjOBJ_GEOM, "ground");
  const int first_field = mj_name2id(model, mjOBJ_GEOM, (std::string(kReliefTilePrefix) + "0").c_str());
  first_far_geom_ = mj_name2id(model, mjOBJ_GEOM, (std::string(kReliefFarTilePrefix) + "0").c_str());
  first_tile_geom_ = first_field >= 0 ? first_field : ground + 2;
  const int type = first_field >= 0 ? mjGEOM_HFIELD : mjGEOM_PLANE;
  for (std::size_t k = 0; k < tiles_.size(); ++k) {
    const int g = first_tile_geom_ + static_cast<int>(k);
    const bool tile = (first_field >= 0 || ground >= 0) && g < model->ngeom && model->geom_type[g] == type &&
                      std::abs(model->geom_pos[3 * g] - tiles_[k].centre_m.x()) < 1e-6 &&
                      std::abs(model->geom_pos[3 * g + 1] - tiles_[k].centre_m.y()) < 1e-6;
    if (!tile) throw Error("the scene's ground tiles are not where its tile list puts tile " + std::to_string(k));
  }
  // The slots the scene has room for (build_scene): at most one for each
  // tile that can be near.
  for (int k = 0; k < unique_ground_slots(s.ground.unique_within_m); ++k) {
    const std::string name = kGroundSlotPrefix + std::to_string(k);
    const int id = mj_name2id(model, mjOBJ_TEXTURE, name.c_str());
    if (id < 0) break;
    if (model->tex_width[id] != kGroundTexturePx || model->tex_height[id] != kGroundTexturePx)
      throw Error("the scene's ground slot texture " + name + " is not " + std::to_string(kGroundTexturePx) + " px");
    slot_tex_.push_back(id);
  }
  if (slot_tex_.empty()) throw Error("the scene has no ground slot textures");
  slot_version_.assign(slot_tex_.size(), 0);
  slot_tile_.assign(slot_tex_.size(), -1);
  slot_used_.assign(slot_tex_.size(), 0);
}

int GroundStream::update(const Eigen::Vector3d& eye_w) {
  ++updates_;
  // The near tiles, nearest first; as many as there are slots (every one
  // where the scene had room for unique_ground_slots).
  std::vector<std::pair<double, int>> near;
  for (std::size_t k = 0; k < tiles_.size(); ++k) {
    const double d = (tiles_[k].centre_m - eye_w.head<2>()).norm();
    if (d <= near_m_) near.emplace_back(d, static_cast<int>(k));
  }
  std::sort(near.begin(), near.end());
  if (near.size() > slot_tex_.size()) near.resize(slot_tex_.size());
  std::fill(tile_near_.begin(), tile_near_.end(), 0);
  for (const auto& [d, k] : near) {
    tile_near_[static_cast<std::size_t>(k)] = 1;
    const int slot = tile_slot_[static_cast<std::size_t>(k)];
    if (slot >= 0) slot_used_[static_cast<std::size_t>(slot)] = updates_;
  }
  // Each near tile without its image takes the slot needed longest ago.
  std::vector<int> to_draw;
  for (const auto& [d, k] : near) {
    if (tile_slot_[static_cast<std::size_t>(k)] >= 0) continue;
    const auto oldest = std::min_element(slot_used_.begin(), slot_used_.end());
    const int slot = static_cast<int>(oldest - slot_used_.begin());
    const int before = slot_tile_[static_cast<std::size_t>(slot)];
    if (before >= 0) tile_slot_[static_cast<std::size_t>(before)] = -1;
    slot_tile_[static_cast<std::size_t>(slot)] = k;
    tile_slot_[static_cast<std::size_t>(k)] = slot;
    slot_used_[static_cast<std::size_t>(slot)] = updates_;
    to_draw.push_back(slot);
  }
  draw(to_draw);
  return static_cast<int>(to_draw.size());
}

void GroundStream::draw(const std::vector<int>& slots) {
  // Each image depends on its tile's seed alone: drawn on every core.
  cv::parallel_for_(cv::Range(0, static_cast<int>(slots.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const auto slot = static_cast<std::size_t>(slots[static_cast<std::size_t>(i)]);
      const GroundTile& t = tiles_[static_cast<std::size_t>(slot_tile_[slot])];
      const cv::Mat img = make_ground_texture(t.gravel ? scenes::GroundType::kGravel : type_, t.own_seed);
      const int tex = slot_tex_[slot];
      std::memcpy(model_->tex_rgb + model_->tex_adr[tex], img.data, img.total() * 3);
    }
  });
  for (int slot : slots) ++slot_version_[static_cast<std::size_t>(slot)];
  drawn_ += slots.size();
}

int GroundStream::texture_of_geom(int geom_id) const {
  const bool far = first_far_geom_ >= 0 && geom_id >= first_far_geom_;  // a relief tile's far version
  const int k = geom_id - (far ? first_far_geom_ : first_tile_geom_);
  if (first_tile_geom_ < 0 || k < 0 || k >= static_cast<int>(tiles_.size())) return -1;
  if (!tile_near_[static_cast<std::size_t>(k)]) return -1;
  return slot_tex_[static_cast<std::size_t>(tile_slot_[static_cast<std::size_t>(k)])];
}

std::vector<int> GroundStream::near_tiles() const {
  std::vector<int> out;
  for (std::size_t k = 0; k < tile_near_.size(); ++k)
    if (tile_near_[k]) out.push_back(static_cast<int>(k));
  return out;
}

}  // namespace pvb::sim
