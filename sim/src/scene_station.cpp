// What stands on the station's ground, as MJCF: the PV arrays (fixed
// tables on rails and posts, single-axis trackers on torque tubes), the
// walls and the vegetation, each on the ground's relief.
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <set>

#include "pvb/scenes/route.hpp"
#include "scene_mjcf.hpp"
#include "splitmix.hpp"

namespace pvb::sim::mjcf {
namespace {

constexpr double kPanelHalfThicknessM = 0.02;

// Deterministic uniform numbers for placement.
struct Placer {
  explicit Placer(std::uint64_t seed) : gen(seed * 0xD1B54A32D192ED03ull + 17) {}
  double uniform(double a, double b) { return a + (b - a) * (static_cast<double>(gen() >> 11) / 9007199254740992.0); }
  std::mt19937_64 gen;
};

double dist_to_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

/// The panels' dust variants: one drawn per panel from the day's seed.
Placer dust_placer(std::uint64_t day_seed, int index) {
  return Placer(day_seed ^ (0xA11A + static_cast<std::uint64_t>(index)));
}

std::string panel_geom(const std::string& name, double pw, double ph, const Eigen::Vector3d& pos,
                       const std::string& axes, const std::string& material) {
  return "<geom name=\"" + name + "\" class=\"scenery\" type=\"box\" size=\"" + v3(pw / 2, ph / 2, kPanelHalfThicknessM) +
         "\" pos=\"" + v3(pos) + "\" xyaxes=\"" + axes + "\" material=\"" + material + "\"/>";
}

/// The dust variant of every table of `row` with row_soiling: from the
/// station's seed, so the same rows are the dirtier ones every day.
int row_dust_variant(std::uint64_t station_seed, int index, int row) {
  SplitMix pick(station_seed, 0x50170000ULL + 100000ULL * static_cast<std::uint64_t>(index) +
                                  static_cast<std::uint64_t>(row));
  return static_cast<int>(pick.next() % kDirtVariants);
}

/// The marked modules of a slab array, each (row, table, line, column):
/// those shown broken and those gone, drawn from the station's seed.
struct ModuleMarks {
  std::set<std::array<int, 4>> broken, missing;

