#pragma once
// Scenario -> MJCF.  The generated model holds the station (ground, PV
// arrays, brick walls, vegetation), the sun and the robot with its camera.
#include <mujoco/mujoco.h>

#include <memory>
#include <string>
#include <vector>

#include "pvb/scenes/scenario.hpp"

namespace pvb::sim {

/// What a scene is built for.  kFull: drawn in colour, every texture
/// generated.  kGeometry: physics, depth and geom ids only; each texture
/// is a 1x1 grey image, so the MJCF (every geom, material and name) is
/// the full scene's, the physics and the rendered depth are the same, and
/// set-up skips drawing and encoding the images.
enum class SceneDetail { kFull, kGeometry };

/// How the textures are held.  kPng: the PNG files a recording writes
/// (zlib level 6, level 1 for a varied ground's tiles; their bytes are
/// pinned).  kPixels: for a scene that is compiled in memory, each
/// texture's pixels as they are (width and height as two 32-bit integers,
/// then the RGB rows, top row first), which compile_scene() writes into
/// the model: the same texels, with no PNG encoded or decoded.  The MJCF
/// is the same; write_scene() writes the PNG files kPng would hold.
enum class TextureEncoding { kPng, kPixels };

/// A generated scene: scene.xml plus the texture files it names.
struct SceneAssets {
  SceneDetail detail = SceneDetail::kFull;
  TextureEncoding textures = TextureEncoding::kPng;
  std::string xml;
  /// Path relative to scene.xml and bytes: the textures' PNGs, and with a
  /// ground relief its height field (kReliefFile).
  std::vector<std::pair<std::string, std::vector<unsigned char>>> files;
  double timestep_s = 0.002;   ///< physics step; an exact divisor of the frame period
  int substeps = 17;           ///< physics steps per camera frame
  double max_scene_depth_m = 100;  ///< anything farther than this is sky
  std::vector<double> route_xy;    ///< route polyline, x0 y0 x1 y1 ...
};

/// Side of one shadow-map texel, metres, for a directional light: MuJoCo
/// renders the light's orthographic view of half-width `shadow_clip_m`
/// into the texture's inner shadow_size - 2 texels (one texel border).
inline double shadow_texel_m(double shadow_clip_m, int shadow_size_px) {
  return 2.0 * shadow_clip_m / (shadow_size_px - 2);
}

/// Where the sun's shadow map lies.  Fixed (the default): centred on the
/// route's bounding box, reaching `kShadowMarginM` beyond its corners;
/// its size, unless the scenario sets one, is the smallest power of two
/// from 1024 that keeps texels at most kShadowTexelTargetM (up to 8192).
/// Following the robot: 9 m around it (the centre is then the offset from
/// the robot, zero).
struct ShadowMap {
  bool follows_robot = false;
  Eigen::Vector2d centre_xy_m = Eigen::Vector2d::Zero();
  double half_width_m = 9.0;  ///< MuJoCo's shadowclip, metres
  int size_px = 1024;         ///< texture side
  double texel_m() const { return shadow_texel_m(half_width_m, size_px); }
};
inline constexpr double kShadowMarginM = 9.0;
inline constexpr double kShadowTexelTargetM = 0.020;
/// One 3 m tile of a varied ground: its centre, the seed of its image, and
/// on a ground of shared images (`ground.soil_images`) which image it takes
/// and how many quarter turns (counter-clockwise) it lies at.
struct GroundTile {
  Eigen::Vector2d centre_m;
  std::uint64_t seed = 0;
  int image = -1;  ///< -1: an image of its own
  int quarter_turns = 0;
  /// On a ground of shared soil images: the seed of the image the tile
  /// shows near the camera (ground.unique_within_m; GroundStream), drawn
  /// from the station's seed and the tile's place.
  std::uint64_t own_seed = 0;
  bool gravel = false;  ///< on a plant's service road: its images are gravel
};
/// A height field whose samples are not in a file of their own: a tiled
/// relief's tile or backdrop piece (kReliefTilesFile holds them all).
struct RuntimeHField {
  std::string name;
  int nrow = 0, ncol = 0;
  double half_x_m = 0, half_y_m = 0;
  double z0_m = 0, range_m = 0;  ///< the lowest sample, and the highest's height above it
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  int quarter_turns = 0;
  std::vector<float> data;  ///< row-major, in [0, 1] of range_m
};
/// Writes the samples of kReliefTilesFile's bytes into the model's height
/// fields of the same names.  Throws Error when one is missing or of
/// another size.
void fill_relief_tiles(mjModel* m, const std::vector<unsigned char>& file);
/// The sphere about height field geom `geom`'s frame that holds it, its
/// radius (MuJoCo 2.2.2 leaves geom_rbound 0 for a height field): half its
/// extent across, and its top or its base below.
double hfield_bounding_radius(const mjModel* m, int geom);

/// The tiles of a varied ground along the scenario's route (none for a
/// repeated one), as the scene lays them.
std::vector<GroundTile> ground_tiles(const scenes::Scenario& s);
/// The seed of shared soil image `k` of a station.
std::uint64_t shared_soil_image_seed(std::uint64_t station_seed, int k);

ShadowMap shadow_map_for(const scenes::Light& light, const std::vector<Eigen::Vector2d>& route_xy_m);

/// Generates the scene.  Deterministic in the scenario (seed included).
SceneAssets build_scene(const scenes::Scenario& scenario, SceneDetail detail = SceneDetail::kFull,
                        TextureEncoding textures = TextureEncoding::kPng);

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

/// Compiles the assets with MuJoCo (from memory, no disk).  Throws Error
/// carrying MuJoCo's message on failure.
ModelPtr compile_scene(const SceneAssets& assets);

/// The scene for physics alone: without the scenery (geoms that never
/// collide: the arrays, walls, fence, plants, ground tiles), its meshes and
/// every texture.  The robot, the ground it drives on and every body,
/// joint, actuator and camera keep their ids; the robot moves exactly as
/// in the whole scene, while a step no longer visits thousands of geoms.
SceneAssets physics_assets(const SceneAssets& scene);

/// Writes scene.xml and the files it names under `dir` (created if needed).
void write_scene(const SceneAssets& assets, const std::string& dir);

/// Names used in the generated model.
inline constexpr const char* kCameraName = "rgbd";
/// The sky's gradient (MuJoCo's skybox), linear RGB in [0, 1]: the zenith
/// and the horizon.  Specular glass mirrors it (glass.hpp).
inline const Eigen::Vector3f kSkyZenithRgb(0.50f, 0.66f, 0.90f);
inline const Eigen::Vector3f kSkyHorizonRgb(0.93f, 0.95f, 0.98f);
/// The d435 model's infrared imagers (scenes::ActiveStereo).
inline constexpr const char* kIrLeftCameraName = "ir_left";
inline constexpr const char* kIrRightCameraName = "ir_right";
inline constexpr const char* kRobotBody = "robot";
inline constexpr const char* kLeftActuator = "wheel_left";
inline constexpr const char* kRightActuator = "wheel_right";
/// The ground relief's height field, in MuJoCo's binary hfield format.
inline constexpr const char* kReliefFile = "ground_relief.bin";
/// A tiled relief's height fields, one after the other (fill_relief_tiles).
inline constexpr const char* kReliefTilesFile = "ground_tiles.bin";
/// The names of a tiled relief's tile K and of its far version (geom and
/// height field alike): prefix then K.
inline constexpr const char* kReliefTilePrefix = "groundtile";
inline constexpr const char* kReliefFarTilePrefix = "groundtilefar";
/// The names of a plant's road pieces (flat varied soil): prefix then K.
inline constexpr const char* kRoadPlanePrefix = "road";

}  // namespace pvb::sim
