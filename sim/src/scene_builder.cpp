#include "pvb/sim/scene_builder.hpp"

#include <sys/stat.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/route.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/sim/textures.hpp"

namespace pvb::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr int kDirtVariants = 4;
constexpr double kPanelHalfThicknessM = 0.02;
/// On a relief, posts, walls and trunks reach this far into the ground, so
/// that no gap shows where the ground under them is uneven.
constexpr double kIntoReliefM = 0.15;
/// Depth of the height field's base below its lowest point.
constexpr double kReliefBaseM = 0.5;

// Fixed-precision number formatting so the XML is byte-identical everywhere.
std::string f(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}
std::string v3(double a, double b, double c) { return f(a) + " " + f(b) + " " + f(c); }
std::string v3(const Eigen::Vector3d& v) { return v3(v.x(), v.y(), v.z()); }
/// Ten digits, for the height field's placement and size (to a micrometre).
std::string exact(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

constexpr const char* kGroundTilePrefix = "textures/groundt";

/// zlib's level for a texture file as recordings write it: level 6 for the
/// station's few images (their bytes are pinned, tests/sim/test_old_bytes.cpp);
/// level 1 for a varied ground's many tiles, which encodes 3x faster for
/// 7 % more bytes (the pixels MuJoCo decodes are the same).
int file_zlib_level(const std::string& path) { return path.rfind(kGroundTilePrefix, 0) == 0 ? 1 : 6; }

std::vector<unsigned char> png_of_bgr(const cv::Mat& bgr, int zlib_level) {
  std::vector<unsigned char> out;
  cv::imencode(".png", bgr, out, {cv::IMWRITE_PNG_COMPRESSION, zlib_level});
  return out;
}

/// The PNG file `path` of an RGB image, compressed as `compression` says.
std::vector<unsigned char> png(const cv::Mat& rgb_img, const std::string& path, PngCompression compression) {
  cv::Mat bgr;
  cv::cvtColor(rgb_img, bgr, cv::COLOR_RGB2BGR);
  return png_of_bgr(bgr, compression == PngCompression::kStored ? 0 : file_zlib_level(path));
}

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

/// The panels' dust variants: one drawn per panel from the day's seed.
Placer dust_placer(std::uint64_t day_seed, int index) {
  return Placer(day_seed ^ (0xA11A + static_cast<std::uint64_t>(index)));
}

std::string panel_geom(const std::string& name, double pw, double ph, const Eigen::Vector3d& pos,
                       const std::string& axes, const std::string& material) {
  return "<geom name=\"" + name + "\" class=\"scenery\" type=\"box\" size=\"" + v3(pw / 2, ph / 2, kPanelHalfThicknessM) +
         "\" pos=\"" + v3(pos) + "\" xyaxes=\"" + axes + "\" material=\"" + material + "\"/>";
}

/// Where a post under `top` starts: on flat ground at z = 0, on a relief
/// kIntoReliefM into the ground.
double post_foot_m(const scenes::GroundRelief& ground, const Eigen::Vector3d& top) {
  return ground.flat() ? 0.0 : ground.height_m(top.x(), top.y()) - kIntoReliefM;
}

/// Fixed tables: each tilted by tilt_deg, facing -v, on rails and four posts.
void add_fixed_array(XmlWriter& x, const scenes::PvArray& a, int index, std::uint64_t day_seed,
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
      for (int line = 0; line < a.panel_lines; ++line) {
        for (int c = 0; c < a.panels_per_table; ++c) {
          const double u = u_start + c * (pw + gap) + pw / 2;
          const double s = line * (ph + gap) + ph / 2;
          const int variant = static_cast<int>(rng.uniform(0, kDirtVariants)) % kDirtVariants;
          x.line(panel_geom(tname + "p" + std::to_string(line) + "_" + std::to_string(c), pw, ph, slope_point(u, s), axes,
                            pre + "panel" + std::to_string(variant)));
        }
      }
      // backsheet and frame structure under the panels, one box per table
      const Eigen::Vector3d centre = slope_point(u_start + tl / 2, td / 2);
      x.line("<geom class=\"scenery\" type=\"box\" size=\"" + v3(tl / 2, td / 2, 0.015) + "\" pos=\"" +
             v3(centre - normal * (kPanelHalfThicknessM + 0.016)) + "\" xyaxes=\"" + axes +
             "\" material=\"backsheet\"/>");
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
void add_tracker_array(XmlWriter& x, const scenes::PvArray& a, int index, std::uint64_t day_seed,
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
      for (int line = 0; line < a.panel_lines; ++line)
        for (int c = 0; c < a.panels_per_table; ++c) {
          const int variant = static_cast<int>(rng.uniform(0, kDirtVariants)) % kDirtVariants;
          x.line(panel_geom(tname + "p" + std::to_string(line) + "_" + std::to_string(c), pw, ph,
                            plane_point(u_start + c * (pw + gap) + pw / 2, line * (ph + gap) + ph / 2), axes,
                            pre + "panel" + std::to_string(variant)));
        }
      const Eigen::Vector3d mid = axis_point(u_start + tl / 2);
      x.line("<geom class=\"scenery\" type=\"box\" size=\"" + v3(tl / 2, td / 2, 0.015) + "\" pos=\"" +
             v3(plane_point(u_start + tl / 2, td / 2) - normal * (kPanelHalfThicknessM + 0.016)) + "\" xyaxes=\"" +
             axes + "\" material=\"backsheet\"/>");
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

void add_array(XmlWriter& x, const scenes::PvArray& a, int index, std::uint64_t day_seed,
               const scenes::GroundRelief& ground) {
  if (a.mount == scenes::Mount::kSingleAxis)
    add_tracker_array(x, a, index, day_seed, ground);
  else
    add_fixed_array(x, a, index, day_seed, ground);
}

}  // namespace

ShadowMap shadow_map_for(const scenes::Light& light, const std::vector<Eigen::Vector2d>& route_xy_m) {
  ShadowMap m;
  m.follows_robot = light.shadow_follows_robot;
  if (!m.follows_robot && !route_xy_m.empty()) {
    Eigen::Vector2d lo = route_xy_m.front(), hi = route_xy_m.front();
    for (const auto& p : route_xy_m) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    m.centre_xy_m = 0.5 * (lo + hi);
    // The map is a square turned with the sun's azimuth: a circle through
    // the box's corners, plus the margin, fits in it whatever the turn.
    m.half_width_m = 0.5 * (hi - lo).norm() + kShadowMarginM;
  }
  if (light.shadow_map_px > 0) {
    m.size_px = light.shadow_map_px;
  } else {
    m.size_px = 1024;
    while (m.size_px < 8192 && m.texel_m() > kShadowTexelTargetM) m.size_px *= 2;
  }
  return m;
}

namespace {

/// One 3 m tile of a varied ground: its centre and its image's seed.
struct GroundTile {
  Eigen::Vector2d centre_m;
  std::uint64_t seed = 0;
};

/// The tiles of a varied ground (none for a repeated one): every 3 m cell
/// of the ground whose centre lies within kGroundVariedCorridorM (and half
/// a tile's diagonal) of the route.  A cell's image seed comes from the
/// station's seed and the cell alone, so the route picks which cells are
/// drawn, never how one looks.
std::vector<GroundTile> varied_ground_tiles(const scenes::Scenario& s, const std::vector<Eigen::Vector2d>& route) {
  if (s.ground.drawn_tiling() != scenes::GroundTiling::kVaried) return {};
  const double tile = kGroundTileM, half_x = s.ground.size_m.x() / 2, half_y = s.ground.size_m.y() / 2;
  const double reach = kGroundVariedCorridorM + tile / std::sqrt(2.0);
  const auto cells_x = static_cast<long long>(std::floor(s.ground.size_m.x() / tile + 1e-9));
  const auto cells_y = static_cast<long long>(std::floor(s.ground.size_m.y() / tile + 1e-9));
  const auto centre = [&](long long i, long long j) {
    return Eigen::Vector2d(-half_x + (static_cast<double>(i) + 0.5) * tile,
                           -half_y + (static_cast<double>(j) + 0.5) * tile);
  };
  // The cells within reach of each route point (a window of cells around it), in (i, j) order.
  std::set<std::pair<long long, long long>> cells;
  for (const Eigen::Vector2d& p : route) {
    const auto first = [&](double v, double half) { return static_cast<long long>(std::floor((v + half) / tile)); };
    const long long i0 = std::max(0LL, first(p.x() - reach, half_x));
    const long long i1 = std::min(cells_x - 1, first(p.x() + reach, half_x));
    const long long j0 = std::max(0LL, first(p.y() - reach, half_y));
    const long long j1 = std::min(cells_y - 1, first(p.y() + reach, half_y));
    for (long long i = i0; i <= i1; ++i)
      for (long long j = j0; j <= j1; ++j)
        if ((p - centre(i, j)).norm() <= reach) cells.insert({i, j});
  }
  if (cells.size() > static_cast<std::size_t>(kMaxGroundTiles))
    throw ConfigError(s.source_file, "ground.tiling",
                      "a varied ground (the default) of at most " + std::to_string(kMaxGroundTiles) + " tiles of " +
                          f(tile) + " m along the route (a route of about 140 m), or tiling: repeat",
                      std::to_string(cells.size()) + " tiles");
  std::vector<GroundTile> tiles;
  for (const auto& [i, j] : cells) {
    const auto cell = static_cast<std::uint64_t>(i * cells_y + j);
    tiles.push_back({centre(i, j), s.station_seed_or_seed() * 2654435761ULL + 1000003ULL * (cell + 1)});
  }
  return tiles;
}

/// The textures: the station's, but for the day's dust on the panels.  A
/// geometry-only scene names the same files, each a 1x1 grey image.
void add_textures(const scenes::Scenario& s, const std::vector<GroundTile>& tiles, SceneDetail detail,
                  SceneAssets* out) {
  const bool full = detail == SceneDetail::kFull;
  const PngCompression compression = out->png;
  const std::vector<unsigned char> grey =
      full ? std::vector<unsigned char>{}
           : png(cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(128)), "textures/grey.png", compression);
  const auto add = [&](const std::string& name, const std::function<cv::Mat()>& draw) {
    const std::string path = "textures/" + name + ".png";
    out->files.emplace_back(path, full ? png(draw(), path, compression) : grey);
  };
  const std::uint64_t station_seed = s.station_seed_or_seed(), day_seed = s.seed;
  add("ground", [&] { return make_ground_texture(s.ground.type, station_seed); });
  // A tile's image depends on its seed alone: drawn and encoded on every core.
  std::vector<std::vector<unsigned char>> tile_png(tiles.size(), grey);
  if (full)
    cv::parallel_for_(cv::Range(0, static_cast<int>(tiles.size())), [&](const cv::Range& range) {
      for (int k = range.start; k < range.end; ++k)
        tile_png[k] = png(make_ground_texture(s.ground.type, tiles[k].seed), kGroundTilePrefix, compression);
    });
  for (std::size_t k = 0; k < tiles.size(); ++k)
    out->files.emplace_back(kGroundTilePrefix + std::to_string(k) + ".png", std::move(tile_png[k]));
  add("brick", [&] { return make_brick_texture(station_seed); });
  add("foliage", [&] { return make_foliage_texture(station_seed); });
  add("bark", [&] { return make_bark_texture(station_seed); });
  for (std::size_t i = 0; i < s.pv_arrays.size(); ++i) {
    for (int k = 0; k < kDirtVariants; ++k) {
      // variant 0 is the cleanest; dirt grows with k up to the array's level
      const double dirt = s.pv_arrays[i].dirt * (0.55 + 0.15 * k);
      add("a" + std::to_string(i) + "panel" + std::to_string(k), [&] {
        return make_panel_texture(s.pv_arrays[i], dirt, station_seed * 131 + i * 17 + k, day_seed * 131 + i * 17 + k);
      });
    }
  }
}

/// The model's header: compiler, physics step, visual (image size, shadow
/// map, depth range, headlight) and the scenery class.
void write_settings(XmlWriter& x, const scenes::Scenario& s, const SceneAssets& out, const ShadowMap& shadow) {
  // Scene size: the ground's diagonal bounds every distance in the scene.
  // Depth mapping: z_far = 2.5 * diag keeps the skybox (drawn beyond ~0.6
  // z_far) separable from geometry; z_near 0.05 m.
  const double diag = std::hypot(s.ground.size_m.x(), s.ground.size_m.y()) + 20.0;
  const double extent = diag / 2;
  const double znear_m = 0.05, zfar_m = 2.5 * diag;
  x.line("<!-- generated by pvbench from " + (s.source_file.empty() ? std::string("code") : s.source_file) +
         (s.station_seed ? ", station seed " + std::to_string(*s.station_seed) : std::string()) + ", seed " +
         std::to_string(s.seed) + " -->");
  x.line("<compiler angle=\"degree\" autolimits=\"true\"/>");
  char step[40];
  std::snprintf(step, sizeof step, "%.17g", out.timestep_s);  // exact: a frame is `substeps` steps
  x.line("<option timestep=\"" + std::string(step) + "\" integrator=\"implicit\" cone=\"elliptic\"/>");
  x.line("<statistic extent=\"" + f(extent) + "\" center=\"0 0 0\"/>");
  x.open("<visual>");
  const bool stereo = s.camera.model == scenes::CameraKind::kD435;  // the infrared views may be larger
  const int off_w = stereo ? std::max(s.camera.width, s.camera.stereo.ir_width) : s.camera.width;
  const int off_h = stereo ? std::max(s.camera.height, s.camera.stereo.ir_height) : s.camera.height;
  x.line("<global offwidth=\"" + std::to_string(off_w) + "\" offheight=\"" + std::to_string(off_h) + "\" fovy=\"" +
         f(s.camera.fovy_deg()) + "\"/>");
  // numquads: box faces drawn as numquads x numquads quads (MuJoCo: 4).
  // The subdivision only serves per-vertex lighting; with a directional sun
  // 1 changes the colour image by 0.004 of 255 on average and saves a
  // fifth of the render time (docs/run.md, "Where the time goes").
  x.line("<quality shadowsize=\"" + std::to_string(shadow.size_px) + "\" offsamples=\"0\" numquads=\"" +
         std::to_string(s.light.box_quads) + "\"/>");
  x.line("<map znear=\"" + f(znear_m / extent) + "\" zfar=\"" + f(zfar_m / extent) + "\" shadowclip=\"" +
         f(shadow.half_width_m / extent) + "\" shadowscale=\"0.6\"/>");
  const double amb = s.light.ambient;
  x.line("<headlight ambient=\"" + v3(amb, amb, amb) + "\" diffuse=\"0 0 0\" specular=\"0 0 0\"/>");
  x.close("</visual>");

  x.open("<default>");
  x.open("<default class=\"scenery\">");
  x.line("<geom contype=\"0\" conaffinity=\"0\" group=\"1\"/>");
  x.close("</default>");
  x.close("</default>");
}

/// The relief's samples in MuJoCo's own height-field file format: int32
/// rows, int32 columns, then rows x columns float32 heights, row-major, row
/// 0 at -y (MuJoCo scales them to [0, 1]; size[2] scales them back).
std::vector<unsigned char> hfield_file(const scenes::HeightGrid& g) {
  const std::int32_t dims[2] = {g.nrow, g.ncol};
  std::vector<unsigned char> out(sizeof dims + g.z_m.size() * sizeof(float));
  std::memcpy(out.data(), dims, sizeof dims);
  const double lowest = g.min_m();
  for (std::size_t i = 0; i < g.z_m.size(); ++i) {
    const float v = static_cast<float>(g.z_m[i] - lowest);
    std::memcpy(out.data() + sizeof dims + i * sizeof(float), &v, sizeof v);
  }
  return out;
}

/// The relief's height field: the ground's extent, its height range and a
/// base kReliefBaseM deep under its lowest point.
std::string hfield_line(const scenes::Scenario& s, const scenes::GroundRelief& ground) {
  const double range = std::max(ground.grid().max_m() - ground.grid().min_m(), 1e-6);  // MuJoCo: positive
  return "<hfield name=\"ground\" file=\"" + std::string(kReliefFile) + "\" size=\"" +
         exact(s.ground.size_m.x() / 2) + " " + exact(s.ground.size_m.y() / 2) + " " + exact(range) + " " +
         f(kReliefBaseM) + "\"/>";
}

/// Textures and materials (and the relief's height field).
void write_assets(XmlWriter& x, const scenes::Scenario& s, const SceneAssets& out, const scenes::GroundRelief& ground) {
  x.open("<asset>");
  if (!ground.flat()) x.line(hfield_line(s, ground));
  const auto rgb = [](const Eigen::Vector3f& c) {  // two decimals, as the sky was always written
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.2f %.2f %.2f", c.x(), c.y(), c.z());
    return std::string(buf);
  };
  x.line("<texture name=\"sky\" type=\"skybox\" builtin=\"gradient\" rgb1=\"" + rgb(kSkyZenithRgb) + "\" rgb2=\"" +
         rgb(kSkyHorizonRgb) + "\" width=\"512\" height=\"512\"/>");
  const auto texture = [](const std::string& path) { return path.rfind("textures/", 0) == 0; };
  for (const auto& file : out.files) {
    if (!texture(file.first)) continue;
    const std::string name = file.first.substr(9, file.first.size() - 13);  // textures/NAME.png
    x.line("<texture name=\"" + name + "\" type=\"2d\" file=\"" + file.first + "\"/>");
  }
  // The materials after every texture, as a scene without varied ground always had them.
  for (const auto& file : out.files) {
    if (!texture(file.first)) continue;
    const std::string name = file.first.substr(9, file.first.size() - 13);  // textures/NAME.png
    if (name.rfind("ground", 0) != 0) continue;  // the ground, and a varied ground's tiles
    x.line("<material name=\"" + name + "\" texture=\"" + name + "\" texuniform=\"true\" texrepeat=\"" +
           f(1.0 / kGroundTileM) + " " + f(1.0 / kGroundTileM) + "\" specular=\"0.02\" shininess=\"0.05\"/>");
  }
  x.line("<material name=\"brick\" texture=\"brick\" texuniform=\"true\" texrepeat=\"" + f(1.0 / kBrickTileWidthM) +
         " " + f(1.0 / kBrickTileHeightM) + "\" specular=\"0.05\" shininess=\"0.1\"/>");
  x.line("<material name=\"foliage\" texture=\"foliage\" texuniform=\"true\" texrepeat=\"2 2\" specular=\"0.05\"/>");
  x.line("<material name=\"bark\" texture=\"bark\" texuniform=\"true\" texrepeat=\"4 4\" specular=\"0.02\"/>");
  for (std::size_t i = 0; i < s.pv_arrays.size(); ++i)
    for (int k = 0; k < kDirtVariants; ++k) {
      const std::string n = "a" + std::to_string(i) + "panel" + std::to_string(k);
      // Diffuse glass: a strong, tight highlight.  Specular glass: the
      // cells only; the sensor model mirrors the sky and the sun (glass.hpp).
      const double specular = s.pv_arrays[i].specular_glass ? 0.0 : 0.9 - 0.4 * s.pv_arrays[i].dirt;
      x.line("<material name=\"" + n + "\" texture=\"" + n + "\" specular=\"" + f(specular) + "\" shininess=\"0.85\"/>");
    }
  // Plaster: one flat colour, matte (walls with finish: plaster).
  x.line("<material name=\"plaster\" rgba=\"0.78 0.76 0.72 1\" specular=\"0.02\" shininess=\"0.05\"/>");
  x.line("<material name=\"backsheet\" rgba=\"0.80 0.81 0.82 1\" specular=\"0.1\"/>");
  x.line("<material name=\"steel\" rgba=\"0.58 0.60 0.62 1\" specular=\"0.4\" shininess=\"0.4\"/>");
  x.line("<material name=\"robot\" rgba=\"0.95 0.55 0.10 1\" specular=\"0.3\"/>");
  x.line("<material name=\"tyre\" rgba=\"0.08 0.08 0.08 1\"/>");
  x.close("</asset>");
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

/// The walls: boxes with local x along the wall and local y up, so that
/// the brick texture maps onto the face.  On a relief a wall's top is
/// height_m above the ground at its middle, and it reaches kIntoReliefM
/// below the lowest ground under it.
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
    // inverse of array_to_world
    const double az = a.azimuth_deg * kDeg;
    const Eigen::Vector2d q = p - a.origin_m;
    const double u = q.x() * std::cos(az) + q.y() * std::sin(az);
    const double v = -q.x() * std::sin(az) + q.y() * std::cos(az);
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
    x.line("<geom name=\"" + n + "_crown\" class=\"scenery\" type=\"ellipsoid\" size=\"" +
           v3(crown, crown * rng.uniform(0.8, 1.1), 0.55 * grown * 0.6) + "\" pos=\"" +
           v3(p.x(), p.y(), z0 + trunk_h + 0.25 * grown) + "\" euler=\"0 0 " + f(rng.uniform(0, 180)) +
           "\" material=\"foliage\"/>");
    return;
  }
  const double r = grown / 2;
  x.line("<geom name=\"" + n + "\" class=\"scenery\" type=\"ellipsoid\" size=\"" +
         v3(r, r * rng.uniform(0.7, 1.0), r * rng.uniform(0.6, 0.9)) + "\" pos=\"" +
         v3(p.x(), p.y(), z0 + r * 0.55) + "\" euler=\"0 0 " + f(rng.uniform(0, 180)) + "\" material=\"foliage\"/>");
  const Eigen::Vector2d q = p + Eigen::Vector2d(rng.uniform(-r, r), rng.uniform(-r, r)) * 0.6;
  x.line("<geom name=\"" + n + "b\" class=\"scenery\" type=\"ellipsoid\" size=\"" + v3(r * 0.7, r * 0.6, r * 0.55) +
         "\" pos=\"" + v3(q.x(), q.y(), ground.height_m(q) + r * 0.5) + "\" material=\"foliage\"/>");
}

/// Vegetation: rejection sampling away from the route, walls and arrays;
/// where the plants stand is the station's.
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
    const Eigen::Vector2d p(rng.uniform(veg.area_m[0], veg.area_m[2]), rng.uniform(veg.area_m[1], veg.area_m[3]));
    const double radius = tree ? 0.3 * size : 0.5 * size;
    if (!clear_of_everything(s, route, p, radius)) continue;
    add_plant(x, (tree ? "tree" : "shrub") + std::to_string(placed), tree, p, size, veg.growth, rng, ground);
    ++placed;
  }
}

