// A relief under a varied ground: every tile along the route is a height
// field of its own, carrying its own image, and the rest of the ground is a
// coarse height field in pieces, drawn only where the camera looks.  The
// heights are filled in after MuJoCo compiles the scene (fill_relief_tiles),
// from one file beside scene.xml: a ground of any extent needs no file per
// tile and no grid over the whole plant.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <utility>

#include "pvb/common/error.hpp"
#include "pvb/sim/textures.hpp"
#include "scene_mjcf.hpp"

namespace pvb::sim {

static_assert(kGroundTileM == scenes::kReliefTileM, "a tiled relief's lattice divides the ground's tiles");

namespace mjcf {

namespace {

/// Backdrop pieces: this many 3 m cells along each side.
constexpr int kBackdropPieceCells = 16;
/// The backdrop lies this far below every tile over it, at least.
constexpr double kBackdropBelowTilesM = 0.005;

/// The lattice index of a tile's -x -y corner.
Eigen::Matrix<long long, 2, 1> corner_index(const scenes::Scenario& s, const scenes::GroundRelief& g,
                                            const Eigen::Vector2d& centre_m) {
  const double half_tile = kGroundTileM / 2;
  return {std::llround((centre_m.x() - half_tile + s.ground.size_m.x() / 2) / g.lattice_m()),
          std::llround((centre_m.y() - half_tile + s.ground.size_m.y() / 2) / g.lattice_m())};
}

/// Heights relative to the lowest one, scaled into [0, 1] as MuJoCo holds
/// them; the field's pos z, range and samples.
void normalise(const std::vector<double>& z_m, RuntimeHField* h) {
  const auto [lo, hi] = std::minmax_element(z_m.begin(), z_m.end());
  h->z0_m = *lo;
  h->range_m = std::max(*hi - *lo, 1e-6);  // MuJoCo: positive
  h->data.resize(z_m.size());
  for (std::size_t k = 0; k < z_m.size(); ++k) h->data[k] = static_cast<float>((z_m[k] - *lo) / h->range_m);
}

/// The cells along a tile's side of its far version: the largest divisor
/// of the lattice's cells a tile that is at most 3 (1 m cells at 0.25 m).
int far_cells_per_tile(const scenes::GroundRelief& g) {
  for (int d = 3; d > 1; --d)
    if (g.cells_per_tile() % d == 0) return d;
  return 1;
}

/// Tile `t`'s height field: the lattice's samples over the tile, every
/// `step`th, in the frame of its geom (turned by its quarter turns, so its
/// image turns too).
RuntimeHField tile_field(const scenes::Scenario& s, const scenes::GroundRelief& g, const GroundTile& t,
                         const std::string& name, int step, double* lowest_m) {
  const int n = g.cells_per_tile() / step;
  const Eigen::Matrix<long long, 2, 1> c0 = corner_index(s, g, t.centre_m);
  RuntimeHField h;
  h.name = name;
  h.nrow = h.ncol = n + 1;
  h.half_x_m = h.half_y_m = kGroundTileM / 2;
  h.centre_m = t.centre_m;
  h.quarter_turns = t.quarter_turns;
  std::vector<double> z(static_cast<std::size_t>(h.nrow * h.ncol));
  for (int r = 0; r <= n; ++r)
    for (int c = 0; c <= n; ++c) {
      // Local sample (c, r) lies at the world lattice point the turn takes it to.
      const int q = ((t.quarter_turns % 4) + 4) % 4;
      const int di = q == 0 ? c : q == 1 ? n - r : q == 2 ? n - c : r;
      const int dj = q == 0 ? r : q == 1 ? c : q == 2 ? n - r : n - c;
      z[static_cast<std::size_t>(r * h.ncol + c)] = g.sample_m(c0.x() + step * di, c0.y() + step * dj);
    }
  normalise(z, &h);
  *lowest_m = h.z0_m;
  return h;
}

/// The coarse backdrop: the lattice every 3 m in pieces of
/// kBackdropPieceCells cells, each sample kept at least
/// kBackdropBelowTilesM below the lowest sample of every tile it borders.
std::vector<RuntimeHField> backdrop_fields(
    const scenes::Scenario& s, const scenes::GroundRelief& g,
    const std::map<std::pair<long long, long long>, double>& tile_low_m) {
  const int n = g.cells_per_tile();
  const auto cells_x = static_cast<long long>(std::ceil(s.ground.size_m.x() / kGroundTileM - 1e-9));
  const auto cells_y = static_cast<long long>(std::ceil(s.ground.size_m.y() / kGroundTileM - 1e-9));
  const auto coarse = [&](long long i, long long j) {
    double z = g.sample_m(i * n, j * n);
    for (long long a = i - 1; a <= i; ++a)
      for (long long b = j - 1; b <= j; ++b) {
        const auto it = tile_low_m.find({a, b});
        if (it != tile_low_m.end()) z = std::min(z, it->second - kBackdropBelowTilesM);
      }
    return z;
  };
  std::vector<RuntimeHField> out;
  for (long long i0 = 0; i0 < cells_x; i0 += kBackdropPieceCells)
    for (long long j0 = 0; j0 < cells_y; j0 += kBackdropPieceCells) {
      const long long ni = std::min<long long>(kBackdropPieceCells, cells_x - i0);
      const long long nj = std::min<long long>(kBackdropPieceCells, cells_y - j0);
      RuntimeHField h;
      h.name = "groundfar" + std::to_string(out.size());
      h.nrow = static_cast<int>(nj + 1);
      h.ncol = static_cast<int>(ni + 1);
      h.half_x_m = static_cast<double>(ni) * kGroundTileM / 2;
      h.half_y_m = static_cast<double>(nj) * kGroundTileM / 2;
      h.centre_m = {-s.ground.size_m.x() / 2 + (static_cast<double>(i0) * kGroundTileM + h.half_x_m),
                    -s.ground.size_m.y() / 2 + (static_cast<double>(j0) * kGroundTileM + h.half_y_m)};
      std::vector<double> z;
      for (long long r = 0; r <= nj; ++r)
        for (long long c = 0; c <= ni; ++c) z.push_back(coarse(i0 + c, j0 + r));
      normalise(z, &h);
      out.push_back(std::move(h));
    }
  return out;
}

}  // namespace

ReliefTiles relief_tiles(const scenes::Scenario& s, const std::vector<GroundTile>& tiles,
                         const scenes::GroundRelief& ground) {
  ReliefTiles out;
  if (!ground.tiled()) return out;
  std::map<std::pair<long long, long long>, double> tile_low_m;  // by the tile's 3 m cell
  const int far_step = ground.cells_per_tile() / far_cells_per_tile(ground);
  for (std::size_t k = 0; k < tiles.size(); ++k) {
    double lowest = 0, far_lowest = 0;
    out.tiles.push_back(tile_field(s, ground, tiles[k], kReliefTilePrefix + std::to_string(k), 1, &lowest));
    out.far_tiles.push_back(
        tile_field(s, ground, tiles[k], kReliefFarTilePrefix + std::to_string(k), far_step, &far_lowest));
    const Eigen::Matrix<long long, 2, 1> c0 = corner_index(s, ground, tiles[k].centre_m);
    tile_low_m[{c0.x() / ground.cells_per_tile(), c0.y() / ground.cells_per_tile()}] = lowest;
  }
  out.backdrop = backdrop_fields(s, ground, tile_low_m);
  return out;
}

std::vector<unsigned char> relief_tiles_file(const ReliefTiles& r) {
  std::vector<unsigned char> out;
  const auto put = [&out](const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    out.insert(out.end(), b, b + n);
  };
  for (const auto* set : {&r.tiles, &r.far_tiles, &r.backdrop})
    for (const RuntimeHField& h : *set) {
      const std::int32_t head[3] = {static_cast<std::int32_t>(h.name.size()), h.nrow, h.ncol};
      put(head, sizeof head);
      put(h.name.data(), h.name.size());
      put(h.data.data(), h.data.size() * sizeof(float));
    }
  return out;
}

std::string hfield_asset_line(const RuntimeHField& h) {
  return "<hfield name=\"" + h.name + "\" nrow=\"" + std::to_string(h.nrow) + "\" ncol=\"" +
         std::to_string(h.ncol) + "\" size=\"" + exact(h.half_x_m) + " " + exact(h.half_y_m) + " " +
         exact(h.range_m) + " " + f(kReliefBaseM) + "\"/>";
}

void add_tiled_relief_ground(XmlWriter& x, const scenes::Scenario& s, const std::vector<GroundTile>& tiles,
                             const ReliefTiles& r) {
  for (const RuntimeHField& h : r.backdrop)
    x.line("<geom class=\"scenery\" type=\"hfield\" hfield=\"" + h.name + "\" pos=\"" + exact(h.centre_m.x()) +
           " " + exact(h.centre_m.y()) + " " + exact(h.z0_m) + "\" material=\"ground\"/>");
  // The tiles, collidable, then their far versions, scenery; the renderer
  // draws one of the two (Renderer::set_relief_detail_m).
  for (const auto* set : {&r.tiles, &r.far_tiles})
    for (std::size_t k = 0; k < set->size(); ++k) {
      const RuntimeHField& h = (*set)[k];
      const GroundTile& t = tiles[k];
      const std::string turn =
          t.quarter_turns > 0 ? "\" euler=\"0 0 " + std::to_string(90 * t.quarter_turns) : "";
      const std::string contact = set == &r.tiles ? "\" condim=\"3\" " + ground_friction(s.ground) : "\"";
      x.line("<geom name=\"" + h.name + "\"" + (set == &r.tiles ? "" : " class=\"scenery\"") +
             " type=\"hfield\" hfield=\"" + h.name + "\" pos=\"" + exact(h.centre_m.x()) + " " +
             exact(h.centre_m.y()) + " " + exact(h.z0_m) + turn + "\" material=\"groundt" +
             std::to_string(t.image >= 0 ? static_cast<std::size_t>(t.image) : k) + contact + "/>");
    }
}

}  // namespace mjcf

void fill_relief_tiles(mjModel* m, const std::vector<unsigned char>& file) {
  std::size_t at = 0;
  const auto take = [&](void* p, std::size_t n) {
    if (at + n > file.size()) throw Error(std::string(kReliefTilesFile) + ": ends inside a height field");
    std::memcpy(p, file.data() + at, n);
    at += n;
  };
  while (at < file.size()) {
    std::int32_t head[3];
    take(head, sizeof head);
    std::string name(static_cast<std::size_t>(std::max(head[0], 0)), '\0');
    take(name.data(), name.size());
    const int id = mj_name2id(m, mjOBJ_HFIELD, name.c_str());
    if (id < 0 || m->hfield_nrow[id] != head[1] || m->hfield_ncol[id] != head[2])
      throw Error(std::string(kReliefTilesFile) + ": the scene has no " + std::to_string(head[1]) + " x " +
                  std::to_string(head[2]) + " height field " + name);
    take(m->hfield_data + m->hfield_adr[id], static_cast<std::size_t>(head[1]) * head[2] * sizeof(float));
  }
  // MuJoCo 2.2.2 leaves a height field's bounding radius 0, and a geom of
  // radius 0 is tested against every other geom in every step; a tile's
  // sphere lets the collision filter skip the tiles far from the robot.
  for (int g = 0; g < m->ngeom; ++g)
    if (m->geom_type[g] == mjGEOM_HFIELD && m->geom_rbound[g] <= 0) m->geom_rbound[g] = hfield_bounding_radius(m, g);
}

double hfield_bounding_radius(const mjModel* m, int geom) {
  const mjtNum* s = m->hfield_size + 4 * m->geom_dataid[geom];
  return std::sqrt(s[0] * s[0] + s[1] * s[1] + std::max(s[2], s[3]) * std::max(s[2], s[3]));
}

}  // namespace pvb::sim
