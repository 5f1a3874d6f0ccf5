#pragma once
// What the scene builder's files share (scene_builder.cpp: the scene, its
// settings, assets and ground; scene_station.cpp: what stands on the
// ground; scene_robot.cpp: the robot and the sun): MJCF text with fixed
// number formatting, and the parts each file writes into the world body.
#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/scene_builder.hpp"

namespace pvb::sim::mjcf {

constexpr double kDeg = M_PI / 180.0;
/// Dust variants of the panels' textures.
constexpr int kDirtVariants = 4;
/// On a relief, posts, walls and trunks reach this far into the ground, so
/// that no gap shows where the ground under them is uneven.
constexpr double kIntoReliefM = 0.15;
/// Depth of a height field's base below its lowest point.
constexpr double kReliefBaseM = 0.5;

// Fixed-precision number formatting so the XML is byte-identical everywhere.
inline std::string f(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}
/// Ten digits, for a height field's placement and size (to a micrometre).
inline std::string exact(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}
inline std::string v3(double a, double b, double c) { return f(a) + " " + f(b) + " " + f(c); }
inline std::string v3(const Eigen::Vector3d& v) { return v3(v.x(), v.y(), v.z()); }

class XmlWriter {
 public:
  std::ostringstream os;
  int indent = 0;
  void line(const std::string& s) { os << std::string(static_cast<std::size_t>(indent) * 2, ' ') << s << "\n"; }
  void open(const std::string& s) {
    line(s);
    ++indent;
  }
  void close(const std::string& s) {
    --indent;
    line(s);
  }
};

// scene_station.cpp
/// The PV array `a` (fixed tables or single-axis trackers), the
/// `index`-th, its dust drawn from `day_seed`.
void add_array(XmlWriter& x, const scenes::PvArray& a, int index, std::uint64_t day_seed, std::uint64_t station_seed,
               const scenes::GroundRelief& ground);
/// The walls: boxes with local x along the wall and local y up, so that
/// the brick texture maps onto the face.  On a relief a wall's top is
/// height_m above the ground at its middle, and it reaches kIntoReliefM
/// below the lowest ground under it.
void add_walls(XmlWriter& x, const scenes::Scenario& s, const scenes::GroundRelief& ground);
/// Vegetation: rejection sampling away from the route, walls and arrays;
/// where the plants stand is the station's.
void add_vegetation(XmlWriter& x, const scenes::Scenario& s, const std::vector<Eigen::Vector2d>& route,
                    const scenes::GroundRelief& ground);

// scene_ground_tiles.cpp
/// The tiles of a varied ground (none for a repeated one): every 3 m cell
/// of the ground whose centre lies within kGroundVariedCorridorM (and half
/// a tile's diagonal) of the route.  A cell's image seed comes from the
/// station's seed and the cell alone, so the route picks which cells are
/// drawn, never how one looks.
std::vector<GroundTile> varied_ground_tiles(const scenes::Scenario& s, const std::vector<Eigen::Vector2d>& route);

// scene_builder.cpp
/// The ground's contact attributes (friction, priority, softness).
std::string ground_friction(const scenes::Ground& g);

// scene_relief_tiles.cpp
/// A tiled relief's height fields (relief_tiles()): the tiles along the
/// route, their far versions (a cell of at least 1 m at 0.25 m), then the
/// coarse backdrop's pieces.
struct ReliefTiles {
  std::vector<RuntimeHField> tiles, far_tiles, backdrop;
};
/// A tiled relief's height fields (none for a grid relief or flat ground).
ReliefTiles relief_tiles(const scenes::Scenario& s, const std::vector<GroundTile>& tiles,
                         const scenes::GroundRelief& ground);
/// kReliefTilesFile's bytes: for each field its name's length, rows and
/// columns (int32), the name, then rows x columns float samples in [0, 1].
std::vector<unsigned char> relief_tiles_file(const ReliefTiles& r);
/// An <hfield> asset whose samples are filled in after compiling.
std::string hfield_asset_line(const RuntimeHField& h);
/// The ground of a tiled relief: the backdrop's pieces (scenery), then each
/// tile, collidable, with its image, then each tile's far version (scenery).
void add_tiled_relief_ground(XmlWriter& x, const scenes::Scenario& s, const std::vector<GroundTile>& tiles,
                             const ReliefTiles& r);

// scene_plant.cpp
/// A plant's materials and its fence's meshes (nothing without a plant).
void add_plant_assets(XmlWriter& x, const scenes::Scenario& s, const scenes::GroundRelief& ground);
/// A plant's fence sections, road pieces, dock and combiner boxes.
void add_plant_fixtures(XmlWriter& x, const scenes::Scenario& s, const scenes::GroundRelief& ground);
/// Whether the scene draws a plant's roads as planes of gravel wherever
/// they run: a plant with roads on a flat ground of shared soil images.
bool draws_road_planes(const scenes::Scenario& s);

// scene_robot.cpp
/// The robot (differential drive, two driven wheels and a caster) at the
/// start of the driven route, its camera, and the sun.
void add_robot_and_sun(XmlWriter& x, const scenes::Scenario& s, const std::vector<Eigen::Vector2d>& driven,
                       const ShadowMap& shadow, const scenes::GroundRelief& ground);

}  // namespace pvb::sim::mjcf