  /// Whether table `t` of `row` lost any module.
  bool lost_any(int row, int t) const {
    const auto it = missing.lower_bound({row, t, 0, 0});
    return it != missing.end() && (*it)[0] == row && (*it)[1] == t;
  }
};

/// `n` distinct modules of a slab array outside `taken`, from the station's seed and `stream`.
std::set<std::array<int, 4>> seeded_modules(const scenes::PvArray& a, std::uint64_t station_seed,
                                            std::uint64_t stream, int n,
                                            const std::set<std::array<int, 4>>& taken) {
  std::set<std::array<int, 4>> out;
  SplitMix pick(station_seed, stream);
  const auto draw = [&](int k) { return static_cast<int>(pick.next() % static_cast<std::uint64_t>(k)); };
  while (static_cast<int>(out.size()) < n) {
    const std::array<int, 4> m{draw(a.rows), draw(a.tables_per_row), draw(a.panel_lines),
                               draw(a.panels_per_table)};
    if (taken.count(m) == 0) out.insert(m);
  }
  return out;
}

ModuleMarks module_marks(const scenes::PvArray& a, std::uint64_t station_seed, int index) {
  ModuleMarks m;
  const auto i = static_cast<std::uint64_t>(index);
  m.broken = seeded_modules(a, station_seed, 0xB40C0000ULL + i, a.broken_modules, {});
  m.missing = seeded_modules(a, station_seed, 0x6A900000ULL + i, a.missing_modules, m.broken);
  return m;
}

/// Where one table of a slab array lies: `point(u, s)` on its panels'
/// surface (u along the row from the array's start, s across the table
/// from its lower edge), `normal` their face.
struct SlabTable {
  int row = 0, table = 0;
  double u_start = 0;
  std::function<Eigen::Vector3d(double, double)> point;
  Eigen::Vector3d normal;
  std::string axes, name;
};

/// The backsheet and frame under panels centred at `panel_centre`, facing `normal`.
std::string backsheet_geom(const Eigen::Vector3d& panel_centre, const Eigen::Vector3d& normal,
                           const std::string& axes, double length_m, double depth_m) {
  return "<geom class=\"scenery\" type=\"box\" size=\"" + v3(length_m / 2, depth_m / 2, 0.015) + "\" pos=\"" +
         v3(panel_centre - normal * (kPanelHalfThicknessM + 0.016)) + "\" xyaxes=\"" + axes +
         "\" material=\"backsheet\"/>";
}

/// A slab array's table: one slab whose material repeats the module texture
/// once per module (`PREslabK`, scene_builder.cpp), the broken modules'
/// panes just over it, and the backsheet under it.  A table that lost a
/// module is drawn a module at a time (`PREpanelK`), each with its own
/// backsheet, so the gap shows what is under the table.  One dust variant a
/// table: the row's with row_soiling (`row_variant` >= 0), else the day's.
void add_slab_table(XmlWriter& x, const scenes::PvArray& a, const ModuleMarks& marks, const SlabTable& t,
                    const std::string& pre, Placer& rng, int row_variant) {
  const int variant =
      row_variant >= 0 ? row_variant : static_cast<int>(rng.uniform(0, kDirtVariants)) % kDirtVariants;
  const double tl = a.table_length_m(), td = a.table_depth_m();
  const double mw = tl / a.panels_per_table, mh = td / a.panel_lines;
  const bool holed = marks.lost_any(t.row, t.table);
  if (!holed)
    x.line(panel_geom(t.name + "slab", tl, td, t.point(t.u_start + tl / 2, td / 2), t.axes,
                      pre + "slab" + std::to_string(variant)));
  for (int line = 0; holed && line < a.panel_lines; ++line)
    for (int c = 0; c < a.panels_per_table; ++c) {
      if (marks.missing.count({t.row, t.table, line, c}) != 0) continue;
      const Eigen::Vector3d centre = t.point(t.u_start + (c + 0.5) * mw, (line + 0.5) * mh);
      x.line(panel_geom(t.name + "p" + std::to_string(line) + "_" + std::to_string(c), mw, mh, centre, t.axes,
                        pre + "panel" + std::to_string(variant)));
      x.line(backsheet_geom(centre, t.normal, t.axes, mw, mh));
    }
  for (auto it = marks.broken.lower_bound({t.row, t.table, 0, 0});
       it != marks.broken.end() && (*it)[0] == t.row && (*it)[1] == t.table; ++it) {
    const Eigen::Vector3d c = t.point(t.u_start + ((*it)[3] + 0.5) * mw, ((*it)[2] + 0.5) * mh) +
                              t.normal * (kPanelHalfThicknessM + 0.002);
    x.line("<geom name=\"" + t.name + "broken" + std::to_string((*it)[2]) + "_" + std::to_string((*it)[3]) +
           "\" class=\"scenery\" type=\"box\" size=\"" + v3(0.49 * mw, 0.49 * mh, 0.001) + "\" pos=\"" +
           v3(c) + "\" xyaxes=\"" + t.axes + "\" material=\"broken\"/>");
  }
  if (!holed) x.line(backsheet_geom(t.point(t.u_start + tl / 2, td / 2), t.normal, t.axes, tl, td));
}

/// Where a post under `top` starts: on flat ground at z = 0, on a relief
/// kIntoReliefM into the ground.
double post_foot_m(const scenes::GroundRelief& ground, const Eigen::Vector3d& top) {
  return ground.flat() ? 0.0 : ground.height_m(top.x(), top.y()) - kIntoReliefM;
}

/// Fixed tables: each tilted by tilt_deg, facing -v, on rails and four posts.
void add_fixed_array(XmlWriter& x, const scenes::PvArray& a, int index, std::uint64_t day_seed, std::uint64_t station_seed,
                     const scenes::GroundRelief& ground) {
  const double az = a.azimuth_deg * kDeg, tilt = a.tilt_deg * kDeg;
  const Eigen::Vector3d eu(std::cos(az), std::sin(az), 0), ev(-std::sin(az), std::cos(az), 0);
  const Eigen::Vector3d up_slope = std::cos(tilt) * ev + std::sin(tilt) * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d normal = eu.cross(up_slope);  // faces -v and up
  const std::string axes = v3(eu) + " " + v3(up_slope);
  const double pw = a.panel_width_m(), ph = a.panel_height_m(), gap = 0.02;
  const double tl = a.table_length_m(), td = a.table_depth_m();
  Placer rng = dust_placer(day_seed, index);
  const std::string pre = "a" + std::to_string(index);
  const Placer first_table_rng = rng;  // identical_tables: every table draws the first one's variants
  const ModuleMarks marks = module_marks(a, station_seed, index);
  for (int row = 0; row < a.rows; ++row) {
    for (int t = 0; t < a.tables_per_row; ++t) {
      if (a.identical_tables) rng = first_table_rng;
      const double u_start = t * (tl + a.table_gap_m);
      const double v0 = row * a.row_pitch_m;
      // The table stands on the ground at its centre: its panels keep their heights above it.
      const double dz = ground.height_m(scenes::array_to_world(a, u_start + tl / 2, v0 + td / 2 * std::cos(tilt)));
      // table centre on the slope: s = td/2
      auto slope_point = [&](double u, double s) {
        const Eigen::Vector2d g = scenes::array_to_world(a, u, v0 + s * std::cos(tilt));
        return Eigen::Vector3d(g.x(), g.y(), a.clearance_m + s * std::sin(tilt) + dz);
      };
      const std::string tname = pre + "r" + std::to_string(row) + "t" + std::to_string(t);
      if (a.panel_slabs) {
        add_slab_table(x, a, marks, {row, t, u_start, slope_point, normal, axes, tname}, pre, rng,
                       a.row_soiling > 0 ? row_dust_variant(station_seed, index, row) : -1);
      } else {
        for (int line = 0; line < a.panel_lines; ++line) {
          for (int c = 0; c < a.panels_per_table; ++c) {
            const double u = u_start + c * (pw + gap) + pw / 2;
            const double s = line * (ph + gap) + ph / 2;
            const int variant = static_cast<int>(rng.uniform(0, kDirtVariants)) % kDirtVariants;
            x.line(panel_geom(tname + "p" + std::to_string(line) + "_" + std::to_string(c), pw, ph, slope_point(u, s),
                              axes, pre + "panel" + std::to_string(variant)));
          }
        }
        x.line(
            backsheet_geom(slope_point(u_start + tl / 2, td / 2), normal, axes, tl, td));  // one box a table
      }
      if (a.rails) {
        for (double sf : {0.22, 0.78}) {
          const Eigen::Vector3d p = slope_point(u_start + tl / 2, td * sf) - normal * 0.09;
          x.line("<geom class=\"scenery\" type=\"box\" size=\"" + v3(tl / 2 + 0.05, 0.03, 0.025) + "\" pos=\"" + v3(p) +
                 "\" xyaxes=\"" + axes + "\" material=\"steel\"/>");
        }
      }
      if (a.posts) {
        for (double uf : {0.12, 0.88}) {
          for (double sf : {0.22, 0.78}) {
            const Eigen::Vector3d top = slope_point(u_start + tl * uf, td * sf) - normal * 0.11;
            const double foot = post_foot_m(ground, top);
            x.line("<geom class=\"scenery\" type=\"box\" size=\"" + v3(0.04, 0.04, (top.z() - foot) / 2) +
                   "\" pos=\"" + v3(top.x(), top.y(), (top.z() + foot) / 2) + "\" euler=\"0 0 " + f(a.azimuth_deg) +
                   "\" material=\"steel\"/>");
          }
        }
      }
    }
  }
}

/// Single-axis trackers: each row's tables on a torque tube along u at the
/// row's middle, turned by rotation_deg (right-handed about +u, 0 flat), on
/// two posts per table.  The panels sit kTrackerPanelAboveAxisM above the
/// tube's axis along their normal.
void add_tracker_array(XmlWriter& x, const scenes::PvArray& a, int index, std::uint64_t day_seed, std::uint64_t station_seed,
                       const scenes::GroundRelief& ground) {
  const double az = a.azimuth_deg * kDeg, rot = a.rotation_deg * kDeg;
  const Eigen::Vector3d eu(std::cos(az), std::sin(az), 0), ev(-std::sin(az), std::cos(az), 0);
  const Eigen::Vector3d across = std::cos(rot) * ev + std::sin(rot) * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d normal = std::cos(rot) * Eigen::Vector3d::UnitZ() - std::sin(rot) * ev;
  const std::string axes = v3(eu) + " " + v3(across);
  const double pw = a.panel_width_m(), ph = a.panel_height_m(), gap = 0.02;
  const double tl = a.table_length_m(), td = a.table_depth_m(), h = a.axis_height_m();
  Placer rng = dust_placer(day_seed, index);
  const Placer first_table_rng = rng;
  const std::string pre = "a" + std::to_string(index);
  const ModuleMarks marks = module_marks(a, station_seed, index);
  for (int row = 0; row < a.rows; ++row) {
    for (int t = 0; t < a.tables_per_row; ++t) {
      if (a.identical_tables) rng = first_table_rng;
      const double u_start = t * (tl + a.table_gap_m);
      const double dz = ground.height_m(scenes::array_to_world(a, u_start + tl / 2, row * a.row_pitch_m + td / 2));
      const auto axis_point = [&](double u) {
        const Eigen::Vector2d g = scenes::array_to_world(a, u, row * a.row_pitch_m + td / 2);
        return Eigen::Vector3d(g.x(), g.y(), h + dz);
      };
      // s from the table's lower (-across) edge, as for fixed tables.
      // Returns a vector, not an Eigen expression: that would refer to
      // axis_point's temporary after the lambda returns.
      const auto plane_point = [&](double u, double s) -> Eigen::Vector3d {
        return axis_point(u) + (s - td / 2) * across + scenes::kTrackerPanelAboveAxisM * normal;
      };
      const std::string tname = pre + "r" + std::to_string(row) + "t" + std::to_string(t);
      if (a.panel_slabs) {
        add_slab_table(x, a, marks, {row, t, u_start, plane_point, normal, axes, tname}, pre, rng,
                       a.row_soiling > 0 ? row_dust_variant(station_seed, index, row) : -1);
      } else {
        for (int line = 0; line < a.panel_lines; ++line)
          for (int c = 0; c < a.panels_per_table; ++c) {
            const int variant = static_cast<int>(rng.uniform(0, kDirtVariants)) % kDirtVariants;
            x.line(panel_geom(tname + "p" + std::to_string(line) + "_" + std::to_string(c), pw, ph,
                              plane_point(u_start + c * (pw + gap) + pw / 2, line * (ph + gap) + ph / 2), axes,
                              pre + "panel" + std::to_string(variant)));
          }
        x.line(backsheet_geom(plane_point(u_start + tl / 2, td / 2), normal, axes, tl, td));
      }
      const Eigen::Vector3d mid = axis_point(u_start + tl / 2);
      x.line("<geom class=\"scenery\" type=\"box\" size=\"" + v3(tl / 2 + 0.1, 0.06, 0.06) + "\" pos=\"" + v3(mid) +
             "\" xyaxes=\"" + axes + "\" material=\"steel\"/>");
      if (a.posts)
        for (double uf : {0.15, 0.85}) {
          const Eigen::Vector3d top = axis_point(u_start + tl * uf) - Eigen::Vector3d(0, 0, 0.06);
          const double foot = post_foot_m(ground, top);
          x.line("<geom class=\"scenery\" type=\"box\" size=\"" + v3(0.05, 0.05, (top.z() - foot) / 2) +
                 "\" pos=\"" + v3(top.x(), top.y(), (top.z() + foot) / 2) + "\" euler=\"0 0 " + f(a.azimuth_deg) +
                 "\" material=\"steel\"/>");
        }
    }
  }
}

/// The lowest ground under a wall's footprint (sampled every 5 cm along
/// both faces and the centre line), or 0 on flat ground.
double lowest_ground_under(const scenes::GroundRelief& ground, const scenes::Wall& w) {
  if (ground.flat()) return 0.0;
  const Eigen::Vector2d along = w.end_m - w.start_m;
  const Eigen::Vector2d side = Eigen::Vector2d(-along.y(), along.x()).normalized() * (w.thickness_m / 2);
  const int n = static_cast<int>(std::ceil(along.norm() / 0.05));
  double lowest = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= n; ++k)
    for (double sf : {-1.0, 0.0, 1.0})
      lowest = std::min(lowest, ground.height_m(w.start_m + along * (static_cast<double>(k) / n) + sf * side));
  return lowest;
}


/// Whether a plant of `radius` at p keeps veg.keep_out_m from the route,
/// the walls and the arrays' footprints.
bool clear_of_everything(const scenes::Scenario& s, const std::vector<Eigen::Vector2d>& route,
                         const Eigen::Vector2d& p, double radius) {
  const double keep = s.vegetation.keep_out_m + radius;
  for (std::size_t i = 1; i < route.size(); i += 4)
    if (dist_to_segment(p, route[i - 1], route[std::min(i + 3, route.size() - 1)]) < keep) return false;
  for (const auto& w : s.walls)
    if (dist_to_segment(p, w.start_m, w.end_m) < keep + w.thickness_m / 2) return false;
  for (const auto& a : s.pv_arrays) {
    const Eigen::Vector2d uv = scenes::world_to_array(a, p);
    const double u = uv.x(), v = uv.y();
    const double len = scenes::row_length_m(a);
    const double depth = (a.rows - 1) * a.row_pitch_m + scenes::row_footprint_m(a);
    if (u > -keep && u < len + keep && v > -keep && v < depth + keep) return false;
  }
  return true;
}

/// One plant, `size` at its station size, grown by the day's growth where
/// it stands (so that it stands in the same place every day), on the ground
/// where it stands (a trunk kIntoReliefM into a relief).
void add_plant(XmlWriter& x, const std::string& n, bool tree, const Eigen::Vector2d& p, double size,
               double growth, Placer& rng, const scenes::GroundRelief& ground) {
  const double grown = size * growth, z0 = ground.height_m(p);
  if (tree) {
    const double trunk_h = 0.45 * grown, crown = 0.3 * grown, into = ground.flat() ? 0.0 : kIntoReliefM;
    x.line("<geom name=\"" + n + "_trunk\" class=\"scenery\" type=\"cylinder\" size=\"" +
           v3(0.06 + 0.02 * grown, (trunk_h + into) / 2, 0) + "\" pos=\"" +
           v3(p.x(), p.y(), z0 + (trunk_h - into) / 2) + "\" material=\"bark\"/>");
    const double yaw_deg = rng.uniform(0, 180), crown_y = crown * rng.uniform(0.8, 1.1);
    x.line("<geom name=\"" + n + "_crown\" class=\"scenery\" type=\"ellipsoid\" size=\"" +
           v3(crown, crown_y, 0.55 * grown * 0.6) + "\" pos=\"" + v3(p.x(), p.y(), z0 + trunk_h + 0.25 * grown) +
           "\" euler=\"0 0 " + f(yaw_deg) + "\" material=\"foliage\"/>");
    return;
  }
  const double r = grown / 2;
  const double yaw_deg = rng.uniform(0, 180), r_z = r * rng.uniform(0.6, 0.9), r_y = r * rng.uniform(0.7, 1.0);
  x.line("<geom name=\"" + n + "\" class=\"scenery\" type=\"ellipsoid\" size=\"" + v3(r, r_y, r_z) + "\" pos=\"" +
         v3(p.x(), p.y(), z0 + r * 0.55) + "\" euler=\"0 0 " + f(yaw_deg) + "\" material=\"foliage\"/>");
  const double dy = rng.uniform(-r, r), dx = rng.uniform(-r, r);
  const Eigen::Vector2d q = p + Eigen::Vector2d(dx, dy) * 0.6;
  x.line("<geom name=\"" + n + "b\" class=\"scenery\" type=\"ellipsoid\" size=\"" + v3(r * 0.7, r * 0.6, r * 0.55) +
         "\" pos=\"" + v3(q.x(), q.y(), ground.height_m(q) + r * 0.5) + "\" material=\"foliage\"/>");
}

}  // namespace

