// The plant: section: a plant described as a designer would, laid out into
// blocks of rows and inverter skids, and the errors a plant's file gets.
#include <gtest/gtest.h>

#include <cmath>

#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/plant.hpp"
#include "pvb/scenes/route.hpp"
#include "scenario_errors.hpp"

namespace pvb::scenes {
namespace plant_test {

using test::error_of;

Scenario plant_scenario(const std::string& plant, const std::string& route = "{pattern: along_row, aisle: 1}",
                        const std::string& ground = "[800, 800]") {
  return parse_scenario("ground: {size_m: " + ground + ", tiling: repeat}\nplant: " + plant + "\nroute: " + route + "\n",
                        "plant.yaml");
}

TEST(Plant, ModulesPowerAndCoverageFollowTheLayout) {
  const Scenario s = plant_scenario("{rows: 10, module_power_w: 580, ground_coverage_ratio: 0.4}");
  ASSERT_TRUE(s.plant.has_value());
  // The defaults: fixed 2P tables of 2 x 28 portrait 144-cell modules, 3 a row.
  EXPECT_EQ(s.plant->modules, 10LL * 3 * 28 * 2);
  EXPECT_NEAR(s.plant->dc_mw, 1680 * 580e-6, 1e-9);
  ASSERT_EQ(s.pv_arrays.size(), 1u);
  const PvArray& a = s.pv_arrays[0];
  EXPECT_TRUE(a.panel_slabs);
  EXPECT_EQ(a.panel_lines, 2);
  // pvlib's ratio: the collector's width (a fixed table's slope length) over the pitch.
  EXPECT_NEAR(a.table_depth_m() / a.row_pitch_m, 0.4, 1e-12);
  EXPECT_NEAR(s.plant->ground_coverage_ratio, 0.4, 1e-12);
}

TEST(Plant, ATargetPowerGivesTheFewestRowsThatHoldIt) {
  // A 10 MWdc block of fixed tables is about a kilometre of rows.
  const Scenario s = plant_scenario("{block_mwdc: 10, module_power_w: 580, origin_m: [-50, -600]}",
                                    "{pattern: along_row, aisle: 1}", "[400, 1400]");
  const double row_mw = 3 * 28 * 2 * 580e-6;
  EXPECT_EQ(s.plant->rows_per_block, static_cast<int>(std::ceil(10.0 / row_mw)));
  EXPECT_GE(s.plant->dc_mw, 10.0);
  EXPECT_LT(s.plant->dc_mw, 10.0 + row_mw);
  // One inverter station a 2 MWdc, by default.
  EXPECT_EQ(s.plant->inverter_stations, static_cast<int>(std::ceil(s.plant->dc_mw / 2.0)));
  EXPECT_EQ(s.walls.size(), static_cast<std::size_t>(s.plant->inverter_stations));
}

TEST(Plant, TrackersAreOnePortraitModuleWideAtTheirCoverageRatio) {
  const Scenario s = plant_scenario("{mount: single_axis, rows: 20}");
  const PvArray& a = s.pv_arrays[0];
  EXPECT_EQ(a.mount, Mount::kSingleAxis);
  EXPECT_EQ(a.panel_lines, 1);
  EXPECT_EQ(a.panels_per_table * a.tables_per_row, 84);
  EXPECT_NEAR(a.table_depth_m() / a.row_pitch_m, 0.35, 1e-12);
}

TEST(Plant, BlocksStandApartWithHeadlandsAndRoadsBetween) {
  const Scenario s = plant_scenario("{rows: 6, blocks: 4, blocks_along: 2, azimuth_deg: 20, headland_m: 8, road_width_m: 4}");
  ASSERT_EQ(s.pv_arrays.size(), 4u);
  const PvArray& b0 = s.pv_arrays[0];
  const double len = row_length_m(b0), depth = 5 * b0.row_pitch_m + row_footprint_m(b0);
  // Along the rows: a headland, the road, a headland.
  const Eigen::Vector2d b1 = world_to_array(b0, s.pv_arrays[1].origin_m);
  EXPECT_NEAR(b1.x(), len + 2 * 8 + 4, 1e-9);
  EXPECT_NEAR(b1.y(), 0, 1e-9);
  // Across them: the next line of blocks beyond the aisle, the road, the skids and an aisle.
  const Eigen::Vector2d b2 = world_to_array(b0, s.pv_arrays[2].origin_m);
  EXPECT_NEAR(b2.x(), 0, 1e-9);
  EXPECT_GT(b2.y(), depth + 4 + kInverterSkidWidthM);
  // Every skid lies clear of every block's rows and headlands.
  for (const Wall& w : s.walls)
    for (const PvArray& b : s.pv_arrays) {
      const Eigen::Vector2d mid = world_to_array(b, 0.5 * (w.start_m + w.end_m));
      const bool in_block = mid.x() > -8 - kInverterSkidLengthM / 2 && mid.x() < len + 8 + kInverterSkidLengthM / 2 &&
                            mid.y() > -kInverterSkidWidthM && mid.y() < depth + kInverterSkidWidthM;
      EXPECT_FALSE(in_block) << "a skid at (" << mid.transpose() << ") in a block's frame";
    }
}

TEST(Plant, ALawnmowerThroughABlockIsAccepted) {
  const Scenario s = plant_scenario("{rows: 12}", "{pattern: lawnmower, aisles: 12}");
  EXPECT_GT(polyline_length(route_polyline(s)), 11 * row_length_m(s.pv_arrays[0]));
}

TEST(PlantErrors, ACoverageRatioOfOneOrMoreIsRefused) {
  const std::string e = error_of("plant: {rows: 4, ground_coverage_ratio: 1.0}\nroute: {pattern: along_row}\n");
  EXPECT_NE(e.find("bad.yaml:1: plant.ground_coverage_ratio: expected a ratio below 1"), std::string::npos) << e;
  const std::string tight = error_of(
      "plant: {rows: 4, mount: single_axis, ground_coverage_ratio: 0.95}\nroute: {pattern: along_row}\n");
  EXPECT_NE(tight.find("plant.ground_coverage_ratio: expected at most"), std::string::npos) << tight;
}

TEST(PlantErrors, APlantLargerThanItsGroundIsRefused) {
  const std::string e = error_of("ground: {size_m: [100, 100]}\nplant:\n  rows: 40\nroute: {pattern: along_row}\n");
  EXPECT_NE(e.find("bad.yaml:2: plant: expected a plant inside ground.size_m [100, 100]"), std::string::npos) << e;
  EXPECT_NE(e.find("a ground of at least"), std::string::npos) << e;
}

TEST(PlantErrors, ARouteThroughATableIsRefused) {
  const std::string e = error_of(
      "ground: {size_m: [400, 400]}\nplant: {rows: 4}\nroute:\n  waypoints_m: [[10, -3], [10, 20]]\n");
  EXPECT_NE(e.find("bad.yaml:4: route.waypoints_m: expected a route that keeps 0.30 m from every table"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("got a route through (x, y) = (10.00, "), std::string::npos) << e;
}

TEST(PlantErrors, ARouteThatLeavesThePlantIsRefused) {
  // Through the fence, or without one beyond the headlands.
  const std::string e = error_of(
      "ground: {size_m: [400, 400]}\nplant: {rows: 4}\nroute:\n  waypoints_m: [[-2, -1.5], [-30, -1.5]]\n");
  EXPECT_NE(e.find("bad.yaml:4: route.waypoints_m: expected a route inside the plant's fence"), std::string::npos) << e;
  EXPECT_NE(e.find("got a route through (x, y) = (-13.7"), std::string::npos) << e;
  const std::string open = error_of(
      "ground: {size_m: [400, 400]}\nplant: {rows: 4, fence: false}\nroute:\n  waypoints_m: [[-2, -1.5], [-30, -1.5]]\n");
  EXPECT_NE(open.find("route.waypoints_m: expected a route inside the plant (its blocks"), std::string::npos) << open;
  EXPECT_NE(open.find("(x, y) = (-8.05, -1.50) m"), std::string::npos) << open;
}

TEST(PlantErrors, RowsAndATargetPowerTogetherAreRefused) {
  const std::string e = error_of("plant: {rows: 4, block_mwdc: 2}\nroute: {pattern: along_row}\n");
  EXPECT_NE(e.find("plant.block_mwdc: expected rows or block_mwdc, not both"), std::string::npos) << e;
}

// The shipped patrol: four blocks of the tracker plant's rows, and a loop
// around the fourth along its roads, driven within the scenario's time.
TEST(Plant, TheBlocksPlantPatrolsItsFourthBlockAlongItsRoads) {
  const Scenario s =
      load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/plants/plant_tracker_blocks_roads.yaml");
  ASSERT_TRUE(s.plant.has_value());
  EXPECT_EQ(s.plant->blocks, 4);
  EXPECT_EQ(s.plant->block_loops_uv.size(), 4u);
  EXPECT_EQ(s.route.pattern, RoutePattern::kRoads);
  EXPECT_EQ(s.route.block, 4);
  EXPECT_GE(s.plant->dc_mw, 10.0);
  const double route_m = polyline_length(route_polyline(s));
  const Eigen::Vector4d& c = s.plant->block_loops_uv[3];
  EXPECT_NEAR(route_m, 2 * (c[2] - c[0] + c[3] - c[1]), 0.01 * route_m);  // its corners rounded
  EXPECT_GE(s.duration_s * s.route.speed_mps, 1.04 * route_m);
}

}  // namespace plant_test
}  // namespace pvb::scenes

namespace pvb::scenes {
namespace plant_test {

// The shipped plants: a 10 MWdc block each, of at least 150 rows of at least
// 100 m, and a day's route of at least a kilometre through their aisles.
TEST(Plant, ShippedPlantsAreTenMegawattBlocksWithAKilometreRoute) {
  for (const char* name : {"plant_10mw_fixed", "plant_10mw_tracker", "plant_10mw_tracker_rough"}) {
    const Scenario s = load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/plants/" + name + ".yaml");
    ASSERT_TRUE(s.plant.has_value()) << name;
    EXPECT_EQ(s.name, name);
    EXPECT_GE(s.plant->dc_mw, 10.0) << name;
    EXPECT_LT(s.plant->dc_mw, 10.1) << name;
    EXPECT_GE(s.plant->rows_per_block, 150) << name;
    const PvArray& block = s.pv_arrays.at(static_cast<std::size_t>(s.plant->first_array));
    EXPECT_GE(row_length_m(block), 100.0) << name;
    const double route_m = polyline_length(route_polyline(s));
    EXPECT_GE(route_m, 1000.0) << name;
    // The robot drives it within the scenario's time: its U-turns and starts
    // are slower than the route's speed (the slow PlantRoutes test drives it).
    EXPECT_GE(s.duration_s * s.route.speed_mps, 1.04 * route_m) << name;
  }
}

// The rough tracker plant is the tracker plant, route and all, on a relief
// drawn tile by tile under its varied soil.
TEST(Plant, TheRoughTrackerPlantIsTheTrackerPlantOnARelief) {
  const std::string dir = std::string(PVB_SOURCE_DIR) + "/scenes/plants/";
  const Scenario flat = load_scenario(dir + "plant_10mw_tracker.yaml");
  const Scenario rough = load_scenario(dir + "plant_10mw_tracker_rough.yaml");
  ASSERT_TRUE(rough.ground.relief.has_value());
  EXPECT_FALSE(flat.ground.relief.has_value());
  EXPECT_TRUE(GroundRelief(rough).tiled());
  EXPECT_EQ(rough.pv_arrays.size(), flat.pv_arrays.size());
  EXPECT_EQ(rough.plant->rows_per_block, flat.plant->rows_per_block);
  const std::vector<Eigen::Vector2d> a = route_polyline(flat), b = route_polyline(rough);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]) << i;
  // The rows rise 2 % to the east: 25 m from the first to the last.
  const GroundRelief g(rough);
  EXPECT_NEAR(g.height_m(600, 0) - g.height_m(-600, 0), 24.0, 0.2);
}

}  // namespace plant_test
}  // namespace pvb::scenes