/// The unit vector towards the sun.
Eigen::Vector3d to_sun(const scenes::Light& light) {
  const double az = light.sun_azimuth_deg * kDeg, el = light.sun_elevation_deg * kDeg;
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

/// The sun: a directional light whose position only places its shadow map
/// (ShadowMap), in `mode` (track: in the robot's body, fixed offset and
/// orientation in the world frame; fixed: in the world body).
std::string sun_line(const scenes::Light& light, const std::string& mode, const Eigen::Vector3d& pos) {
  const double I = light.intensity;
  return "<light name=\"sun\" mode=\"" + mode + "\" directional=\"true\" castshadow=\"" +
         std::string(light.shadows ? "true" : "false") + "\" pos=\"" + v3(pos) + "\" dir=\"" + v3(-to_sun(light)) +
         "\" diffuse=\"" + v3(I, I, I * 0.96) + "\" specular=\"" + v3(0.5 * I, 0.5 * I, 0.5 * I) + "\"/>";
}

/// The chassis, caster, the two driven wheels and the mast.
void add_robot_parts(XmlWriter& x, const scenes::Scenario& s) {
  const scenes::Robot& rb = s.robot;
  const double r = rb.wheel_radius_m;
  x.line("<freejoint name=\"robot_free\"/>");
  x.line("<geom name=\"chassis\" type=\"box\" size=\"0.30 " + f(0.5 * rb.track_m - 0.05) + " 0.07\" pos=\"-0.12 0 0.05\" "
         "mass=\"18\" material=\"robot\"/>");
  // Frictionless: its priority above the ground's (1 when the soil's friction is given) makes its own govern.
  x.line("<geom name=\"caster\" type=\"sphere\" size=\"0.04\" pos=\"" + v3(-scenes::kRobotWheelBaseM, 0, 0.04 - r) +
         "\" mass=\"0.3\" condim=\"1\" priority=\"" + (s.ground.governs_contact() ? "2" : "1") +
         "\" friction=\"0 0 0\" rgba=\"0.2 0.2 0.2 1\"/>");
  for (int side = 0; side < 2; ++side) {
    const double y = (side == 0 ? 1 : -1) * 0.5 * rb.track_m;
    const std::string n = side == 0 ? kLeftActuator : kRightActuator;
    x.open("<body name=\"" + n + "\" pos=\"" + v3(0, y, 0) + "\">");
    x.line("<joint name=\"" + n + "\" type=\"hinge\" axis=\"0 1 0\" armature=\"0.01\" damping=\"0.02\"/>");
    x.line("<geom type=\"cylinder\" size=\"" + f(r) + " 0.025\" euler=\"90 0 0\" mass=\"1.5\" condim=\"3\" "
           "friction=\"1.2 0.01 0.001\" material=\"tyre\"/>");
    x.close("</body>");
  }
  const double mast_h = s.camera.mount_height_m - r;
  x.line("<geom name=\"mast\" type=\"cylinder\" size=\"0.02 " + f(mast_h / 2) + "\" pos=\"" +
         v3(s.camera.mount_forward_m - 0.05, 0, mast_h / 2) + "\" mass=\"0.5\" rgba=\"0.3 0.3 0.3 1\"/>");
}

/// The robot's body at its start: on flat ground 2 mm above it, heading
/// yaw0; on a relief tilted to the plane through the ground under its two
/// wheels and its caster, 10 mm above it (it settles before frame 0).
std::string robot_body_line(const scenes::Scenario& s, const scenes::GroundRelief& ground, const Eigen::Vector2d& start,
                            double yaw0) {
  const double r = s.robot.wheel_radius_m;
  const std::string open = "<body name=\"" + std::string(kRobotBody) + "\" pos=\"";
  if (ground.flat()) return open + v3(start.x(), start.y(), r + 0.002) + "\" euler=\"0 0 " + f(yaw0 / kDeg) + "\">";
  const Eigen::Vector2d ahead(std::cos(yaw0), std::sin(yaw0)), left(-ahead.y(), ahead.x());
  const double hl = ground.height_m(start + 0.5 * s.robot.track_m * left);
  const double hr = ground.height_m(start - 0.5 * s.robot.track_m * left);
  const double hc = ground.height_m(start - scenes::kRobotWheelBaseM * ahead), axle = 0.5 * (hl + hr);
  const double pitch = -std::atan2(axle - hc, scenes::kRobotWheelBaseM);  // about +y: positive turns the nose down
  const double roll = std::atan2(hl - hr, s.robot.track_m);               // about +x: positive lifts the left wheel
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw0, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return open + v3(start.x(), start.y(), axle + r + 0.010) + "\" quat=\"" + f(q.w()) + " " + v3(q.vec()) + "\">";
}

/// The robot (differential drive, two driven wheels and a caster) at the
/// start of the driven route, its camera, and the sun.
void add_robot_and_sun(XmlWriter& x, const scenes::Scenario& s, const std::vector<Eigen::Vector2d>& driven,
                       const ShadowMap& shadow, const scenes::GroundRelief& ground) {
  const scenes::Camera& cam = s.camera;
  const double r = s.robot.wheel_radius_m;
  const Eigen::Vector2d start = driven.empty() ? Eigen::Vector2d::Zero() : driven.front();
  double yaw0 = 0;
  if (driven.size() >= 2) {
    const Eigen::Vector2d d = driven[std::min<std::size_t>(10, driven.size() - 1)] - driven.front();
    yaw0 = std::atan2(d.y(), d.x());
  }
  x.open(robot_body_line(s, ground, start, yaw0));
  add_robot_parts(x, s);
  const double mast_h = cam.mount_height_m - r;
  // Camera: MuJoCo cameras look along -z with y up.  Forward direction from
  // yaw (left positive) and pitch (up positive) in the robot frame.
  const double p = cam.pitch_deg * kDeg, yw = cam.yaw_deg * kDeg;
  const Eigen::Vector3d fwd(std::cos(p) * std::cos(yw), std::cos(p) * std::sin(yw), std::sin(p));
  const Eigen::Vector3d right(std::sin(yw), -std::cos(yw), 0);
  const Eigen::Vector3d up = right.cross(fwd);
  x.line("<camera name=\"" + std::string(kCameraName) + "\" pos=\"" + v3(cam.mount_forward_m, 0, mast_h) +
         "\" xyaxes=\"" + v3(right) + " " + v3(up) + "\" fovy=\"" + f(cam.fovy_deg()) + "\"/>");
  if (cam.model == scenes::CameraKind::kD435) {  // the two infrared imagers, beside the colour camera
    const Eigen::Vector3d left = Eigen::Vector3d(cam.mount_forward_m, 0, mast_h) - cam.stereo.colour_offset_m * right;
    const std::string axes = "\" xyaxes=\"" + v3(right) + " " + v3(up) + "\" fovy=\"" + f(cam.stereo.ir_fovy_deg()) + "\"/>";
    x.line("<camera name=\"" + std::string(kIrLeftCameraName) + "\" pos=\"" + v3(left) + axes);
    x.line("<camera name=\"" + std::string(kIrRightCameraName) + "\" pos=\"" +
           v3(left + cam.stereo.baseline_m * right) + axes);
  }
  if (shadow.follows_robot) x.line(sun_line(s.light, "track", to_sun(s.light) * 20.0));
  x.close("</body>");
  if (!shadow.follows_robot)
    x.line(sun_line(s.light, "fixed",
                    Eigen::Vector3d(shadow.centre_xy_m.x(), shadow.centre_xy_m.y(), 0) + to_sun(s.light) * 20.0));
}

/// The ground's contact: MuJoCo's default combination with the tyres (the
/// larger friction) unless the day gives the soil's friction or softness;
/// then the ground's govern (a priority above the tyres'): its friction
/// (the tyres' 1.2 when only the softness is given) and, for a soft soil,
/// a softer, slower contact in which the tyres sink and creep.
std::string ground_friction(const scenes::Ground& g) {
  if (!g.governs_contact()) return "friction=\"1 0.005 0.0001\"";
  std::string out = "priority=\"1\" friction=\"" + f(g.friction.value_or(1.2)) + " 0.005 0.0001\"";
  if (g.softness > 0) {  // MuJoCo's defaults at 0: solref 0.02 1, solimp 0.9 0.95 0.001
    const double k = g.softness;
    out += " solref=\"" + f(0.02 + 0.08 * k) + " 1\" solimp=\"" + f(0.9 - 0.4 * k) + " " + f(0.95 - 0.25 * k) + " " +
           f(0.001 + 0.009 * k) + "\"";
  }
  return out;
}

/// The ground: one plane that the robot drives on, with the soil image
/// repeated every kGroundTileM.  A varied ground hides that plane (group 3,
/// still colliding) and draws its tiles, each with its own image, over a
/// copy of the repeated plane 5 mm lower for the distance.  A relief is a
/// height field instead, at the height of its lowest sample, with the same
/// soil image (MuJoCo maps a 2-D texture onto a height field as onto a
/// plane: by x and y, texrepeat per metre with texuniform).
void add_ground(XmlWriter& x, const scenes::Scenario& s, const std::vector<GroundTile>& tiles,
                const scenes::GroundRelief& ground) {
  if (!ground.flat()) {
    x.line("<geom name=\"ground\" type=\"hfield\" hfield=\"ground\" pos=\"0 0 " + exact(ground.grid().min_m()) +
           "\" material=\"ground\" condim=\"3\" " + ground_friction(s.ground) + "/>");
    return;
  }
  const std::string size = v3(s.ground.size_m.x() / 2, s.ground.size_m.y() / 2, 1);
  const bool varied = s.ground.drawn_tiling() == scenes::GroundTiling::kVaried;
  x.line("<geom name=\"ground\" type=\"plane\" size=\"" + size + "\" material=\"ground\" condim=\"3\" " +
         std::string(varied ? "group=\"3\" " : "") + ground_friction(s.ground) + "/>");
  if (!varied) return;
  x.line("<geom class=\"scenery\" type=\"plane\" size=\"" + size + "\" pos=\"0 0 -0.005\" material=\"ground\"/>");
  for (std::size_t k = 0; k < tiles.size(); ++k)
    x.line("<geom class=\"scenery\" type=\"plane\" size=\"" + v3(kGroundTileM / 2, kGroundTileM / 2, 1) +
           "\" pos=\"" + v3(tiles[k].centre_m.x(), tiles[k].centre_m.y(), 0) + "\" material=\"groundt" +
           std::to_string(k) + "\"/>");
}

}  // namespace

