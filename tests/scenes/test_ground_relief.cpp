// The ground relief: made from the station's seed, interpolated as MuJoCo
// interpolates a height field, with the roughness and slope asked for; and
// the errors of its keys, by file, line and key.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/route.hpp"
#include "pvb/scenes/scenario.hpp"

using namespace pvb::scenes;
namespace fs = std::filesystem;

namespace {

const std::string kReliefScenes = std::string(PVB_SOURCE_DIR) + "/scenes/";

const char* kReliefStation =
    "name: station\nseed: 7\n"
    "pv_arrays:\n  - {rows: 2, tables_per_row: 2, panels_per_table: 4}\n"
    "route: {pattern: along_row, aisle: 1}\n";

std::string relief_error(const std::string& yaml) {
  try {
    parse_scenario(yaml, "bad.yaml");
  } catch (const pvb::ConfigError& e) {
    return e.what();
  }
  return "";
}

/// A day file over a station file, both written to a fresh folder.
std::string relief_day_error(const std::string& name, const std::string& station, const std::string& day) {
  const std::string dir = ::testing::TempDir() + "pvb_relief_" + name + "_" + std::to_string(::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  pvb::write_file(dir + "/station.yaml", station);
  pvb::write_file(dir + "/day.yaml", day);
  try {
    load_scenario(dir + "/day.yaml");
  } catch (const pvb::ConfigError& e) {
    return e.what();
  }
  return "";
}

Relief make_relief(double amplitude_cm, double slope_percent) {
  Relief r;
  r.amplitude_cm = amplitude_cm;
  r.scale_m = 1.0;
  r.slope_percent = slope_percent;
  r.slope_azimuth_deg = 30;
  r.cell_m = 0.2;
  return r;
}

}  // namespace

// Every day of a station stands on the same relief; another station seed
// gives another.
TEST(GroundRelief, IsTheStationsAndTheSameOnEveryDay) {
  const Scenario station = load_scenario(kReliefScenes + "rough_station.yaml");
  const Scenario dry = load_scenario(kReliefScenes + "days/rough_station_dry.yaml");
  const Scenario wet = load_scenario(kReliefScenes + "days/rough_station_wet.yaml");
  ASSERT_TRUE(station.ground.relief);
  ASSERT_NE(dry.seed, wet.seed);
  const GroundRelief a(station), b(dry), c(wet);
  ASSERT_FALSE(a.flat());
  EXPECT_EQ(a.grid().z_m, b.grid().z_m);
  EXPECT_EQ(a.grid().z_m, c.grid().z_m);
  EXPECT_EQ(GroundRelief(station).grid().z_m, a.grid().z_m);  // deterministic
  Scenario other = station;
  other.station_seed = 8;
  const GroundRelief d(other);
  double largest = 0;
  for (std::size_t i = 0; i < a.grid().z_m.size(); ++i)
    largest = std::max(largest, std::abs(a.grid().z_m[i] - d.grid().z_m[i]));
  EXPECT_GT(largest, 0.02);
  // Without a relief the ground is the plane z = 0.
  const GroundRelief flat(load_scenario(kReliefScenes + "pv_station.yaml"));
  EXPECT_TRUE(flat.flat());
  EXPECT_EQ(flat.height_m(3.0, -2.0), 0.0);
  EXPECT_EQ(flat.normal(3.0, -2.0), Eigen::Vector3d::UnitZ());
}

// Between samples the height is MuJoCo's: two flat triangles per cell,
// split along the diagonal from (c, r) to (c + 1, r + 1).
TEST(GroundRelief, HeightFollowsMujocosTriangles) {
  const GroundRelief g(make_relief(3.0, 2.0), Eigen::Vector2d(6, 4), 5);
  const HeightGrid& h = g.grid();
  ASSERT_EQ(h.ncol, 31);
  ASSERT_EQ(h.nrow, 21);
  const double d = 0.2;
  const auto z = [&](int r, int c) { return h.z_m[static_cast<std::size_t>(r * h.ncol + c)]; };
  const int r = 7, c = 11;
  const double x0 = -3 + c * d, y0 = -2 + r * d;
  EXPECT_NEAR(g.height_m(x0, y0), z(r, c), 1e-12);
  EXPECT_NEAR(g.height_m(x0 + d, y0 + d), z(r + 1, c + 1), 1e-12);
  // Below the diagonal: the plane through (c, r), (c + 1, r), (c + 1, r + 1).
  const double fx = 0.7, fy = 0.2;
  const double below = z(r, c) + fx * (z(r, c + 1) - z(r, c)) + fy * (z(r + 1, c + 1) - z(r, c + 1));
  EXPECT_NEAR(g.height_m(x0 + fx * d, y0 + fy * d), below, 1e-12);
  // Above it (x fraction fy, y fraction fx): the plane through (c, r), (c, r + 1), (c + 1, r + 1).
  const double above = z(r, c) + fx * (z(r + 1, c) - z(r, c)) + fy * (z(r + 1, c + 1) - z(r + 1, c));
  EXPECT_NEAR(g.height_m(x0 + fy * d, y0 + fx * d), above, 1e-12);
  // The normal is the triangle's: perpendicular to two of its edges.
  const Eigen::Vector3d n = g.normal(x0 + fx * d, y0 + fy * d);
  EXPECT_NEAR(n.norm(), 1.0, 1e-12);
  EXPECT_NEAR(n.dot(Eigen::Vector3d(d, 0, z(r, c + 1) - z(r, c))), 0.0, 1e-12);
  EXPECT_NEAR(n.dot(Eigen::Vector3d(0, d, z(r + 1, c + 1) - z(r, c + 1))), 0.0, 1e-12);
  EXPECT_GT(n.z(), 0.9);
  // Outside the grid: the nearest edge.
  EXPECT_NEAR(g.height_m(10.0, y0), z(r, h.ncol - 1), 1e-12);
}

// Under a varied soil the relief is the same field, sampled where asked
// on a lattice from the ground's corner whose spacing divides a 3 m tile:
// where that lattice is the grid's (0.2 m cells on 6 m x 4 m: 15 to a
// tile), heights and normals are the grid's.  Its samples reach past the
// ground's edge, where the grid's stop.
TEST(GroundRelief, TiledIsTheGridsFieldOnTheSameLattice) {
  const GroundRelief grid(make_relief(3.0, 2.0), Eigen::Vector2d(6, 4), 5);
  const GroundRelief tiled(make_relief(3.0, 2.0), Eigen::Vector2d(6, 4), 5, true);
  ASSERT_TRUE(tiled.tiled());
  ASSERT_FALSE(grid.tiled());
  EXPECT_TRUE(tiled.grid().z_m.empty());
  EXPECT_EQ(tiled.cells_per_tile(), 15);
  EXPECT_NEAR(tiled.lattice_m(), 0.2, 1e-12);
  for (int k = 0; k < 200; ++k) {
    // Off the cells' diagonals, where either triangle's normal is the surface's.
    const double x = -2.9 + 5.8 * std::fmod(k * 0.6180339887, 1.0),
                 y = -1.9 + 3.8 * std::fmod(k * 0.4142135624, 1.0);
    EXPECT_NEAR(tiled.height_m(x, y), grid.height_m(x, y), 1e-12) << x << " " << y;
    EXPECT_LT((tiled.normal(x, y) - grid.normal(x, y)).norm(), 1e-9) << x << " " << y;
  }
  EXPECT_NEAR(tiled.sample_m(4, 3), grid.grid().z_m[static_cast<std::size_t>(3 * grid.grid().ncol + 4)],
              1e-12);
  // A cell of 0.4 m does not divide 3 m: the lattice takes 8 cells of 0.375 m.
  Relief coarse = make_relief(3.0, 2.0);
  coarse.cell_m = 0.4;
  const GroundRelief wide(coarse, Eigen::Vector2d(2000, 2000), 5, true);
  EXPECT_EQ(wide.cells_per_tile(), 8);
  EXPECT_NEAR(wide.lattice_m(), 0.375, 1e-12);
  EXPECT_FALSE(std::isnan(wide.height_m(999.9, -999.9)));
}

// The roughness has the standard deviation and correlation length asked
// for, the plane the slope and direction.
TEST(GroundRelief, HasTheRoughnessAndSlopeAsked) {
  const GroundRelief rough(make_relief(2.0, 0.0), Eigen::Vector2d(60, 60), 3);
  const HeightGrid& h = rough.grid();
  double sum = 0, sum2 = 0, lag1 = 0, lag4 = 0;
  int pairs = 0;
  for (int r = 0; r < h.nrow; ++r)
    for (int c = 0; c + 20 < h.ncol; ++c) {
      const double z = h.z_m[static_cast<std::size_t>(r * h.ncol + c)];
      sum += z;
      sum2 += z * z;
      lag1 += z * h.z_m[static_cast<std::size_t>(r * h.ncol + c + 5)];   // 1 m
      lag4 += z * h.z_m[static_cast<std::size_t>(r * h.ncol + c + 20)];  // 4 m
      ++pairs;
    }
  const double mean = sum / pairs, var = sum2 / pairs - mean * mean;
  EXPECT_NEAR(std::sqrt(var), 0.02, 0.006);
  EXPECT_NEAR(lag1 / pairs / var, std::exp(-0.5), 0.15);  // exp(-r^2 / (2 scale^2)) at r = scale
  EXPECT_LT(std::abs(lag4 / pairs / var), 0.25);
  const GroundRelief plane(make_relief(0.0, 3.0), Eigen::Vector2d(60, 60), 3);
  const double az = 30 * M_PI / 180;
  EXPECT_NEAR(plane.height_m(10 * std::cos(az), 10 * std::sin(az)) - plane.height_m(0, 0), 0.30, 1e-9);
  EXPECT_NEAR(plane.height_m(-10 * std::sin(az), 10 * std::cos(az)) - plane.height_m(0, 0), 0.0, 1e-9);
  EXPECT_NEAR(plane.normal(1, 1).dot(Eigen::Vector3d(std::cos(az), std::sin(az), 0.03)), 0.0, 1e-9);
}

TEST(GroundRelief, BadKeysAreOneLineWithTheirRange) {
  EXPECT_NE(relief_error(std::string(kReliefStation) + "ground: {relief: {amplitude_cm: -1}}\n")
                .find("bad.yaml:6: ground.relief.amplitude_cm: expected a value in [0, 20], got -1"),
            std::string::npos);
  EXPECT_NE(relief_error(std::string(kReliefStation) + "ground: {relief: {scale_m: 0}}\n")
                .find("ground.relief.scale_m: expected a value in [0.2, 50], got 0"),
            std::string::npos);
  EXPECT_NE(relief_error(std::string(kReliefStation) + "ground: {relief: {slope_percent: -3}}\n")
                .find("ground.relief.slope_percent: expected a value in [0, 30], got -3"),
            std::string::npos);
  EXPECT_NE(relief_error(std::string(kReliefStation) + "ground: {relief: {scale_m: 0.5, cell_m: 0.3}}\n")
                .find("ground.relief.cell_m: expected a cell of at most half of scale_m (0.25 m)"),
            std::string::npos);
  EXPECT_NE(
      relief_error(std::string(kReliefStation) + "ground: {size_m: [2000, 2000], relief: {cell_m: 0.05}}\n")
          .find("ground.relief.cell_m: expected a cell that samples ground.size_m in at most 1000000 points, "
                "got 0.05 m (40001 x 40001 points)"),
      std::string::npos);
  // Under a varied soil the relief has no grid over the ground to bound.
  EXPECT_EQ(relief_error(std::string(kReliefStation) +
                         "ground: {size_m: [2000, 2000], tiling: varied, relief: {cell_m: 0.05}}\n"),
            "");
  EXPECT_NE(relief_error(std::string(kReliefStation) + "ground: {friction: 0}\n")
                .find("ground.friction: expected a value in [0.05, 2], got 0"),
            std::string::npos);
  EXPECT_NE(relief_error(std::string(kReliefStation) + "ground: {relief: {bumps: 3}}\n")
                .find("ground.relief.bumps: expected a known key"),
            std::string::npos);
}

// A relief the robot cannot drive is refused at the key that makes it, with
// the grade and where on the route it is.
TEST(GroundRelief, TooRoughOrSteepForTheRouteIsRefused) {
  const std::string ok = std::string(kReliefStation) + "ground: {relief: {amplitude_cm: 2, scale_m: 1}}\n";
  EXPECT_EQ(relief_error(ok), "");
  const std::string rough = relief_error(
      std::string(kReliefStation) + "ground:\n  relief: {amplitude_cm: 10, scale_m: 0.4, cell_m: 0.1}\n");
  EXPECT_NE(
      rough.find(
          "bad.yaml:7: ground.relief.amplitude_cm: expected a relief the robot can drive: grades of at "
          "most 15 % along its route, over its wheel base (0.36 m) and across its track (0.42 m), got "),
      std::string::npos)
      << rough;
  EXPECT_NE(rough.find(" the route at (x, y) = ("), std::string::npos) << rough;
  const std::string steep =
      relief_error(std::string(kReliefStation) + "ground: {relief: {amplitude_cm: 0, slope_percent: 20}}\n");
  EXPECT_NE(steep.find("ground.relief.slope_percent: expected a relief the robot can drive"),
            std::string::npos)
      << steep;
  EXPECT_NE(steep.find("got 20.0 % along the route at (x, y) = ("), std::string::npos) << steep;
  // Across the route the same slope is a roll.
  const std::string across =
      relief_error(std::string(kReliefStation) +
                   "ground: {relief: {amplitude_cm: 0, slope_percent: 20, slope_azimuth_deg: 90}}\n");
  EXPECT_NE(across.find("got 20.0 % across the route"), std::string::npos) << across;
  // The criterion itself: a grade just within the limit passes, just beyond it fails.
  const std::vector<Eigen::Vector2d> route = {{-2, 0}, {-1, 0}, {0, 0}, {1, 0}};
  Relief r = make_relief(0.0, 14.9);
  r.slope_azimuth_deg = 0;
  EXPECT_FALSE(find_route_grade_fault(GroundRelief(r, Eigen::Vector2d(10, 10), 0), route, 0.36, 0.42));
  r.slope_percent = 15.1;
  const auto fault = find_route_grade_fault(GroundRelief(r, Eigen::Vector2d(10, 10), 0), route, 0.36, 0.42);
  ASSERT_TRUE(fault);
  EXPECT_FALSE(fault->across);
  EXPECT_NEAR(fault->grade, 0.151, 1e-9);
}

// The soil's friction is the day's; the relief is the station's.
TEST(GroundRelief, FrictionIsADayKeyAndTheReliefIsNot) {
  const std::string station = std::string(kReliefStation) + "ground: {relief: {amplitude_cm: 1}}\n";
  EXPECT_EQ(relief_day_error("friction", station, "base: station.yaml\nground: {friction: 0.35}\n"), "");
  const std::string e =
      relief_day_error("relief", station, "base: station.yaml\nground: {relief: {amplitude_cm: 3}}\n");
  EXPECT_NE(e.find("day.yaml:2: ground.relief: expected a key a derived file may change"), std::string::npos)
      << e;
  EXPECT_DOUBLE_EQ(*load_scenario(kReliefScenes + "days/rough_station_wet.yaml").ground.friction, 0.4);
  EXPECT_DOUBLE_EQ(*load_scenario(kReliefScenes + "days/rough_station_dry.yaml").ground.friction, 0.65);
  EXPECT_FALSE(load_scenario(kReliefScenes + "rough_station.yaml").ground.friction);
}
