// A plant's fence and gates, its dock and combiner boxes, its roads, the
// routes that use them (a day from the dock and back, a loop along the
// perimeter road), and the errors they give.
#include <gtest/gtest.h>

#include <cmath>

#include "pvb/scenes/plant.hpp"
#include "pvb/scenes/route.hpp"
#include "scenario_errors.hpp"

namespace pvb::scenes {
namespace plant_fixtures_test {

using test::error_of;

Scenario plant_scenario(const std::string& plant, const std::string& route) {
  return parse_scenario("ground: {size_m: [600, 600], tiling: repeat}\nplant: " + plant + "\nroute: " + route + "\n",
                        "plant.yaml");
}

/// A point in the plant's first block's frame.
Eigen::Vector2d uv(const Scenario& s, const Eigen::Vector2d& p_m) {
  return world_to_array(s.pv_arrays[static_cast<std::size_t>(s.plant->first_array)], p_m);
}

TEST(PlantFence, StandsAtItsSetbackAroundThePlantWithAGateWhereverARoadMeetsIt) {
  const Scenario s = plant_scenario("{rows: 6, blocks: 2, blocks_along: 2, azimuth_deg: 30, road_width_m: 5}",
                                    "{pattern: along_row, aisle: 1}");
  ASSERT_TRUE(s.plant->fence.has_value());
  const Fence& f = *s.plant->fence;
  ASSERT_EQ(f.corners_m.size(), 4u);
  const Eigen::Vector4d e = s.plant->extent_uv;
  const double setback = 5 + 2;  // the road and a metre either side of it
  EXPECT_NEAR((uv(s, f.corners_m[0]) - Eigen::Vector2d(e[0] - setback, e[1] - setback)).norm(), 0, 1e-9);
  EXPECT_NEAR((uv(s, f.corners_m[2]) - Eigen::Vector2d(e[2] + setback, e[3] + setback)).norm(), 0, 1e-9);
  // The dock's aisle at both ends, the road between the two blocks at both
  // sides, the road behind the blocks at both ends.
  EXPECT_EQ(f.gates_m.size(), 6u);
  for (const Eigen::Vector2d& g : f.gates_m) {
    const Eigen::Vector2d q = uv(s, g);
    const bool on_fence = std::abs(q.x() - (e[0] - setback)) < 1e-9 || std::abs(q.x() - (e[2] + setback)) < 1e-9 ||
                          std::abs(q.y() - (e[1] - setback)) < 1e-9 || std::abs(q.y() - (e[3] + setback)) < 1e-9;
    EXPECT_TRUE(on_fence) << q.transpose();
  }
  // Two roads inside (between the blocks, behind them) and four around.
  EXPECT_EQ(s.plant->roads_uv.size(), 6u);
  EXPECT_NEAR(s.plant->perimeter_road_m, 1 + 5 / 2.0, 1e-12);
}

TEST(PlantFence, CanBeLeftOutWithItsPerimeterRoad) {
  const Scenario s = plant_scenario("{rows: 6, fence: false}", "{pattern: along_row, aisle: 1}");
  EXPECT_FALSE(s.plant->fence.has_value());
  EXPECT_EQ(s.plant->roads_uv.size(), 1u);  // the road behind the block
}

TEST(PlantFixtures, ACombinerBoxEveryNRowsAndTheDockInTheHeadlandOfItsAisle) {
  const Scenario s = plant_scenario("{rows: 12, combiner_rows: 4, dock: {aisle: 2}}", "{pattern: along_row, aisle: 1}");
  const PvArray& b = s.pv_arrays[0];
  int boxes = 0, dock = 0;
  for (const Fixture& fx : s.plant->fixtures) {
    const Eigen::Vector2d q = uv(s, fx.centre_m);
    if (q.x() > row_length_m(b)) {
      ++boxes;  // past the rows' far end, within the footprint of rows 3, 7, 11
      const int row = static_cast<int>(std::floor(q.y() / b.row_pitch_m));
      EXPECT_EQ(row % 4, 3) << q.transpose();
      EXPECT_LT(q.x(), row_length_m(b) + 1.0);
    } else {
      ++dock;  // in the headland before the rows, on aisle 2's centre line
      EXPECT_LT(q.x(), 0);
      EXPECT_GT(q.x(), -8);
      EXPECT_NEAR(q.y(), 2 * b.row_pitch_m - (b.row_pitch_m - row_footprint_m(b)) / 2, 1e-9);
    }
  }
  EXPECT_EQ(boxes, 2 * 3);  // a post and a box each
  EXPECT_EQ(dock, 3);       // the cabinet, the canopy's post, the canopy
  EXPECT_EQ(s.plant->dock_aisle, 2);
  const Scenario bare = plant_scenario("{rows: 12, combiner_rows: 0, dock: false}", "{pattern: along_row, aisle: 1}");
  EXPECT_TRUE(bare.plant->fixtures.empty());
}

TEST(PlantRouteShapes, ADayFromTheDockComesBackToWhereItStarted) {
  for (const int aisles : {3, 4}) {  // the way back differs after an odd and an even number of aisles
    const Scenario s = plant_scenario("{rows: 8}", "{pattern: lawnmower, aisles: " + std::to_string(aisles) +
                                                       ", from_dock: true}");
    const std::vector<Eigen::Vector2d> route = route_polyline(s);
    const Eigen::Vector2d start = uv(s, route.front()), end = uv(s, route.back());
    EXPECT_NEAR((start - end).norm(), 0, 1e-9) << aisles;
    EXPECT_NEAR(start.x(), s.plant->dock_front_u_m, 1e-9);
    // It starts and ends heading into the first aisle.
    const Eigen::Vector2d first = uv(s, route[1]) - start, last = end - uv(s, route[route.size() - 2]);
    EXPECT_GT(first.normalized().x(), 0.99);
    EXPECT_GT(last.normalized().x(), 0.99) << aisles;
    // No gap between points longer than their spacing: a follower moves on along it.
    for (std::size_t i = 1; i < route.size(); ++i)
      ASSERT_LE((route[i] - route[i - 1]).norm(), 0.05 + 1e-9) << aisles << " aisles, point " << i;
    // Longer than its aisles: it drives to them and back.
    EXPECT_GT(polyline_length(route), aisles * row_length_m(s.pv_arrays[0]));
  }
}

TEST(PlantRouteShapes, ALoopAlongThePerimeterRoadStaysOnTheRoad) {
  const Scenario s = plant_scenario("{rows: 8}", "{pattern: roads, laps: 2}");
  const std::vector<Eigen::Vector2d> route = route_polyline(s, 0.25);
  const Eigen::Vector4d e = s.plant->extent_uv;
  const double w = s.plant->road_width_m;
  for (const Eigen::Vector2d& p : route) {
    const Eigen::Vector2d q = uv(s, p);
    // Distance beyond the extent (outside it: between 1 m and 1 m + the road).
    const double du = std::max({e[0] - q.x(), q.x() - e[2], 0.0}), dv = std::max({e[1] - q.y(), q.y() - e[3], 0.0});
    const double out = std::hypot(du, dv);
    EXPECT_GE(out, 1.0 - 1e-9) << q.transpose();
    EXPECT_LE(std::max(du, dv), 1.0 + w + 1e-9) << q.transpose();
  }
  EXPECT_NEAR((route.front() - route.back()).norm(), 0, 1e-9);
  const double lap = 2 * (e[2] - e[0] + e[3] - e[1]) + 8 * s.plant->perimeter_road_m;
  EXPECT_NEAR(polyline_length(route), 2 * lap, 2 * lap * 0.02);  // corners rounded
}

// Around each block of a 2 x 2 plant along the roads that bound it: the
// perimeter road on the plant's edges, the roads between blocks elsewhere.
TEST(PlantRouteShapes, ALoopAroundABlockFollowsTheRoadsAroundIt) {
  const std::string plant = "{rows: 6, blocks: 4, blocks_along: 2, modules_per_table: 20}";
  for (int k = 1; k <= 4; ++k) {
    const Scenario s = plant_scenario(plant, "{pattern: roads, block: " + std::to_string(k) + "}");
    const std::vector<Eigen::Vector2d> route = route_polyline(s, 0.25);
    // On a road, or on the metre between the plant's extent and the
    // perimeter road where the roads inside end.
    for (const Eigen::Vector2d& p : route) {
      const Eigen::Vector2d q = uv(s, p);
      double nearest = 1e9;
      for (const Eigen::Vector4d& r : s.plant->roads_uv)
        nearest = std::min(nearest, std::hypot(std::max({r[0] - q.x(), q.x() - r[2], 0.0}),
                                               std::max({r[1] - q.y(), q.y() - r[3], 0.0})));
      EXPECT_LE(nearest, 1.0 + 1e-9) << "block " << k << ": " << q.transpose();
    }
    EXPECT_NEAR((route.front() - route.back()).norm(), 0, 1e-9);
    // The loop holds its block's rows and no other block's.
    Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
    for (const Eigen::Vector2d& p : route) lo = lo.cwiseMin(uv(s, p)), hi = hi.cwiseMax(uv(s, p));
    for (int b = 0; b < 4; ++b) {
      const PvArray& a = s.pv_arrays[static_cast<std::size_t>(s.plant->first_array + b)];
      int inside = 0;
      for (const auto& [du, dv] : {std::pair{0.0, 0.0},
                                   {row_length_m(a), 0.0},
                                   {0.0, a.rows * a.row_pitch_m},
                                   {row_length_m(a), a.rows * a.row_pitch_m}}) {
        const Eigen::Vector2d q = uv(s, array_to_world(a, du, dv));
        inside += (q.array() > lo.array()).all() && (q.array() < hi.array()).all();
      }
      EXPECT_EQ(inside, b == k - 1 ? 4 : 0) << "block " << k << ", block " << b + 1 << "'s corners";
    }
  }
  // The dock's block starts level with the dock, the others half-way along their west side.
  const Scenario first = plant_scenario(plant, "{pattern: roads, block: 1}");
  EXPECT_NEAR(uv(first, route_polyline(first).front()).y(), first.plant->dock_v_m, 1e-9);
}

TEST(PlantErrors, ALoopAroundABlockThePlantLacksIsRefused) {
  const std::string ground = "ground: {size_m: [600, 600]}\n";
  std::string e = error_of(ground + "plant: {rows: 6, blocks: 2}\nroute: {pattern: roads, block: 3}\n");
  EXPECT_NE(e.find("bad.yaml:3: route.block: expected a block of the plant, from 1 to 2, got 3"),
            std::string::npos)
      << e;
  // Before the route is drawn (a start part-way measures it).
  e = error_of(ground + "plant: {rows: 6, blocks: 2}\nroute: {pattern: roads, block: 3, start_m: 10}\n");
  EXPECT_NE(e.find("bad.yaml:3: route.block: expected a block of the plant"), std::string::npos) << e;
  e = error_of(ground + "plant: {rows: 6}\nroute: {pattern: lawnmower, block: 1}\n");
  EXPECT_NE(e.find("bad.yaml:3: route.block: expected no block unless route.pattern is roads"),
            std::string::npos)
      << e;
}

TEST(PlantErrors, RowsThatCrossTheFenceOrARoadAreRefused) {
  const std::string plant = "plant:\n  origin_m: [-40, -20]\n  rows: 6\n  tables_per_row: 2\n  modules_per_table: 20\n";
  const auto with_array_at = [&](double y) {
    return error_of("ground: {size_m: [200, 200]}\npv_arrays:\n  - {origin_m: [-45, " + std::to_string(y) +
                    "], rows: 2, tables_per_row: 2}\n" + plant + "route: {pattern: lawnmower, array: 1}\n");
  };
  const Scenario s = parse_scenario("ground: {size_m: [200, 200]}\n" + plant + "route: {pattern: along_row}\n", "p.yaml");
  const double fence_y = s.plant->fence->corners_m[2].y();
  const double depth = row_footprint_m(parse_scenario("pv_arrays:\n  - {rows: 2, tables_per_row: 2}\n"
                                                      "route: {pattern: along_row}\n", "a.yaml").pv_arrays[0]);
  // Row 0 astride the fence (the fence is checked first).
  std::string e = with_array_at(fence_y - depth / 2);
  EXPECT_NE(e.find("bad.yaml:3: pv_arrays[0]: expected rows clear of the plant's service roads and its fence, got row 0 "
                   "crossing the fence"),
            std::string::npos)
      << e;
  e = with_array_at(fence_y - 1.5 - depth);  // row 0 inside the fence, on the perimeter road
  EXPECT_NE(e.find("got row 0 crossing a service road"), std::string::npos) << e;
  EXPECT_EQ(with_array_at(fence_y + 1.0), "");  // outside the fence
}

TEST(PlantErrors, RoutesThatNeedAPlantsFixturesAreRefusedWithoutThem) {
  std::string e = error_of("ground: {size_m: [400, 400]}\nplant: {rows: 4, fence: false}\nroute: {pattern: roads}\n");
  EXPECT_NE(e.find("bad.yaml:3: route.pattern: expected roads only in a plant with a fence"), std::string::npos) << e;
  e = error_of("ground: {size_m: [400, 400]}\nplant: {rows: 4, dock: false}\nroute:\n  pattern: lawnmower\n"
               "  from_dock: true\n");
  EXPECT_NE(e.find("bad.yaml:5: route.from_dock: expected false unless the plant has a dock"), std::string::npos) << e;
  e = error_of("ground: {size_m: [400, 400]}\nplant: {rows: 4}\nroute:\n  pattern: lawnmower\n  first_aisle: 1\n"
               "  from_dock: true\n");
  EXPECT_NE(e.find("route.first_aisle: expected the dock's aisle, 0 (plant.dock.aisle), got 1"), std::string::npos) << e;
  e = error_of("ground: {size_m: [400, 400]}\nplant: {rows: 4}\nroute:\n  pattern: lawnmower\n  margin_m: 5\n"
               "  from_dock: true\n");
  EXPECT_NE(e.find("route.margin_m: expected a run-out that starts past the dock: below 4.70 m"), std::string::npos)
      << e;
  e = error_of("ground: {size_m: [400, 400]}\nplant: {rows: 4, headland_m: 3}\nroute: {pattern: along_row}\n");
  EXPECT_NE(e.find("plant.dock: expected a headland_m of at least 3.8 m"), std::string::npos) << e;
  e = error_of("ground: {size_m: [400, 400]}\nplant: {rows: 4, fence: {setback_m: 3}}\nroute: {pattern: along_row}\n");
  EXPECT_NE(e.find("plant.fence.setback_m: expected a value in [5, 100]"), std::string::npos) << e;
}

TEST(PlantErrors, ARouteThroughTheDockIsRefused) {
  // Along the dock's aisle from beyond the headland's edge: through the cabinet.
  const std::string e = error_of(
      "ground: {size_m: [400, 400]}\nplant: {rows: 4}\nroute:\n  waypoints_m: [[-12, -3], [-2, -3]]\n");
  EXPECT_NE(e.find("route.waypoints_m: expected a route that keeps 0.30 m from the dock, the combiner boxes, the row "
                   "signs and the inverter stations"),
            std::string::npos)
      << e;
}

}  // namespace plant_fixtures_test
}  // namespace pvb::scenes
