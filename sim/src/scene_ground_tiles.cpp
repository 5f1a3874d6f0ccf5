// The tiles of a varied ground: which 3 m cells along the route are drawn,
// and the image each shows (its own, or a shared soil or gravel image at a
// quarter turn, with the seed of its own image near the camera).
#include <cmath>
#include <set>
#include <string>
#include <utility>

#include "pvb/common/error.hpp"
#include "pvb/scenes/route.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/textures.hpp"
#include "scene_mjcf.hpp"
#include "splitmix.hpp"

namespace pvb::sim {
namespace mjcf {

namespace {

/// Whether a point lies on one of a plant's service roads.
bool on_plant_road(const scenes::Scenario& s, const Eigen::Vector2d& p_m) {
  if (!s.plant) return false;
  const Eigen::Vector2d uv =
      scenes::world_to_array(s.pv_arrays[static_cast<std::size_t>(s.plant->first_array)], p_m);
  for (const Eigen::Vector4d& r : s.plant->roads_uv)
    if (uv.x() >= r[0] && uv.x() <= r[2] && uv.y() >= r[1] && uv.y() <= r[3]) return true;
  return false;
}

}  // namespace

std::vector<GroundTile> varied_ground_tiles(const scenes::Scenario& s, const std::vector<Eigen::Vector2d>& route) {
  if (s.ground.drawn_tiling() != scenes::GroundTiling::kVaried) return {};
  const double tile = kGroundTileM, half_x = s.ground.size_m.x() / 2, half_y = s.ground.size_m.y() / 2;
  const double reach = kGroundVariedCorridorM + tile / std::sqrt(2.0);
  const auto cells_x = static_cast<long long>(std::floor(s.ground.size_m.x() / tile + 1e-9));
  const auto cells_y = static_cast<long long>(std::floor(s.ground.size_m.y() / tile + 1e-9));
  const auto centre = [&](long long i, long long j) {
    return Eigen::Vector2d(-half_x + (static_cast<double>(i) + 0.5) * tile,
                           -half_y + (static_cast<double>(j) + 0.5) * tile);
  };
  // The cells within reach of each route point (a window of cells around it), in (i, j) order.
  std::set<std::pair<long long, long long>> cells;
  for (const Eigen::Vector2d& p : route) {
    const auto first = [&](double v, double half) { return static_cast<long long>(std::floor((v + half) / tile)); };
    const long long i0 = std::max(0LL, first(p.x() - reach, half_x));
    const long long i1 = std::min(cells_x - 1, first(p.x() + reach, half_x));
    const long long j0 = std::max(0LL, first(p.y() - reach, half_y));
    const long long j1 = std::min(cells_y - 1, first(p.y() + reach, half_y));
    for (long long i = i0; i <= i1; ++i)
      for (long long j = j0; j <= j1; ++j)
        if ((p - centre(i, j)).norm() <= reach) cells.insert({i, j});
  }
  const int images = s.ground.soil_images;
  if (images == 0 && cells.size() > static_cast<std::size_t>(kMaxGroundTiles))
    throw ConfigError(s.source_file, "ground.tiling",
                      "a varied ground (the default) of at most " + std::to_string(kMaxGroundTiles) + " tiles of " +
                          f(tile) + " m along the route (a route of about 55 m), ground.soil_images for a longer "
                          "one, or tiling: repeat",
                      std::to_string(cells.size()) + " tiles");
  if (cells.size() > static_cast<std::size_t>(kMaxSharedImageTiles))
    throw ConfigError(s.source_file, "ground.soil_images",
                      "a route whose varied ground takes at most " + std::to_string(kMaxSharedImageTiles) + " tiles",
                      std::to_string(cells.size()) + " tiles");
  std::vector<GroundTile> tiles;
  for (const auto& [i, j] : cells) {
    const auto cell = static_cast<std::uint64_t>(i * cells_y + j);
    GroundTile t{centre(i, j)};
    if (images > 0) {  // a shared image and a quarter turn, from the station and the cell alone
      SplitMix pick(s.station_seed_or_seed(), 0x711E0000ULL + cell);
      t.image = static_cast<int>(pick.next() % static_cast<std::uint64_t>(images));
      t.quarter_turns = static_cast<int>(pick.next() % 4);
      t.seed = shared_soil_image_seed(s.station_seed_or_seed(), t.image);
      t.own_seed = SplitMix(s.station_seed_or_seed(), 0x0A1E0000ULL + cell).next();
      if (on_plant_road(s, t.centre_m)) {
        t.gravel = true;  // gravel: one of the road's images
        SplitMix road(s.station_seed_or_seed(), 0x6A4E1000ULL + cell);
        t.image = images + static_cast<int>(road.next() % kRoadGravelImages);
        t.quarter_turns = static_cast<int>(road.next() % 4);
        t.seed = shared_soil_image_seed(s.station_seed_or_seed(), t.image);
      }
    } else {
      t.seed = s.station_seed_or_seed() * 2654435761ULL + 1000003ULL * (cell + 1);
    }
    tiles.push_back(t);
  }
  return tiles;
}

}  // namespace mjcf

std::vector<GroundTile> ground_tiles(const scenes::Scenario& s) {
  return mjcf::varied_ground_tiles(s, scenes::route_polyline(s));
}

std::uint64_t shared_soil_image_seed(std::uint64_t station_seed, int k) {
  return SplitMix(station_seed, 0x5011000ULL + static_cast<std::uint64_t>(k)).next();
}

}  // namespace pvb::sim
