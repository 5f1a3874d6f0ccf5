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

TEST(Route, LoopLapsDriveTheSameLoopAgain) {
  const auto one = route_polyline(array_scenario("{pattern: loop, offset_m: 1.5}"), 0.05);
  const auto three = route_polyline(array_scenario("{pattern: loop, offset_m: 1.5, laps: 3}"), 0.05);
  EXPECT_NEAR(polyline_length(three), 3 * polyline_length(one), 1e-6);
  ASSERT_EQ(three.size(), 3 * one.size() - 2);  // each lap after the first starts at the last one's end
  for (std::size_t lap = 1; lap < 3; ++lap)
    for (std::size_t i = 0; i < one.size(); ++i)
      EXPECT_LT((three[lap * (one.size() - 1) + i] - one[i]).norm(), 1e-9) << "lap " << lap << ", point " << i;
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

// A lawnmower that returns to its start: after the last aisle (at either
// end of the rows, after an odd or an even number of aisles) it drives back
// outside the rows, reaches its start heading the way it started, and
// re-drives the first return_overlap_m metres of its first aisle.
TEST(Route, LawnmowerReturnsToItsStartAndRedrivesTheFirstMetres) {
  for (int aisles : {1, 2, 3, 4}) {
    SCOPED_TRACE("aisles " + std::to_string(aisles));
    const std::string pattern = "{pattern: lawnmower, aisles: " + std::to_string(aisles) + ", margin_m: 1.5";
    const Scenario plain = array_scenario(pattern + "}");
    const Scenario s = array_scenario(pattern + ", return_to_start: true, return_overlap_m: 3}");
    const PvArray& a = s.pv_arrays[0];
    const auto open = route_polyline(plain, 0.05);
    const auto pts = route_polyline(s, 0.05);
    // the same route up to the end of the last aisle, then the way back
    ASSERT_GT(pts.size(), open.size());
    for (std::size_t i = 0; i < open.size(); ++i) ASSERT_LT((pts[i] - open[i]).norm(), 1e-12) << i;
    const Eigen::Vector2d dir(std::cos(M_PI / 6), std::sin(M_PI / 6));
    const Eigen::Vector2d start = pts.front();
    EXPECT_LT((pts.back() - (start + 3.0 * dir)).norm(), 1e-9);
    // the last 3 m lie on the first 3 m of the first aisle, driven the same way
    std::size_t i = pts.size() - 1;
    double driven = 0;
    for (; i > 0 && driven < 3.0 - 1e-9; --i) {
      const Eigen::Vector2d step = pts[i] - pts[i - 1];
      driven += step.norm();
      EXPECT_NEAR(step.normalized().dot(dir), 1.0, 1e-9) << i;
      const Eigen::Vector2d rel = pts[i - 1] - start;
      EXPECT_LT(std::abs(rel.x() * dir.y() - rel.y() * dir.x()), 1e-9) << i;
      EXPECT_GT(rel.dot(dir), -1e-9) << i;
    }
    EXPECT_LT((pts[i] - start).norm(), 1e-9);  // the overlap starts at the start
    // heading at the start of the overlap: the turn into it ends tangent to the aisle
    EXPECT_NEAR((pts[i] - pts[i - 1]).normalized().dot(dir), 1.0, 2e-3);
    // evenly sampled, no point repeated, no point on a row's footprint
    const Eigen::Vector2d across(-dir.y(), dir.x());
    for (std::size_t k = 1; k < pts.size(); ++k) {
      const double step = (pts[k] - pts[k - 1]).norm();
      EXPECT_GT(step, 0.01) << k;
      EXPECT_LT(step, 0.0501) << k;
      const double u = (pts[k] - a.origin_m).dot(dir), v = (pts[k] - a.origin_m).dot(across);
      for (int row = 0; row < a.rows; ++row) {
        const bool on_row = u > -0.3 && u < row_length_m(a) + 0.3 && v > row * a.row_pitch_m - 0.3 &&
                            v < row * a.row_pitch_m + row_footprint_m(a) + 0.3;
        EXPECT_FALSE(on_row) << "point " << k << " (u " << u << ", v " << v << ") on row " << row;
      }
    }
  }
}
