#pragma once
// The ground under the station: flat (z = 0), or a seeded relief
// (`ground.relief`) sampled on a grid that the simulator hands to MuJoCo as
// a height field.  Everything that stands on the ground, the true surface
// and the check that the robot can drive the route ask this one function.
// Pure: no MuJoCo.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "pvb/scenes/scenario.hpp"

namespace pvb::scenes {

/// Height and upward unit normal of the ground at one point.
struct GroundPoint {
  double z_m = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

/// The surface of a height grid of `nrow` x `ncol` samples over
/// [-half_x, half_x] x [-half_y, half_y], row-major, sample (r, c) at
/// x = -half_x + c dx, y = -half_y + r dy, height `z[r * ncol + c] * scale`
/// (MuJoCo's hfield layout: its data are in [0, 1], scaled by size[2]).
/// Each cell is two flat triangles split along the diagonal from (c, r) to
/// (c + 1, r + 1), as MuJoCo 2.2.2 triangulates a height field for
/// collisions, rays and rendering (engine_collision_convex.c,
/// engine_ray.c, render_context.c).  A point outside the grid takes the
/// nearest edge's value.  Heights are relative to the grid's frame.
template <typename T>
GroundPoint grid_surface(const T* z, double scale, int nrow, int ncol, double half_x, double half_y, double x,
                         double y) {
  const double dx = 2.0 * half_x / (ncol - 1), dy = 2.0 * half_y / (nrow - 1);
  const double gx = std::clamp((x + half_x) / dx, 0.0, ncol - 1.0);
  const double gy = std::clamp((y + half_y) / dy, 0.0, nrow - 1.0);
  const int c = std::min(static_cast<int>(gx), ncol - 2), r = std::min(static_cast<int>(gy), nrow - 2);
  const double fx = gx - c, fy = gy - r;
  const auto at = [&](int rr, int cc) { return static_cast<double>(z[rr * ncol + cc]) * scale; };
  const double z00 = at(r, c), z11 = at(r + 1, c + 1);
  GroundPoint p;
  double sx = 0, sy = 0;  // slopes dz/dx, dz/dy of the triangle
  if (fx >= fy) {         // the triangle (c, r), (c + 1, r), (c + 1, r + 1)
    const double z10 = at(r, c + 1);
    sx = (z10 - z00) / dx;
    sy = (z11 - z10) / dy;
  } else {  // the triangle (c, r), (c, r + 1), (c + 1, r + 1)
    const double z01 = at(r + 1, c);
    sx = (z11 - z01) / dx;
    sy = (z01 - z00) / dy;
  }
  p.z_m = z00 + sx * fx * dx + sy * fy * dy;
  p.normal = Eigen::Vector3d(-sx, -sy, 1.0).normalized();
  return p;
}

/// A grid of heights in metres (see grid_surface for its layout).
struct HeightGrid {
  int nrow = 0, ncol = 0;
  double half_x_m = 0, half_y_m = 0;
  std::vector<double> z_m;  ///< row-major, nrow x ncol
  double min_m() const;
  double max_m() const;
  GroundPoint at(double x, double y) const {
    return grid_surface(z_m.data(), 1.0, nrow, ncol, half_x_m, half_y_m, x, y);
  }
};

/// The ground of a scenario: flat, or its relief for the station's seed.
///
/// The relief is a plane rising by slope_percent towards slope_azimuth_deg
/// (through z = 0 at the origin) plus roughness: a stationary Gaussian field
/// of standard deviation amplitude_cm and covariance
/// exp(-r^2 / (2 scale_m^2)), made as a sum of kReliefWaves cosines whose
/// wave vectors are drawn from that spectrum (N(0, 1 / scale_m^2) per
/// component) and phases uniform, from the station's seed (random-phase
/// spectral synthesis; Shinozuka and Deodatis, Appl. Mech. Rev. 44(4),
/// 1991).  Under a repeated soil it is sampled every cell_m (at most) over
/// ground.size_m into one grid; under a varied soil (tiled) it is sampled
/// on a lattice from the ground's -x -y corner whose spacing divides
/// kReliefTileM (at most cell_m), one sample computed when asked for, so
/// that a ground of any extent holds no grid.  Between samples it is
/// interpolated as MuJoCo interpolates its height field.
class GroundRelief {
 public:
  /// Flat ground: z = 0 everywhere.
  GroundRelief() = default;
  /// The scenario's ground: flat without ground.relief, tiled under a
  /// varied tiling.
  explicit GroundRelief(const Scenario& s);
  /// The relief `r` over a ground of `size_m` from a station seed, one grid
  /// or (`tiled`) a lattice.
  GroundRelief(const Relief& r, const Eigen::Vector2d& size_m, std::uint64_t station_seed,
               bool tiled = false);

