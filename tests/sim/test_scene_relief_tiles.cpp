#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/ground_stream.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/sim/textures.hpp"
#include "pvb/sim/truth_surface.hpp"

using namespace pvb;

namespace {

/// rough_station with a varied soil: its relief drawn tile by tile.
scenes::Scenario rough_varied(int soil_images) {
  scenes::Scenario s = scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/rough_station.yaml");
  s.ground.tiling = scenes::GroundTiling::kVaried;
  s.ground.soil_images = soil_images;
  return s;
}

/// A scenario's relief, tiles and compiled scene, its data forwarded.
struct Compiled {
  explicit Compiled(const scenes::Scenario& s)
      : relief(s),
        tiles(sim::ground_tiles(s)),
        m(sim::compile_scene(sim::build_scene(s))),
        d(mj_makeData(m.get())) {
    mj_forward(m.get(), d.get());
  }
  scenes::GroundRelief relief;
  std::vector<sim::GroundTile> tiles;
  sim::ModelPtr m;
  sim::DataPtr d;
};

/// Where a ray cast down from 10 m above (x, y) meets geom `g` (NaN: misses).
double ray_down(const mjModel* m, const mjData* d, int g, double x, double y) {
  const mjtNum from[3] = {x, y, 10.0}, down[3] = {0, 0, -1};
  const mjtNum dist = mj_rayHfield(m, d, g, from, down);
  return dist < 0 ? std::nan("") : 10.0 - dist;
}

/// How far MuJoCo's split of lattice cell (i, j) along the other diagonal
/// can lie from GroundRelief's: half the cell's twist.
double split_bound_m(const scenes::GroundRelief& g, long long i, long long j) {
  return 0.5 *
         std::abs(g.sample_m(i, j) + g.sample_m(i + 1, j + 1) - g.sample_m(i + 1, j) - g.sample_m(i, j + 1));
}

}  // namespace

// Every tile along the route is a height field of its own whose surface is
// GroundRelief's: exactly where the tile lies unturned, and within the
// other diagonal split of its cells where a quarter turn (an odd one)
// turns MuJoCo's triangles.  The true surface's normals are the tiles'.
TEST(SceneReliefTiles, EveryTileIsAHeightFieldThatMujocoAgreesWith) {
  for (const int images : {0, 6}) {
    const scenes::Scenario s = rough_varied(images);
    const scenes::GroundRelief relief(s);
    ASSERT_TRUE(relief.tiled());
    const std::vector<sim::GroundTile> tiles = sim::ground_tiles(s);
    ASSERT_GT(tiles.size(), 20u);
    const sim::ModelPtr m = sim::compile_scene(sim::build_scene(s));
    sim::DataPtr d(mj_makeData(m.get()));
    mj_forward(m.get(), d.get());
    std::mt19937_64 rng(20261203 + images);
    std::uniform_real_distribution<double> u(-1.45, 1.45);
    double worst_even = 0, worst_odd_over_bound = -1;
    int odd = 0;
    for (std::size_t k = 0; k < tiles.size(); ++k) {
      const int g = mj_name2id(m.get(), mjOBJ_GEOM, ("groundtile" + std::to_string(k)).c_str());
      ASSERT_GE(g, 0) << k;
      ASSERT_EQ(m->geom_type[g], mjGEOM_HFIELD);
      odd += tiles[k].quarter_turns % 2;
      for (int n = 0; n < 8; ++n) {
        const double x = tiles[k].centre_m.x() + u(rng), y = tiles[k].centre_m.y() + u(rng);
        const double z = ray_down(m.get(), d.get(), g, x, y);
        ASSERT_FALSE(std::isnan(z)) << k << " " << x << " " << y;
        const double err = std::abs(z - relief.height_m(x, y));
        if (tiles[k].quarter_turns % 2 == 0) {
          worst_even = std::max(worst_even, err);
          const Eigen::Vector3d p(x, y, z);
          EXPECT_LT(
              (sim::geom_normal(m.get(), d.get(), g, p, p + Eigen::Vector3d::UnitZ()) - relief.normal(x, y))
                  .norm(),
              1e-3);
        } else {
          const auto i =
              static_cast<long long>(std::floor((x + s.ground.size_m.x() / 2) / relief.lattice_m()));
          const auto j =
              static_cast<long long>(std::floor((y + s.ground.size_m.y() / 2) / relief.lattice_m()));
          worst_odd_over_bound = std::max(worst_odd_over_bound, err - split_bound_m(relief, i, j));
        }
      }
    }
    EXPECT_LT(worst_even, 1e-4) << images;  // within 0.1 mm (MuJoCo keeps the samples as floats)
    if (images == 0) {
      EXPECT_EQ(odd, 0);  // an image of its own lies unturned
    } else {
      EXPECT_GT(odd, 5);
      EXPECT_LT(worst_odd_over_bound, 1e-4);
    }
  }
}

