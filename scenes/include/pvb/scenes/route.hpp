#pragma once
// Routes: the path the robot follows, as a densely sampled polyline in the
// world's ground plane, plus the array geometry the generated patterns use.
#include <Eigen/Core>
#include <vector>

#include "pvb/scenes/scenario.hpp"

namespace pvb::scenes {

/// Maps array-frame (u along rows, v across rows) to world x, y.
Eigen::Vector2d array_to_world(const PvArray& a, double u, double v);
/// The inverse: world x, y to the array frame (u, v).
Eigen::Vector2d world_to_array(const PvArray& a, const Eigen::Vector2d& p_m);
/// Length of one row along u: tables and the gaps between them.
double row_length_m(const PvArray& a);
/// Ground footprint depth of one row along v (the tilted table's projection;
/// a tracker row's full width, which it has flat).
double row_footprint_m(const PvArray& a);

/// The route as a polyline sampled every `spacing_m` (first point = start).
/// Waypoint routes are taken as given; patterns are generated:
/// - along_row: one straight pass along aisle `aisle` (in front of row
///   `aisle`; aisle == rows is behind the last row), margin_m beyond each end;
/// - lawnmower: `aisles` passes in alternating directions joined by
///   half-circle turns beyond the row ends;
/// - loop: a rounded rectangle offset_m around the whole array, ending where
///   it started.
std::vector<Eigen::Vector2d> route_polyline(const Scenario& s, double spacing_m = 0.05);

/// The rest of `route` from `start_m` metres along it: the point there
/// (interpolated) first, then the route's points beyond it.
std::vector<Eigen::Vector2d> polyline_from(const std::vector<Eigen::Vector2d>& route, double start_m);

/// Total length of a polyline.
double polyline_length(const std::vector<Eigen::Vector2d>& pts);

}  // namespace pvb::scenes