  bool flat() const { return !relief_; }
  bool tiled() const { return tiled_; }
  double height_m(double x, double y) const { return at(x, y).z_m; }
  double height_m(const Eigen::Vector2d& p) const { return height_m(p.x(), p.y()); }
  /// Upward unit normal.
  Eigen::Vector3d normal(double x, double y) const { return at(x, y).normal; }
  /// The samples of a grid relief (empty for flat ground and a tiled one).
  const HeightGrid& grid() const { return grid_; }

  /// A tiled relief's lattice: its spacing, the cells along a tile's side,
  /// and the height of sample (i, j) at x = -size_x / 2 + i cell,
  /// y = -size_y / 2 + j cell (any i, j: the field has no edge).
  double lattice_m() const { return lattice_m_; }
  int cells_per_tile() const { return cells_per_tile_; }
  double sample_m(long long i, long long j) const;

 private:
  GroundPoint at(double x, double y) const;
  bool relief_ = false, tiled_ = false;
  HeightGrid grid_;
  // A tiled relief's field and lattice.
  std::vector<Eigen::Vector3d> waves_;  ///< kx, ky (rad/m) and phase of each cosine
  double amp_m_ = 0, grade_x_ = 0, grade_y_ = 0;
  double half_x_m_ = 0, half_y_m_ = 0, lattice_m_ = 0;
  int cells_per_tile_ = 0;
};

/// The side of a tile of a varied ground, which a tiled relief's lattice
/// divides (the simulator's kGroundTileM).
inline constexpr double kReliefTileM = 3.0;
/// Cosines summed for the roughness.
inline constexpr int kReliefWaves = 64;
/// Grid samples a relief may have (MuJoCo draws two triangles per cell
/// every frame).
inline constexpr long long kMaxReliefSamples = 1'000'000;
/// Samples along x and y of a relief of cell `cell_m` over `size_m`: the
/// smallest count that keeps cells at most cell_m.
Eigen::Vector2i relief_samples(const Eigen::Vector2d& size_m, double cell_m);

/// Where the robot cannot drive a route over the relief: the steepest grade
/// along the heading over the wheel base (axle to caster), or across it
/// over the track, beyond kMaxRouteGrade.
struct RouteGradeFault {
  Eigen::Vector2d at_m;  ///< the route point
  double grade = 0;      ///< rise over run, signed
  bool across = false;   ///< across the heading (roll) rather than along it (pitch)
};
/// The steepest grade the robot is asked to drive: 15 % (8.5 degrees).
/// About 72 % of the robot's weight rests on its driven wheels (the rest on
/// the caster), so on wet earth (friction 0.4) traction holds up to a grade
/// of about 0.72 x 0.4 = 29 %; 15 % leaves a margin for bumps and turns.
inline constexpr double kMaxRouteGrade = 0.15;
/// The first point of `route` (route_polyline gives one every 5 cm) where a
/// grade exceeds kMaxRouteGrade.
std::optional<RouteGradeFault> find_route_grade_fault(const GroundRelief& g,
                                                      const std::vector<Eigen::Vector2d>& route,
                                                      double wheel_base_m, double track_m);

}  // namespace pvb::scenes