// Each tile has a far version of 1 m cells, scenery, on the same lattice:
// at the tile's corners both lie on the field.
TEST(SceneReliefTiles, EachTileHasAFarVersionOnTheSameLattice) {
  const scenes::Scenario s = rough_varied(6);
  const Compiled c(s);
  const scenes::GroundRelief& relief = c.relief;
  const std::vector<sim::GroundTile>& tiles = c.tiles;
  const mjModel* m = c.m.get();
  mjData* d = c.d.get();
  for (std::size_t k = 0; k < tiles.size(); ++k) {
    const int g = mj_name2id(m, mjOBJ_GEOM, (sim::kReliefFarTilePrefix + std::to_string(k)).c_str());
    ASSERT_GE(g, 0) << k;
    EXPECT_EQ(m->hfield_nrow[m->geom_dataid[g]], 4);  // 3 cells of 1 m
    EXPECT_EQ(m->geom_contype[g], 0);
    EXPECT_EQ(m->geom_matid[g],
              m->geom_matid[mj_name2id(m, mjOBJ_GEOM, (sim::kReliefTilePrefix + std::to_string(k)).c_str())]);
    for (const double cx : {-1.499, 1.499})
      for (const double cy : {-1.499, 1.499}) {
        const double x = tiles[k].centre_m.x() + cx, y = tiles[k].centre_m.y() + cy;
        EXPECT_NEAR(ray_down(m, d, g, x, y), relief.height_m(x, y), 2e-3) << k;
      }
  }
}

// The backdrop, the rest of the ground in coarse pieces, lies at least
// 5 mm under every tile, and away from the tiles on the field itself.
TEST(SceneReliefTiles, TheBackdropLiesUnderTheTilesAndOnTheFieldBeyond) {
  const scenes::Scenario s = rough_varied(0);
  const Compiled c(s);
  const std::vector<sim::GroundTile>& tiles = c.tiles;
  const mjModel* m = c.m.get();
  mjData* d = c.d.get();
  const int ground_mat = mj_name2id(m, mjOBJ_MATERIAL, "ground");
  std::vector<int> pieces;
  for (int g = 0; g < m->ngeom; ++g)
    if (m->geom_type[g] == mjGEOM_HFIELD && m->geom_matid[g] == ground_mat) pieces.push_back(g);
  ASSERT_FALSE(pieces.empty());
  const auto backdrop = [&](double x, double y) {
    for (int g : pieces) {
      const double z = ray_down(m, d, g, x, y);
      if (!std::isnan(z)) return z;
    }
    return std::nan("");
  };
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  double closest = 1e9;
  for (const sim::GroundTile& t : tiles)
    for (int n = 0; n < 8; ++n) {
      const double x = t.centre_m.x() + u(rng), y = t.centre_m.y() + u(rng);
      const double below = c.relief.height_m(x, y) - backdrop(x, y);
      ASSERT_FALSE(std::isnan(below)) << x << " " << y;
      closest = std::min(closest, below);
    }
  EXPECT_GT(closest, 0.005 - 1e-4);
  // Far from the route, at the 3 m lattice's points, the backdrop is the field.
  const int n = c.relief.cells_per_tile();
  int far_points = 0;
  for (long long i = 1; i < 20; i += 3)
    for (long long j = 1; j < 13; j += 3) {
      const Eigen::Vector2d p(-s.ground.size_m.x() / 2 + i * 3.0, -s.ground.size_m.y() / 2 + j * 3.0);
      const bool near = std::any_of(tiles.begin(), tiles.end(), [&](const sim::GroundTile& t) {
        return (t.centre_m - p).cwiseAbs().maxCoeff() < 3.0;
      });
      if (near) continue;
      ++far_points;
      EXPECT_NEAR(backdrop(p.x() + 1e-6, p.y() + 1e-6), c.relief.sample_m(i * n, j * n), 1e-4)
          << p.transpose();
    }
  EXPECT_GT(far_points, 10);
}

// The robot drives the tiles as it drives the one height field of the same
// relief under a repeated soil: after 3 s its camera is within 1 mm and
// 0.05 degrees of where it is there (0.1 mm and 0.005 degrees when written).
TEST(SceneReliefTiles, TheRobotDrivesTheTilesAsTheOneHeightField) {
  scenes::Scenario repeated =
      scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/rough_station.yaml");
  sim::Simulator tiled(rough_varied(0), sim::SceneDetail::kGeometry),
      one(repeated, sim::SceneDetail::kGeometry);
  const geom::SE3d start = one.T_w_c();
  for (int i = 0; i < 90; ++i) {
    tiled.advance();
    one.advance();
  }
  const geom::SE3d a = tiled.T_w_c(), b = one.T_w_c();
  EXPECT_GT(b.translation().z(), 0.3);  // on the relief, not fallen through it
  EXPECT_LT((a.translation() - b.translation()).norm(), 0.001)
      << (a.translation() - b.translation()).transpose();
  EXPECT_GT((b.translation() - start.translation()).norm(), 0.5);  // it drove
  const double angle_deg = Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180 / M_PI;
  EXPECT_LT(angle_deg, 0.05) << angle_deg;
}

// The near tiles take their own images on a tiled relief as on flat ground.
TEST(SceneReliefTiles, NearTilesShowTheirOwnImages) {
  scenes::Scenario s = rough_varied(6);
  s.ground.unique_within_m = 6;
  const sim::SceneAssets a = sim::build_scene(s);
  const sim::ModelPtr m = sim::compile_scene(a);
  ASSERT_TRUE(sim::GroundStream::wanted(s, a.detail));
  sim::GroundStream stream(m.get(), s);
  const sim::GroundTile t = sim::ground_tiles(s).front();
  EXPECT_GT(stream.update(Eigen::Vector3d(t.centre_m.x(), t.centre_m.y(), 0.5)), 0);
  EXPECT_GE(stream.texture_of_geom(mj_name2id(m.get(), mjOBJ_GEOM, "groundtile0")), 0);
}
