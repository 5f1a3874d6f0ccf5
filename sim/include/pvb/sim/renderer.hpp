#pragma once
// Off-screen RGB-D rendering of a MuJoCo camera.
#include <mujoco/mujoco.h>

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>
#include <cstdint>

#include "pvb/sim/gl_context.hpp"

namespace pvb::sim {

class GroundStream;

/// Renders one fixed camera of a model into RGB and metric depth.
///
/// Depth comes from the depth buffer of the same (single-sample) pass as the
/// colour image.  MuJoCo 2.2.2 uses a standard Z buffer, so with
/// n = vis.map.znear * stat.extent and f = vis.map.zfar * stat.extent a
/// buffer value d in [0, 1] is the optical-axis depth z = n f / (f - d (f - n)).
/// Rows are flipped (OpenGL's origin is bottom-left); sky (d == 1) is 0.
class Renderer {
 public:
  /// Creates the GL context (one per process backend) and MuJoCo's render
  /// context.  The model's offscreen buffer must be at least width x height
  /// and single-sampled (vis.quality.offsamples = 0) for exact depth.
  Renderer(const mjModel* model, GlBackend backend, int width, int height);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Renders camera `camera_id` for the state in `data`, first making this
  /// renderer's GL context current on the calling thread (several renderers
  /// may live in one process, on one thread at a time each; throws
  /// UnavailableError when the context cannot be made current).  rgb becomes CV_8UC3
  /// (R, G, B order), depth_m CV_32FC1 metres (0 = nothing within zfar).
  void render(const mjModel* model, mjData* data, int camera_id, cv::Mat* rgb, cv::Mat* depth_m);

  /// Renders which model geom each pixel shows (CV_32SC1, -1 = none), with
  /// MuJoCo's segmentation mode (mjRND_SEGMENT + mjRND_IDCOLOR).  depth_m,
  /// when given, is read from the same pass: the depth render() gives for
  /// the same state, in one draw instead of two.
  void render_geom_ids(const mjModel* model, mjData* data, int camera_id, cv::Mat* geom_id,
                       cv::Mat* depth_m = nullptr);

  /// Turns shadows on or off for the following renders.
  void set_shadows(bool on);
  /// Keeps the shadow-map texel grid of each directional shadow-casting
  /// light fixed in the world (on by default; see snap_to_shadow_texels).
  /// Off is MuJoCo's own behaviour, kept for tests that show the difference.
  void set_stable_shadows(bool on) { stable_shadows_ = on; }
  /// Whether geoms that neither lie in the camera's view nor shadow it are
  /// left out before drawing (cull_to_view; on by default).
  void set_culling(bool on) { cull_ = on; }
  /// Ground tiles (finite planes, a relief's tiles) farther than this from
  /// the camera are left out too, where the base plane's repeated soil shows instead
  /// (0: none; cull_to_view).
  void set_far_tile_cull_m(double m) { far_tile_m_ = m; }
  /// The lowest ground a shadow can fall on (z = 0 by default, flat
  /// ground): the cull sweeps each geom's sphere along the sun's beam down
  /// to 2 m below it.
  void set_shadow_floor_z_m(double z) { shadow_floor_z_m_ = z; }
  /// A tiled relief's tiles farther than this from the camera are drawn as
  /// their far versions (select_relief_detail; 0, the default: every tile
  /// in full).
  void set_relief_detail_m(double m) { relief_detail_m_ = m; }
  /// Draws the ground's tiles near the camera with their own images, as
  /// `stream` holds them at each render (null: every tile its material's).
  /// The stream must outlive the renderer or be unset first.
  void set_ground_stream(const GroundStream* stream) { stream_ = stream; }
  /// Geoms the last render left out of the scene, and those it drew.
  int culled_geoms() const { return culled_; }
  int drawn_geoms() const { return scene_.ngeom; }
  const std::string& description() const { return gl_->description(); }
  GlBackend backend() const { return gl_->backend(); }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  /// Uploads the stream's redrawn slots and points its near tiles at them.
  void apply_ground_stream();
  /// The depth buffer read last, flipped to image rows, in metres.
  void copy_depth(const mjModel* model, cv::Mat* depth_m) const;

  std::unique_ptr<GlContext> gl_;
  mjrContext con_;
  mjvScene scene_;
  mjvOption option_;
  mjvCamera camera_;
  int width_;
  int height_;
  bool stable_shadows_ = true;
  bool cull_ = true;
  double far_tile_m_ = 0;
  double shadow_floor_z_m_ = 0;
  double relief_detail_m_ = 0;
  const GroundStream* stream_ = nullptr;
  std::vector<std::uint64_t> uploaded_;  ///< the stream's slot versions this context holds
  int culled_ = 0;
  std::vector<unsigned char> rgb_buf_;
  std::vector<float> depth_buf_;
};

/// Moves a directional light's position, across its direction only, to the
/// nearest node of a texel grid fixed in the world.  A light that follows
/// the robot (mode "track") otherwise drags the shadow map's texel grid
/// with it, and every shadow edge, drawn at texel resolution, crawls over
/// the static scene as the robot drives: image corners that are not fixed
/// 3-D points.  Uses the light frame of MuJoCo 2.2.2's shadow pass (up from
/// mjr_orthoVec, then mjr_lookAt).  The shadow's lit/dark pattern is then
/// the same wherever the light is, up to which part of the world the map
/// covers.
void snap_to_shadow_texels(float pos[3], const float dir[3], double texel_m);

/// Leaves out of `scn` (after mjv_updateScene) every static geom
/// whose bounding sphere lies outside the view frustum of its first
/// camera, the sphere swept first along the beam of the shadow-casting sun
/// (when shadows are on), down to 2 m below `shadow_floor_z_m`, so that a
/// geom whose shadow falls in view stays.
/// `aspect` is the image's width over its height.  With far_tile_m > 0, a
/// ground tile (a finite plane but a plant's road piece, kRoadPlanePrefix,
/// or a height field not of the ground's repeated image, material
/// "ground") farther than that is left out as
/// well: the one cull that changes pixels (colour only, beyond the depth
/// range).  A mesh (a plant's fence section) and a height field are culled
/// by their model's bounding sphere (when `model` is given).  Returns the
/// geoms left out.
int cull_to_view(mjvScene* scn, double aspect, double far_tile_m = 0, const mjModel* model = nullptr,
                 double shadow_floor_z_m = 0);

/// Keeps in `scn` one version of each tile of a tiled relief: the tile
/// itself (kReliefTilePrefix) where its centre lies within `detail_m` of
/// the first camera, or everywhere with detail_m <= 0; its far version
/// (kReliefFarTilePrefix, 1 m cells) beyond.  Every render draws one or the
/// other, whether it culls or not.
void select_relief_detail(mjvScene* scn, const mjModel* model, double detail_m);

/// Converts one standard-Z-buffer value to metric depth (0 for d >= 1).
inline float depth_from_buffer(float d, double znear_m, double zfar_m) {
  if (d >= 1.0f) return 0.0f;
  return static_cast<float>(znear_m * zfar_m / (zfar_m - static_cast<double>(d) * (zfar_m - znear_m)));
}

}  // namespace pvb::sim