SceneAssets build_scene(const scenes::Scenario& s, SceneDetail detail, PngCompression png) {
  SceneAssets out;
  out.detail = detail;
  out.png = png;
  const scenes::Camera& cam = s.camera;
  // Physics step: physics.rate_hz, or the largest step <= 2 ms that divides
  // the frame period, so frame i is rendered at exactly i / fps.
  out.substeps = scenes::physics_substeps(s);
  out.timestep_s = 1.0 / (cam.fps * out.substeps);
  const double diag = std::hypot(s.ground.size_m.x(), s.ground.size_m.y()) + 20.0;
  out.max_scene_depth_m = 1.05 * diag;

  // The whole route bounds the shadow map and where plants may grow; the
  // robot drives it from route.start_m.
  const std::vector<Eigen::Vector2d> route = scenes::route_polyline(s);
  const std::vector<Eigen::Vector2d> driven = scenes::polyline_from(route, s.route.start_m);
  const ShadowMap shadow = shadow_map_for(s.light, route);
  for (const auto& p : driven) {
    out.route_xy.push_back(p.x());
    out.route_xy.push_back(p.y());
  }
  const std::vector<GroundTile> tiles = varied_ground_tiles(s, route);
  add_textures(s, tiles, detail, &out);
  const scenes::GroundRelief ground(s);
  if (!ground.flat()) out.files.emplace_back(kReliefFile, hfield_file(ground.grid()));

  XmlWriter x;
  x.open("<mujoco model=\"" + s.name + "\">");
  write_settings(x, s, out, shadow);
  write_assets(x, s, out, ground);
  x.open("<worldbody>");
  add_ground(x, s, tiles, ground);
  for (std::size_t i = 0; i < s.pv_arrays.size(); ++i)
    add_array(x, s.pv_arrays[i], static_cast<int>(i), s.seed, ground);
  add_walls(x, s, ground);
  add_vegetation(x, s, route, ground);
  add_robot_and_sun(x, s, driven, shadow, ground);
  x.close("</worldbody>");

  x.open("<actuator>");
  for (const char* n : {kLeftActuator, kRightActuator})
    x.line("<velocity name=\"" + std::string(n) + "\" joint=\"" + n + "\" kv=\"25\" ctrlrange=\"" +
           f(-s.robot.max_wheel_speed_radps) + " " + f(s.robot.max_wheel_speed_radps) + "\" forcerange=\"-40 40\"/>");
  x.close("</actuator>");
  x.close("</mujoco>");
  out.xml = x.os.str();
  return out;
}