void add_array(XmlWriter& x, const scenes::PvArray& a, int index, std::uint64_t day_seed, std::uint64_t station_seed,
               const scenes::GroundRelief& ground) {
  if (a.mount == scenes::Mount::kSingleAxis)
    add_tracker_array(x, a, index, day_seed, station_seed, ground);
  else
    add_fixed_array(x, a, index, day_seed, station_seed, ground);
}

void add_walls(XmlWriter& x, const scenes::Scenario& s, const scenes::GroundRelief& ground) {
  for (std::size_t i = 0; i < s.walls.size(); ++i) {
    const scenes::Wall& w = s.walls[i];
    const Eigen::Vector2d d = (w.end_m - w.start_m).normalized();
    const Eigen::Vector2d mid = 0.5 * (w.start_m + w.end_m);
    const double len = (w.end_m - w.start_m).norm();
    const double top = ground.height_m(mid) + w.height_m;
    const double foot = ground.flat() ? 0.0 : lowest_ground_under(ground, w) - kIntoReliefM;
    const char* material = w.finish == scenes::WallFinish::kPlaster ? "plaster" : "brick";
    x.line("<geom name=\"wall" + std::to_string(i) + "\" class=\"scenery\" type=\"box\" size=\"" +
           v3(len / 2, (top - foot) / 2, w.thickness_m / 2) + "\" pos=\"" + v3(mid.x(), mid.y(), (top + foot) / 2) +
           "\" xyaxes=\"" + v3(d.x(), d.y(), 0) + " 0 0 1\" material=\"" + material + "\"/>");
  }
}