namespace pvb::scenes {
namespace plant_test {

TEST(PlantErrors, APlantLargerThanTheSceneLimitIsRefusedAtItsKey) {
  const std::string e = error_of(
      "ground: {size_m: [2000, 2000]}\nplant:\n  rows: 100\n  tables_per_row: 30\n  origin_m: [-700, -600]\n"
      "route: {pattern: along_row}\n");
  EXPECT_NE(e.find("bad.yaml:2: plant: expected at most 20000 geoms in the scene"), std::string::npos) << e;
  EXPECT_NE(e.find("(1 blocks x 100 rows x 30 tables x 8 geoms)"), std::string::npos) << e;
}

// A table that lost a module is drawn a module at a time: the limit counts
// its modules and backsheets (2 x 56 - 4 more geoms for the default table of 2 x 28).
TEST(PlantErrors, MissingModulesCountInTheSceneLimit) {
  const std::string plant = "ground: {size_m: [2000, 2000]}\nplant:\n  rows: 20\n  origin_m: [-700, -600]\n";
  EXPECT_NO_THROW(parse_scenario(plant + "  missing_modules: 100\nroute: {pattern: along_row}\n", "ok.yaml"));
  const std::string e = error_of(plant + "  missing_modules: 200\nroute: {pattern: along_row}\n");
  EXPECT_NE(e.find("bad.yaml:2: plant: expected at most 20000 geoms in the scene"), std::string::npos) << e;
  EXPECT_NE(e.find(", up to 21600 more for 200 missing modules a block)"), std::string::npos) << e;
}

}  // namespace plant_test
}  // namespace pvb::scenes