ModelPtr compile_scene(const SceneAssets& assets) {
  install_mujoco_handlers();  // MuJoCo's log goes to stderr, not MUJOCO_LOG.TXT
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  auto add = [&](const std::string& name, const void* data, std::size_t size) {
    if (mj_makeEmptyFileVFS(&vfs, name.c_str(), static_cast<int>(size)) != 0) {
      mj_deleteVFS(&vfs);
      throw Error("MuJoCo VFS: cannot add " + name);
    }
    std::memcpy(vfs.filedata[vfs.nfile - 1], data, size);
  };
  add("scene.xml", assets.xml.data(), assets.xml.size());
  for (const auto& file : assets.files) add(file.first, file.second.data(), file.second.size());
  char err[1024] = {0};
  mjModel* m = mj_loadXML("scene.xml", &vfs, err, sizeof err);
  mj_deleteVFS(&vfs);
  if (m == nullptr) throw Error(std::string("MuJoCo could not compile the generated scene: ") + err);
  return ModelPtr(m);
}

void write_scene(const SceneAssets& assets, const std::string& dir) {
  ::mkdir(dir.c_str(), 0755);
  ::mkdir((dir + "/textures").c_str(), 0755);
  write_file(dir + "/scene.xml", assets.xml);
  for (const auto& [path, bytes] : assets.files) {
    const bool stored_png =
        assets.png == PngCompression::kStored && path.size() > 4 && path.compare(path.size() - 4, 4, ".png") == 0;
    const std::vector<unsigned char> file =
        stored_png ? png_of_bgr(cv::imdecode(bytes, cv::IMREAD_COLOR), file_zlib_level(path)) : bytes;
    write_file(dir + "/" + path, std::string(file.begin(), file.end()));
  }
}

}  // namespace pvb::sim
