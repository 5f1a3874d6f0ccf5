// The scene as MJCF: the settings (physics step, visual, classes), the
// textures and materials, the ground (its tiles: scene_ground_tiles.cpp),
// then the world body's parts (scene_station.cpp: arrays, walls,
// vegetation; scene_robot.cpp: the robot and the sun); compiled by MuJoCo
// from memory or written to a folder.
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
#include <opencv2/imgcodecs.hpp>  // the flags
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <regex>
#include <set>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/route.hpp"
#include "pvb/sensor/image_codec.hpp"
#include "pvb/sim/ground_stream.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/sim/textures.hpp"
#include "scene_mjcf.hpp"

namespace pvb::sim {
namespace mjcf {
namespace {

constexpr const char* kGroundTilePrefix = "textures/groundt";
/// A drawn plane's grid quads along its longer side, at most (MuJoCo adds
/// one narrower quad at each end).
constexpr int kMaxPlaneGridQuads = 30;

/// zlib's level for a texture file as recordings write it: level 6 for the
/// station's few images (their bytes are pinned, tests/sim/test_old_bytes.cpp);
/// level 1 for a varied ground's many tiles, which encodes 3x faster for
/// 7 % more bytes (the pixels MuJoCo decodes are the same).
int file_zlib_level(const std::string& path) { return path.rfind(kGroundTilePrefix, 0) == 0 ? 1 : 6; }

std::vector<unsigned char> png_of_bgr(const cv::Mat& bgr, int zlib_level) {
  std::vector<unsigned char> out;
  sensor::imencode(".png", bgr, &out, {cv::IMWRITE_PNG_COMPRESSION, zlib_level});
  return out;
}

/// The PNG file `path` of an RGB image.
std::vector<unsigned char> png(const cv::Mat& rgb_img, const std::string& path) {
  cv::Mat bgr;
  cv::cvtColor(rgb_img, bgr, cv::COLOR_RGB2BGR);
  return png_of_bgr(bgr, file_zlib_level(path));
}

/// An RGB image as TextureEncoding::kPixels holds it.
std::vector<unsigned char> pixels(const cv::Mat& rgb_img) {
  const std::int32_t size[2] = {rgb_img.cols, rgb_img.rows};
  std::vector<unsigned char> out(sizeof size + rgb_img.total() * 3);
  std::memcpy(out.data(), size, sizeof size);
  for (int r = 0; r < rgb_img.rows; ++r)
    std::memcpy(out.data() + sizeof size + static_cast<std::size_t>(r) * rgb_img.cols * 3, rgb_img.ptr(r),
                static_cast<std::size_t>(rgb_img.cols) * 3);
  return out;
}

/// The image that pixels() held, as a cv::Mat (RGB) that points into `bytes`.
cv::Mat pixels_image(const std::vector<unsigned char>& bytes) {
  std::int32_t size[2] = {0, 0};
  if (bytes.size() >= sizeof size) std::memcpy(size, bytes.data(), sizeof size);
  if (size[0] <= 0 || size[1] <= 0 || bytes.size() != sizeof size + std::size_t(size[0]) * size[1] * 3)
    throw Error("a texture's pixels do not match their size");
  return cv::Mat(size[1], size[0], CV_8UC3, const_cast<unsigned char*>(bytes.data()) + sizeof size);
}

/// A texture's file, textures/NAME.png, and its NAME.
bool is_texture_file(const std::string& path) {
  return path.rfind("textures/", 0) == 0 && path.size() > 13 && path.compare(path.size() - 4, 4, ".png") == 0;
}
std::string texture_name(const std::string& path) { return path.substr(9, path.size() - 13); }

/// A texture's bytes as `encoding` holds them.
std::vector<unsigned char> texture_bytes(const cv::Mat& rgb_img, const std::string& path, TextureEncoding encoding) {
  return encoding == TextureEncoding::kPixels ? pixels(rgb_img) : png(rgb_img, path);
}

/// The textures: the station's, but for the day's dust on the panels.  A
/// geometry-only scene names the same files, each a 1x1 grey image.
void add_textures(const scenes::Scenario& s, const std::vector<GroundTile>& tiles, SceneDetail detail,
                  SceneAssets* out) {
  const bool full = detail == SceneDetail::kFull;
  const TextureEncoding encoding = out->textures;
  const std::vector<unsigned char> grey =
      full ? std::vector<unsigned char>{}
           : texture_bytes(cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(128)), "textures/grey.png", encoding);
  const auto add = [&](const std::string& name, const std::function<cv::Mat()>& draw) {
    const std::string path = "textures/" + name + ".png";
    out->files.emplace_back(path, full ? texture_bytes(draw(), path, encoding) : grey);
  };
  const std::uint64_t station_seed = s.station_seed_or_seed(), day_seed = s.seed;
  add("ground", [&] { return make_ground_texture(s.ground.type, station_seed); });
  // A tile's image depends on its seed alone: drawn and encoded on every core.
  // Shared images: image k is groundtK; else tile k's own image is.
  // A plant's roads add their gravel images after the soil's.
  std::vector<std::uint64_t> seeds;
  const bool gravel = (std::any_of(tiles.begin(), tiles.end(),
                                   [&](const GroundTile& t) { return t.image >= s.ground.soil_images; }) ||
                       mjcf::draws_road_planes(s)) &&
                      s.ground.soil_images > 0;
  const int shared = s.ground.soil_images + (gravel ? kRoadGravelImages : 0);
  for (int k = 0; k < shared && !tiles.empty(); ++k) seeds.push_back(shared_soil_image_seed(station_seed, k));
  if (s.ground.soil_images == 0)
    for (const GroundTile& t : tiles) seeds.push_back(t.seed);
  std::vector<std::vector<unsigned char>> tile_png(seeds.size(), grey);
  if (full)
    cv::parallel_for_(cv::Range(0, static_cast<int>(seeds.size())), [&](const cv::Range& range) {
      for (int k = range.start; k < range.end; ++k) {
        const bool road = s.ground.soil_images > 0 && k >= s.ground.soil_images;
        const scenes::GroundType type = road ? scenes::GroundType::kGravel : s.ground.type;
        tile_png[k] = texture_bytes(make_ground_texture(type, seeds[k]), kGroundTilePrefix, encoding);
      }
    });
  for (std::size_t k = 0; k < seeds.size(); ++k)
    out->files.emplace_back(kGroundTilePrefix + std::to_string(k) + ".png", std::move(tile_png[k]));
  if (s.plant && !s.plant->row_signs.empty())
    add("rowsigns", [&] { return make_sign_atlas(s.plant->sign_labels); });
  if (s.plant && s.plant->tracked_aisles > 0) add("track", [&] { return make_track_texture(station_seed); });
  if (s.plant && s.plant->grass_rows > 0) add("grass", [&] { return make_grass_texture(station_seed); });
  add("brick", [&] { return make_brick_texture(station_seed); });
  add("foliage", [&] { return make_foliage_texture(station_seed); });
  add("bark", [&] { return make_bark_texture(station_seed); });
  for (std::size_t i = 0; i < s.pv_arrays.size(); ++i) {
    for (int k = 0; k < kDirtVariants; ++k) {
      // variant 0 is the cleanest; dirt grows with k up to the array's level
      const scenes::PvArray& a = s.pv_arrays[i];
      const double spread = a.row_soiling;
      const double dirt = spread > 0 ? std::clamp(a.dirt * (1 - spread + 2 * spread * k / (kDirtVariants - 1)), 0.0, 1.0)
                                     : a.dirt * (0.55 + 0.15 * k);
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
void write_assets(XmlWriter& x, const scenes::Scenario& s, const SceneAssets& out,
                  const scenes::GroundRelief& ground, const ReliefTiles& relief_tiles) {
  x.open("<asset>");
  if (!ground.flat() && !ground.tiled()) x.line(hfield_line(s, ground));
  for (const auto* set : {&relief_tiles.backdrop, &relief_tiles.tiles, &relief_tiles.far_tiles})
    for (const RuntimeHField& h : *set) x.line(hfield_asset_line(h));
  const auto rgb = [](const Eigen::Vector3f& c) {  // two decimals, as the sky was always written
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.2f %.2f %.2f", c.x(), c.y(), c.z());
    return std::string(buf);
  };
  x.line("<texture name=\"sky\" type=\"skybox\" builtin=\"gradient\" rgb1=\"" + rgb(kSkyZenithRgb) + "\" rgb2=\"" +
         rgb(kSkyHorizonRgb) + "\" width=\"512\" height=\"512\"/>");
  for (const auto& file : out.files) {
    if (!is_texture_file(file.first)) continue;
    const std::string name = texture_name(file.first);
    x.line("<texture name=\"" + name + "\" type=\"2d\" file=\"" + file.first + "\"/>");
  }
  // A ground of shared soil images: the slots of the images that tiles near
  // the camera show instead (GroundStream fills them), as many as fit the
  // render context's textures after the scene's own and the sky.
  const int textures = 1 + static_cast<int>(std::count_if(out.files.begin(), out.files.end(),
                                                          [](const auto& f) { return is_texture_file(f.first); }));
  if (textures > kMaxSceneTextures)
    throw ConfigError(s.source_file, s.ground.soil_images > 0 ? "ground.soil_images" : "ground.tiling",
                      "a scene of at most " + std::to_string(kMaxSceneTextures) +
                          " textures (MuJoCo's renderer holds no more): fewer soil images, a shorter route on a "
                          "varied ground, fewer arrays, or tiling: repeat",
                      std::to_string(textures) + " textures");
  const int slots = GroundStream::wanted(s, out.detail)
                        ? std::min(unique_ground_slots(s.ground.unique_within_m), kMaxSceneTextures - textures)
                        : 0;
  for (int k = 0; k < slots; ++k)
    x.line("<texture name=\"" + std::string(kGroundSlotPrefix) + std::to_string(k) +
           "\" type=\"2d\" builtin=\"flat\" width=\"" + std::to_string(kGroundTexturePx) + "\" height=\"" +
           std::to_string(kGroundTexturePx) + "\" rgb1=\"0.44 0.35 0.24\"/>");
  // The materials after every texture, as a scene without varied ground always had them.
  for (const auto& file : out.files) {
    if (!is_texture_file(file.first)) continue;
    const std::string name = texture_name(file.first);
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
      if (s.pv_arrays[i].panel_slabs)  // a table's slab: the module texture once per module
        x.line("<material name=\"a" + std::to_string(i) + "slab" + std::to_string(k) + "\" texture=\"" + n +
               "\" texrepeat=\"" + std::to_string(s.pv_arrays[i].panels_per_table) + " " +
               std::to_string(s.pv_arrays[i].panel_lines) + "\" specular=\"" + f(specular) + "\" shininess=\"0.85\"/>");
    }
  // Plaster: one flat colour, matte (walls with finish: plaster).
  x.line("<material name=\"plaster\" rgba=\"0.78 0.76 0.72 1\" specular=\"0.02\" shininess=\"0.05\"/>");
  x.line("<material name=\"backsheet\" rgba=\"0.80 0.81 0.82 1\" specular=\"0.1\"/>");
  x.line("<material name=\"steel\" rgba=\"0.58 0.60 0.62 1\" specular=\"0.4\" shininess=\"0.4\"/>");
  x.line("<material name=\"robot\" rgba=\"0.95 0.55 0.10 1\" specular=\"0.3\"/>");
  x.line("<material name=\"tyre\" rgba=\"0.08 0.08 0.08 1\"/>");
  add_plant_assets(x, s, ground);
  if (std::any_of(s.pv_arrays.begin(), s.pv_arrays.end(), [](const scenes::PvArray& a) { return a.broken_modules > 0; }))
    x.line("<material name=\"broken\" rgba=\"0.62 0.66 0.70 1\" specular=\"0.5\" shininess=\"0.3\"/>");  // shattered glass
  x.close("</asset>");
}

/// The spacing of the grid that MuJoCo draws a ground plane as (its size's
/// third number, half a quad's side): 1 m, or coarser on a ground longer
/// than 60 m, so that no side has more than kMaxPlaneGridQuads quads.  The
/// corners of every quad are lit and transformed in each pass of every
/// frame: a plant's 300 x 1400 m plane at 1 m was about 150 x 200 quads,
/// which cost more than the rest of the scene's ground.  The picture
/// changes only in the soil's faint specular highlight, lit at the corners
/// and interpolated between them.
double plane_grid_m(const Eigen::Vector2d& size_m) {
  return std::max(1.0, 0.5 * size_m.maxCoeff() / kMaxPlaneGridQuads);
}

/// The ground: one plane that the robot drives on, with the soil image
/// repeated every kGroundTileM.  A varied ground hides that plane (group 3,
/// still colliding) and draws its tiles, each with its own image, over a
/// copy of the repeated plane 5 mm lower for the distance.  A relief is a
/// height field instead, at the height of its lowest sample, with the same
/// soil image (MuJoCo maps a 2-D texture onto a height field as onto a
/// plane: by x and y, texrepeat per metre with texuniform).
void add_ground(XmlWriter& x, const scenes::Scenario& s, const std::vector<GroundTile>& tiles,
                const scenes::GroundRelief& ground, const ReliefTiles& relief_tiles) {
  if (ground.tiled()) {
    add_tiled_relief_ground(x, s, tiles, relief_tiles);
    return;
  }
  if (!ground.flat()) {
    x.line("<geom name=\"ground\" type=\"hfield\" hfield=\"ground\" pos=\"0 0 " + exact(ground.grid().min_m()) +
           "\" material=\"ground\" condim=\"3\" " + ground_friction(s.ground) + "/>");
    return;
  }
  const std::string size =
      v3(s.ground.size_m.x() / 2, s.ground.size_m.y() / 2, plane_grid_m(s.ground.size_m));
  const bool varied = s.ground.drawn_tiling() == scenes::GroundTiling::kVaried;
  x.line("<geom name=\"ground\" type=\"plane\" size=\"" + size + "\" material=\"ground\" condim=\"3\" " +
         std::string(varied ? "group=\"3\" " : "") + ground_friction(s.ground) + "/>");
  if (!varied) return;
  x.line("<geom class=\"scenery\" type=\"plane\" size=\"" + size + "\" pos=\"0 0 -0.005\" material=\"ground\"/>");
  for (std::size_t k = 0; k < tiles.size(); ++k) {
    const GroundTile& t = tiles[k];
    const std::string turn = t.quarter_turns > 0 ? "\" euler=\"0 0 " + std::to_string(90 * t.quarter_turns) : "";
    x.line("<geom class=\"scenery\" type=\"plane\" size=\"" + v3(kGroundTileM / 2, kGroundTileM / 2, 1) +
           "\" pos=\"" + v3(t.centre_m.x(), t.centre_m.y(), 0) + turn + "\" material=\"groundt" +
           std::to_string(t.image >= 0 ? static_cast<std::size_t>(t.image) : k) + "\"/>");
  }
}

}  // namespace

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
    out += " solref=\"" + f(0.02 + 0.08 * k) + " 1\" solimp=\"" + f(0.9 - 0.4 * k) + " " +
           f(0.95 - 0.25 * k) + " " + f(0.001 + 0.009 * k) + "\"";
  }
  return out;
}

}  // namespace mjcf

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

SceneAssets build_scene(const scenes::Scenario& s, SceneDetail detail, TextureEncoding textures) {
  using namespace mjcf;
  SceneAssets out;
  out.detail = detail;
  out.textures = textures;
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
  const ReliefTiles tiled = relief_tiles(s, tiles, ground);
  if (ground.tiled())
    out.files.emplace_back(kReliefTilesFile, relief_tiles_file(tiled));
  else if (!ground.flat())
    out.files.emplace_back(kReliefFile, hfield_file(ground.grid()));

  XmlWriter x;
  x.open("<mujoco model=\"" + s.name + "\">");
  write_settings(x, s, out, shadow);
  write_assets(x, s, out, ground, tiled);
  x.open("<worldbody>");
  add_ground(x, s, tiles, ground, tiled);
  for (std::size_t i = 0; i < s.pv_arrays.size(); ++i)
    add_array(x, s.pv_arrays[i], static_cast<int>(i), s.seed, s.station_seed_or_seed(), ground);
  add_walls(x, s, ground);
  add_plant_fixtures(x, s, ground);
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

namespace {

using mjcf::is_texture_file;

/// The MJCF that MuJoCo compiles for kPixels textures: each texture a flat
/// image of its size, whose texels fill_textures() then writes.
std::string xml_with_flat_textures(const SceneAssets& assets) {
  std::string xml = assets.xml;
  for (const auto& [path, bytes] : assets.files) {
    if (!is_texture_file(path)) continue;
    const cv::Mat img = mjcf::pixels_image(bytes);
    const std::string file = "file=\"" + path + "\"";
    const std::size_t at = xml.find(file);
    if (at == std::string::npos) throw Error("the generated scene does not name its texture " + path);
    xml.replace(at, file.size(), "builtin=\"flat\" width=\"" + std::to_string(img.cols) + "\" height=\"" +
                                     std::to_string(img.rows) + "\" rgb1=\"0 0 0\"");
  }
  return xml;
}

/// Writes each kPixels texture's texels into the compiled model.
void fill_textures(mjModel* m, const SceneAssets& assets) {
  for (const auto& [path, bytes] : assets.files) {
    if (!is_texture_file(path)) continue;
    const std::string name = mjcf::texture_name(path);
    const int id = mj_name2id(m, mjOBJ_TEXTURE, name.c_str());
    const cv::Mat img = mjcf::pixels_image(bytes);
    if (id < 0 || m->tex_width[id] != img.cols || m->tex_height[id] != img.rows)
      throw Error("MuJoCo did not make the texture " + name + " at its size");
    std::memcpy(m->tex_rgb + m->tex_adr[id], img.data, img.total() * 3);
  }
}

}  // namespace

SceneAssets physics_assets(const SceneAssets& scene) {
  SceneAssets out = scene;
  out.textures = TextureEncoding::kPng;
  out.files.clear();
  for (const auto& file : scene.files)
    if (!is_texture_file(file.first)) out.files.push_back(file);
  // Every line is one element (XmlWriter).  The scenery's geoms go, the
  // meshes only they use, every texture and the materials' references to them.
  std::istringstream in(scene.xml);
  std::ostringstream xml;
  std::set<std::string> scenery_meshes;
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (line.find("class=\"scenery\"") != std::string::npos && line.find("<geom ") != std::string::npos) {
      const std::size_t at = line.find(" mesh=\"");
      if (at != std::string::npos) scenery_meshes.insert(line.substr(at + 7, line.find('"', at + 7) - at - 7));
      continue;
    }
    lines.push_back(line);
  }
  const std::regex texture_ref(" texture=\"[^\"]*\"");
  for (const std::string& line : lines) {
    const std::size_t open = line.find_first_not_of(' ');
    if (line.compare(open, 9, "<texture ") == 0) continue;
    if (line.compare(open, 6, "<mesh ") == 0) {
      const std::size_t at = line.find(" name=\"") + 7;
      if (scenery_meshes.count(line.substr(at, line.find('"', at) - at))) continue;
    }
    xml << (line.compare(open, 10, "<material ") == 0 ? std::regex_replace(line, texture_ref, "") : line) << "\n";
  }
  out.xml = xml.str();
  return out;
}

ModelPtr compile_scene(const SceneAssets& assets) {
  install_mujoco_handlers();  // MuJoCo's log goes to stderr, not MUJOCO_LOG.TXT
  const bool pixels = assets.textures == TextureEncoding::kPixels;
  const std::string xml = pixels ? xml_with_flat_textures(assets) : assets.xml;
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  auto add = [&](const std::string& name, const void* data, std::size_t size) {
    if (mj_makeEmptyFileVFS(&vfs, name.c_str(), static_cast<int>(size)) != 0) {
      mj_deleteVFS(&vfs);
      throw Error("MuJoCo VFS: cannot add " + name);
    }
    std::memcpy(vfs.filedata[vfs.nfile - 1], data, size);
  };
  add("scene.xml", xml.data(), xml.size());
  for (const auto& file : assets.files)
    if (!pixels || !is_texture_file(file.first)) add(file.first, file.second.data(), file.second.size());
  char err[1024] = {0};
  mjModel* m = mj_loadXML("scene.xml", &vfs, err, sizeof err);
  mj_deleteVFS(&vfs);
  if (m == nullptr) throw Error(std::string("MuJoCo could not compile the generated scene: ") + err);
  ModelPtr model(m);
  if (pixels) fill_textures(m, assets);
  for (const auto& file : assets.files)
    if (file.first == kReliefTilesFile) fill_relief_tiles(m, file.second);
  return model;
}

void write_scene(const SceneAssets& assets, const std::string& dir) {
  ::mkdir(dir.c_str(), 0755);
  ::mkdir((dir + "/textures").c_str(), 0755);
  write_file(dir + "/scene.xml", assets.xml);
  for (const auto& [path, bytes] : assets.files) {
    const bool pixels = assets.textures == TextureEncoding::kPixels && is_texture_file(path);
    const std::vector<unsigned char> file = pixels ? mjcf::png(mjcf::pixels_image(bytes), path) : bytes;
    write_file(dir + "/" + path, std::string(file.begin(), file.end()));
  }
}

}  // namespace pvb::sim
