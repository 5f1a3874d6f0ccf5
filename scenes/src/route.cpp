#include "pvb/scenes/route.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "pvb/geometry/angles.hpp"

namespace pvb::scenes {
namespace {

using geom::kDegToRad;

void append_segment(std::vector<Eigen::Vector2d>* out, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                    double spacing) {
  const double len = (b - a).norm();
  const int n = std::max(1, static_cast<int>(std::ceil(len / spacing)));
  for (int i = out->empty() ? 0 : 1; i <= n; ++i) out->push_back(a + (b - a) * (static_cast<double>(i) / n));
}

// Arc around `centre` from angle a0 to a1 (radians, either direction).
void append_arc(std::vector<Eigen::Vector2d>* out, const Eigen::Vector2d& centre, double radius, double a0, double a1,
                double spacing) {
  const double len = std::abs(a1 - a0) * radius;
  const int n = std::max(2, static_cast<int>(std::ceil(len / spacing)));
  for (int i = 1; i <= n; ++i) {
    const double a = a0 + (a1 - a0) * (static_cast<double>(i) / n);
    out->push_back(centre + radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
}

// v coordinate of aisle k's centre line.
double aisle_v(const PvArray& a, int k, double offset) {
  const double depth = row_footprint_m(a);
  if (k == 0) return -offset;
  const double back_of_prev = (k - 1) * a.row_pitch_m + depth;
  if (k >= a.rows) return back_of_prev + offset;
  const double width = a.row_pitch_m - depth;
  return k * a.row_pitch_m - std::min(offset, 0.5 * width);
}

/// Radius of the turns of a lawnmower's return to its start.
constexpr double kReturnTurnRadiusM = 1.5;

// Appends the segment unless it is shorter than one spacing (no repeated points).
void append_segment_if_long(std::vector<Eigen::Vector2d>* out, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b, double spacing) {
  if ((b - a).norm() >= spacing) append_segment(out, a, b, spacing);
}

// A lawnmower's way back to its start, in the array frame, from the end of
// its last aisle (at v_last; at u0 after an even number of aisles, at u1
// after an odd one) to the start (u0, v0) heading +u, then on along the
// first aisle for `overlap_m`.  Every part lies outside the rows: beyond
// the row ends at u0 - r, and after an odd number of aisles also in front
// of the first aisle at v0 - 2r.
void append_return(std::vector<Eigen::Vector2d>* uv, double u0, double u1, double v0, double v_last,
                   bool ends_at_u1, double overlap_m, double spacing) {
  if (!ends_at_u1) {
    // heading -u at (u0, v_last), after the run-out to there when u0 lies
    // beyond the last aisle's end (a dock): left turn down the run-out, left
    // turn into the first aisle
    if (!uv->empty()) append_segment_if_long(uv, uv->back(), {u0, v_last}, spacing);
    const double r = std::min(kReturnTurnRadiusM, 0.5 * (v_last - v0));
    append_arc(uv, {u0, v_last - r}, r, M_PI / 2, M_PI, spacing);
    append_segment_if_long(uv, {u0 - r, v_last - r}, {u0 - r, v0 + r}, spacing);
    append_arc(uv, {u0, v0 + r}, r, M_PI, 1.5 * M_PI, spacing);
  } else {
    // heading +u at (u1, v_last): right turn down beyond u1, right turn into a
    // lane in front of the first aisle, back along it, half turn up into the first aisle
    const double r = kReturnTurnRadiusM;
    append_arc(uv, {u1, v_last - r}, r, M_PI / 2, 0, spacing);
    append_segment_if_long(uv, {u1 + r, v_last - r}, {u1 + r, v0 - r}, spacing);
    append_arc(uv, {u1, v0 - r}, r, 0, -M_PI / 2, spacing);
    append_segment(uv, {u1, v0 - 2 * r}, {u0, v0 - 2 * r}, spacing);
    append_arc(uv, {u0, v0 - r}, r, -M_PI / 2, -1.5 * M_PI, spacing);
  }
  append_segment_if_long(uv, {u0, v0}, {u0 + overlap_m, v0}, spacing);
}

/// Radius of the corners of a loop along a plant's perimeter road.
constexpr double kRoadCornerRadiusM = 3.0;

/// Around a plant along its perimeter road (block 0), or around its block
/// `block` along the roads that bound it, `laps` times, counter-clockwise
/// seen from above, from the side before the rows' start (-u) level with
/// the dock (or that side's middle), heading -v; in the first block's frame.
void append_road_loop(std::vector<Eigen::Vector2d>* uv, const PlantSummary& plant, int block, int laps,
                      double spacing) {
  const Eigen::Vector4d& e = plant.extent_uv;
  const double d = plant.perimeter_road_m, r = kRoadCornerRadiusM;
  const Eigen::Vector4d c = block > 0 ? plant.block_loops_uv.at(static_cast<std::size_t>(block - 1))
                                      : Eigen::Vector4d(e[0] - d, e[1] - d, e[2] + d, e[3] + d);
  const double u0 = c[0], v0 = c[1], u1 = c[2], v1 = c[3];
  // Level with the dock where the loop passes it, else half-way along.
  const bool by_dock =
      plant.dock_aisle && (block == 0 || (u0 < e[0] && plant.dock_v_m > v0 + r && plant.dock_v_m < v1 - r));
  const double vs = by_dock ? std::clamp(plant.dock_v_m, v0 + r, v1 - r) : 0.5 * (v0 + v1);
  for (int lap = 0; lap < laps; ++lap) {
    if (uv->empty()) uv->push_back({u0, vs});
    append_segment_if_long(uv, {u0, vs}, {u0, v0 + r}, spacing);
    append_arc(uv, {u0 + r, v0 + r}, r, M_PI, 1.5 * M_PI, spacing);
    append_segment(uv, {u0 + r, v0}, {u1 - r, v0}, spacing);
    append_arc(uv, {u1 - r, v0 + r}, r, -M_PI / 2, 0, spacing);
    append_segment(uv, {u1, v0 + r}, {u1, v1 - r}, spacing);
    append_arc(uv, {u1 - r, v1 - r}, r, 0, M_PI / 2, spacing);
    append_segment(uv, {u1 - r, v1}, {u0 + r, v1}, spacing);
    append_arc(uv, {u0 + r, v1 - r}, r, M_PI / 2, M_PI, spacing);
    append_segment_if_long(uv, {u0, v1 - r}, {u0, vs}, spacing);
  }
}

/// A lawnmower through `aisles` aisles from `first`, U-turns beyond the row
/// ends; from a plant's dock and back to it when `dock_u` is set.
void append_lawnmower(std::vector<Eigen::Vector2d>* uv, const PvArray& a, const Route& rt, double u0, double u1,
                      std::optional<double> dock_u, double spacing) {
  const int first = rt.first_aisle, last = rt.first_aisle + rt.aisles - 1;
  if (dock_u) append_segment(uv, {*dock_u, aisle_v(a, first, rt.offset_m)}, {u0, aisle_v(a, first, rt.offset_m)}, spacing);
  for (int k = first; k <= last; ++k) {
    const double v = aisle_v(a, k, rt.offset_m);
    const bool forward = (k - first) % 2 == 0;
    const Eigen::Vector2d start(forward ? u0 : u1, v), end(forward ? u1 : u0, v);
    append_segment(uv, start, end, spacing);
    if (k < last) {
      const double v_next = aisle_v(a, k + 1, rt.offset_m);
      const double radius = 0.5 * (v_next - v);
      const Eigen::Vector2d centre(end.x(), v + radius);
      // forward pass ends at u1 and turns through +u; backward through -u
      if (forward)
        append_arc(uv, centre, radius, -M_PI / 2, M_PI / 2, spacing);
      else
        append_arc(uv, centre, radius, -M_PI / 2, -3 * M_PI / 2, spacing);
    }
  }
  const bool odd = rt.aisles % 2 == 1;
  if (dock_u)
    append_return(uv, *dock_u, u1, aisle_v(a, first, rt.offset_m), aisle_v(a, last, rt.offset_m), odd, 0.0, spacing);
  else if (rt.return_to_start)
    append_return(uv, u0, u1, aisle_v(a, first, rt.offset_m), aisle_v(a, last, rt.offset_m), odd,
                  rt.return_overlap_m, spacing);
}

}  // namespace

Eigen::Vector2d array_to_world(const PvArray& a, double u, double v) {
  const double az = a.azimuth_deg * kDegToRad;
  const Eigen::Vector2d eu(std::cos(az), std::sin(az));
  const Eigen::Vector2d ev(-std::sin(az), std::cos(az));
  return a.origin_m + u * eu + v * ev;
}

Eigen::Vector2d world_to_array(const PvArray& a, const Eigen::Vector2d& p_m) {
  const double az = a.azimuth_deg * kDegToRad;
  const Eigen::Vector2d q = p_m - a.origin_m;
  return {q.x() * std::cos(az) + q.y() * std::sin(az), -q.x() * std::sin(az) + q.y() * std::cos(az)};
}

double row_length_m(const PvArray& a) {
  return a.tables_per_row * a.table_length_m() + (a.tables_per_row - 1) * a.table_gap_m;
}

double row_footprint_m(const PvArray& a) {
  // A tracker's row is widest flat: routes keep their clearance at every angle.
  if (a.mount == Mount::kSingleAxis) return a.table_depth_m();
  return a.table_depth_m() * std::cos(a.tilt_deg * kDegToRad);
}

std::vector<Eigen::Vector2d> polyline_from(const std::vector<Eigen::Vector2d>& route, double start_m) {
  if (start_m <= 0.0 || route.size() < 2) return route;
  double along = 0.0;
  for (std::size_t i = 1; i < route.size(); ++i) {
    const double seg = (route[i] - route[i - 1]).norm();
    if (along + seg > start_m) {
      std::vector<Eigen::Vector2d> out{route[i - 1] + (route[i] - route[i - 1]) * ((start_m - along) / seg)};
      out.insert(out.end(), route.begin() + static_cast<std::ptrdiff_t>(i), route.end());
      return out;
    }
    along += seg;
  }
  return {route.back()};
}

double polyline_length(const std::vector<Eigen::Vector2d>& pts) {
  double len = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) len += (pts[i] - pts[i - 1]).norm();
  return len;
}

std::vector<Eigen::Vector2d> route_polyline(const Scenario& s, double spacing_m) {
  const Route& rt = s.route;
  std::vector<Eigen::Vector2d> uv;  // in the array frame for patterns
  std::vector<Eigen::Vector2d> out;
  if (rt.pattern == RoutePattern::kWaypoints) {
    for (std::size_t i = 1; i < rt.waypoints_m.size(); ++i)
      append_segment(&out, rt.waypoints_m[i - 1], rt.waypoints_m[i], spacing_m);
    return out;
  }
  const std::size_t frame = rt.pattern == RoutePattern::kRoads && s.plant ? static_cast<std::size_t>(s.plant->first_array)
                                                                          : static_cast<std::size_t>(rt.array);
  const PvArray& a = s.pv_arrays.at(frame);
  const double u0 = -rt.margin_m;
  const double u1 = row_length_m(a) + rt.margin_m;
  switch (rt.pattern) {
    case RoutePattern::kAlongRow: {
      const double v = aisle_v(a, rt.aisle, rt.offset_m);
      append_segment(&uv, {u0, v}, {u1, v}, spacing_m);
      break;
    }
    case RoutePattern::kLawnmower: {
      std::optional<double> dock_u;
      if (rt.from_dock && s.plant) dock_u = s.plant->dock_front_u_m;
      append_lawnmower(&uv, a, rt, u0, u1, dock_u, spacing_m);
      break;
    }
    case RoutePattern::kRoads:
      if (s.plant) append_road_loop(&uv, *s.plant, rt.block, rt.laps, spacing_m);
      break;
    case RoutePattern::kLoop: {
      const double v0 = -rt.offset_m;
      const double v1 = (a.rows - 1) * a.row_pitch_m + row_footprint_m(a) + rt.offset_m;
      const double r = std::min({1.5, 0.45 * (v1 - v0), 0.45 * (u1 - u0)});
      const double um = 0.5 * (u0 + u1);
      // counter-clockwise from the middle of the front side, `laps` times
      for (int lap = 0; lap < rt.laps; ++lap) {
        append_segment(&uv, {um, v0}, {u1 - r, v0}, spacing_m);
        append_arc(&uv, {u1 - r, v0 + r}, r, -M_PI / 2, 0, spacing_m);
        append_segment(&uv, {u1, v0 + r}, {u1, v1 - r}, spacing_m);
        append_arc(&uv, {u1 - r, v1 - r}, r, 0, M_PI / 2, spacing_m);
        append_segment(&uv, {u1 - r, v1}, {u0 + r, v1}, spacing_m);
        append_arc(&uv, {u0 + r, v1 - r}, r, M_PI / 2, M_PI, spacing_m);
        append_segment(&uv, {u0, v1 - r}, {u0, v0 + r}, spacing_m);
        append_arc(&uv, {u0 + r, v0 + r}, r, M_PI, 1.5 * M_PI, spacing_m);
        append_segment(&uv, {u0 + r, v0}, {um, v0}, spacing_m);
      }
      break;
    }
    case RoutePattern::kWaypoints:
      break;
  }
  out.reserve(uv.size());
  for (const auto& p : uv) out.push_back(array_to_world(a, p.x(), p.y()));
  return out;
}

}  // namespace pvb::scenes