void add_vegetation(XmlWriter& x, const scenes::Scenario& s, const std::vector<Eigen::Vector2d>& route,
                    const scenes::GroundRelief& ground) {
  const scenes::Vegetation& veg = s.vegetation;
  Placer rng(s.station_seed_or_seed() ^ 0x5EED5EED);
  int placed = 0;
  const int total = veg.shrubs + veg.trees;
  for (int attempt = 0; attempt < 200 * std::max(total, 1) && placed < total; ++attempt) {
    const bool tree = placed >= veg.shrubs;
    const double size = tree ? rng.uniform(veg.tree_height_m.x(), veg.tree_height_m.y())
                             : rng.uniform(veg.shrub_size_m.x(), veg.shrub_size_m.y());
    const double y_m = rng.uniform(veg.area_m[1], veg.area_m[3]), x_m = rng.uniform(veg.area_m[0], veg.area_m[2]);
    const Eigen::Vector2d p(x_m, y_m);
    const double radius = tree ? 0.3 * size : 0.5 * size;
    if (!clear_of_everything(s, route, p, radius)) continue;
    add_plant(x, (tree ? "tree" : "shrub") + std::to_string(placed), tree, p, size, veg.growth, rng, ground);
    ++placed;
  }
}

}  // namespace pvb::sim::mjcf
