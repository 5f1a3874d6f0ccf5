#include <gtest/gtest.h>

#include "pvb/scenes/route.hpp"

using namespace pvb::scenes;

namespace {
Scenario array_scenario(const std::string& route) {
  return parse_scenario(
      "pv_arrays:\n  - {origin_m: [2, 3], azimuth_deg: 30, rows: 3, tables_per_row: 2, panels_per_table: 4,"
      " row_pitch_m: 6, tilt_deg: 20}\nroute: " + route + "\n",
      "route.yaml");
}
}  // namespace

TEST(Route, WaypointsAreSampledInOrder) {
  const Scenario s = parse_scenario("route: {waypoints_m: [[0, 0], [4, 0], [4, 3]]}\n", "w.yaml");
  const auto pts = route_polyline(s, 0.1);
  EXPECT_NEAR(polyline_length(pts), 7.0, 1e-9);
  EXPECT_NEAR((pts.front() - Eigen::Vector2d(0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((pts.back() - Eigen::Vector2d(4, 3)).norm(), 0, 1e-12);
}

TEST(Route, AlongRowIsStraightAndSpansTheRow) {
  const Scenario s = array_scenario("{pattern: along_row, aisle: 1, margin_m: 2, offset_m: 1}");
  const PvArray& a = s.pv_arrays[0];
  const auto pts = route_polyline(s, 0.05);
  EXPECT_NEAR(polyline_length(pts), row_length_m(a) + 4.0, 1e-6);
  const Eigen::Vector2d dir(std::cos(M_PI / 6), std::sin(M_PI / 6));
  EXPECT_NEAR(((pts.back() - pts.front()).normalized() - dir).norm(), 0, 1e-9);
  // the aisle lies between row 0's back edge and row 1's front edge
  const Eigen::Vector2d normal(-dir.y(), dir.x());
  const double v = (pts.front() - a.origin_m).dot(normal);
  EXPECT_GT(v, row_footprint_m(a));
  EXPECT_LT(v, a.row_pitch_m);
}

TEST(Route, LoopReturnsToItsStart) {
  const Scenario s = array_scenario("{pattern: loop, offset_m: 1.5}");
  const auto pts = route_polyline(s, 0.05);
  EXPECT_LT((pts.front() - pts.back()).norm(), 1e-9);
  EXPECT_GT(polyline_length(pts), 2 * row_length_m(s.pv_arrays[0]));
  for (std::size_t i = 1; i < pts.size(); ++i) EXPECT_LT((pts[i] - pts[i - 1]).norm(), 0.0501);
}

TEST(Route, LawnmowerAlternatesDirection) {
  const Scenario s = array_scenario("{pattern: lawnmower, aisles: 3, margin_m: 1.5}");
  const auto pts = route_polyline(s, 0.05);
  const Eigen::Vector2d dir(std::cos(M_PI / 6), std::sin(M_PI / 6));
  // count sign changes of the along-row velocity
  int changes = 0;
  double last = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const double along = (pts[i] - pts[i - 1]).dot(dir);
    if (std::abs(along) < 0.04) continue;  // turns
    if (last != 0 && (along > 0) != (last > 0)) ++changes;
    last = along;
  }
  EXPECT_EQ(changes, 2);
}
