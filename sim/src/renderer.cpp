#include "pvb/sim/renderer.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include "pvb/common/error.hpp"
#include "pvb/sim/ground_stream.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/sim/textures.hpp"

namespace pvb::sim {

Renderer::Renderer(const mjModel* model, GlBackend backend, int width, int height)
    : width_(width), height_(height) {
  install_mujoco_handlers();  // MuJoCo's log goes to stderr, not MUJOCO_LOG.TXT
  if (width > model->vis.global.offwidth || height > model->vis.global.offheight)
    throw ConfigError("model", "visual.global.offwidth/offheight",
                      "at least " + std::to_string(width) + "x" + std::to_string(height),
                      std::to_string(model->vis.global.offwidth) + "x" + std::to_string(model->vis.global.offheight));
  gl_ = GlContext::create(backend, width, height);
  mjr_defaultContext(&con_);
  mjv_defaultScene(&scene_);
  mjv_defaultOption(&option_);
  mjv_defaultCamera(&camera_);
  // Room for every geom of the model (a plant's thousands; culled to the
  // view before drawing), a varied ground's tiles (textures.hpp) and decor.
  mjv_makeScene(model, &scene_, std::max(4000, model->ngeom + 200) + kMaxGroundTiles);
  mjr_makeContext(model, &con_, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &con_);
  if (con_.currentBuffer != mjFB_OFFSCREEN) {
    mjr_freeContext(&con_);
    mjv_freeScene(&scene_);
    throw UnavailableError(std::string("GL backend ") + to_string(gl_->backend()) +
                           ": MuJoCo could not use its off-screen buffer");
  }
  rgb_buf_.resize(static_cast<std::size_t>(width) * height * 3);
  depth_buf_.resize(static_cast<std::size_t>(width) * height);
}

Renderer::~Renderer() {
  // MuJoCo frees its GL objects in the current context: make it ours.
  try {
    gl_->make_current();
  } catch (const UnavailableError&) {
    // nothing to free into; the context goes with gl_
  }
  mjr_freeContext(&con_);
  mjv_freeScene(&scene_);
}

namespace {

void cross(float* a, const float* b, const float* c) {
  a[0] = b[1] * c[2] - b[2] * c[1];
  a[1] = b[2] * c[0] - b[0] * c[2];
  a[2] = b[0] * c[1] - b[1] * c[0];
}

void normalize(float* v) {
  const float n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (n < 1e-10f) {
    v[0] = 0;
    v[1] = 0;
    v[2] = 1;
    return;
  }
  for (int i = 0; i < 3; ++i) v[i] /= n;
}

}  // namespace

void snap_to_shadow_texels(float pos[3], const float dir[3], double texel_m) {
  // The light's view axes as MuJoCo builds them: up = dir x (-1, 0, 0)
  // (or dir x (0, 1, 0) when dir is near the x axis), side = dir x up,
  // up' = side x dir.
  float f[3] = {dir[0], dir[1], dir[2]}, up[3], s[3], u[3];
  float other[3] = {-1, 0, 0};
  cross(up, dir, other);
  if (up[0] * up[0] + up[1] * up[1] + up[2] * up[2] <= 0.01f) {
    other[0] = 0;
    other[1] = 1;
    cross(up, dir, other);
  }
  normalize(up);
  normalize(f);
  cross(s, f, up);
  normalize(s);
  cross(u, s, f);
  normalize(u);
  double a = 0, b = 0;
  for (int i = 0; i < 3; ++i) {
    a += static_cast<double>(s[i]) * pos[i];
    b += static_cast<double>(u[i]) * pos[i];
  }
  const double da = a - texel_m * std::round(a / texel_m), db = b - texel_m * std::round(b / texel_m);
  for (int i = 0; i < 3; ++i) pos[i] = static_cast<float>(pos[i] - da * s[i] - db * u[i]);
}

namespace {

/// The sphere that holds a primitive geom, its radius; -1 for a geom that is
/// not culled (an infinite plane, decor) or whose model gives the radius
/// (a height field, a mesh).
double bounding_radius(const mjvGeom& g) {
  const double a = g.size[0], b = g.size[1], c = g.size[2];
  switch (g.type) {
    case mjGEOM_BOX: return std::sqrt(a * a + b * b + c * c);
    case mjGEOM_SPHERE: return a;
    case mjGEOM_ELLIPSOID: return std::max({a, b, c});
    case mjGEOM_CYLINDER: return std::sqrt(a * a + b * b);
    case mjGEOM_CAPSULE: return a + b;
    case mjGEOM_PLANE:  // a ground tile (the ground plane's is far larger); an infinite plane stays
      return a > 0 && b > 0 ? std::sqrt(a * a + b * b) : -1;
    default: return -1;
  }
}

/// The beam of the first shadow-casting directional light (unit, pointing
/// down from the light), or none.
std::optional<Eigen::Vector3d> shadow_beam(const mjvScene& scn) {
  if (!scn.flags[mjRND_SHADOW]) return std::nullopt;
  for (int i = 0; i < scn.nlight; ++i) {
    const mjvLight& l = scn.lights[i];
    if (l.directional && l.castshadow) return Eigen::Vector3d(l.dir[0], l.dir[1], l.dir[2]).normalized();
  }
  return std::nullopt;
}

/// Whether `name` starts with `prefix`.
bool named(const char* name, const char* prefix) {
  return std::strncmp(name, prefix, std::strlen(prefix)) == 0;
}

}  // namespace

void select_relief_detail(mjvScene* scn, const mjModel* model, double detail_m) {
  const mjvGLCamera& cam = scn->camera[0];
  int kept = 0;
  for (int i = 0; i < scn->ngeom; ++i) {
    const mjvGeom g = scn->geoms[i];
    bool keep = true;
    if (g.type == mjGEOM_HFIELD && g.objtype == mjOBJ_GEOM && g.category == mjCAT_STATIC) {
      const char* name = model->names + model->name_geomadr[g.objid];
      const bool far = named(name, kReliefFarTilePrefix), tile = !far && named(name, kReliefTilePrefix);
      const double dx = g.pos[0] - cam.pos[0], dy = g.pos[1] - cam.pos[1], dz = g.pos[2] - cam.pos[2];
      const bool near = detail_m <= 0 || std::sqrt(dx * dx + dy * dy + dz * dz) <= detail_m;
      keep = far ? !near : (!tile || near);
    }
    if (!keep) continue;
    scn->geoms[kept] = g;
    if (scn->geoms[kept].segid >= 0) scn->geoms[kept].segid = kept;
    ++kept;
  }
  scn->ngeom = kept;
}

int cull_to_view(mjvScene* scn, double aspect, double far_tile_m, const mjModel* model,
                 double shadow_floor_z_m) {
  const int backdrop_matid = model ? mj_name2id(model, mjOBJ_MATERIAL, "ground") : -1;
  const mjvGLCamera& cam = scn->camera[0];
  const Eigen::Vector3d pos(cam.pos[0], cam.pos[1], cam.pos[2]), fwd(cam.forward[0], cam.forward[1], cam.forward[2]);
  const Eigen::Vector3d up(cam.up[0], cam.up[1], cam.up[2]);
  const Eigen::Vector3d right = fwd.cross(up);
  const double tan_top = cam.frustum_top / cam.frustum_near, tan_bottom = -cam.frustum_bottom / cam.frustum_near;
  const double tan_side = 0.5 * (cam.frustum_top - cam.frustum_bottom) * aspect / cam.frustum_near;
  // Outward normals of the four side planes through the eye, in (right, up, forward).
  const Eigen::Vector3d planes[4] = {Eigen::Vector3d(1, 0, -tan_side).normalized(),
                                     Eigen::Vector3d(-1, 0, -tan_side).normalized(),
                                     Eigen::Vector3d(0, 1, -tan_top).normalized(),
                                     Eigen::Vector3d(0, -1, -tan_bottom).normalized()};
  const std::optional<Eigen::Vector3d> beam = shadow_beam(*scn);
  int kept = 0;
  for (int i = 0; i < scn->ngeom; ++i) {
    const mjvGeom g = scn->geoms[i];
    double r = g.category == mjCAT_STATIC && g.objtype == mjOBJ_GEOM ? bounding_radius(g) : -1;
    const bool model_geom = model && g.category == mjCAT_STATIC && g.objtype == mjOBJ_GEOM;
    if (g.type == mjGEOM_MESH && model_geom) r = model->geom_rbound[g.objid];
    if (g.type == mjGEOM_HFIELD && model_geom) r = hfield_bounding_radius(model, g.objid);
    Eigen::Vector3d c(g.pos[0], g.pos[1], g.pos[2]);
    const bool relief_tile =
        g.type == mjGEOM_HFIELD && model_geom && model->geom_matid[g.objid] != backdrop_matid;
    if (r >= 0 && beam && beam->z() < -1e-3 && !relief_tile) {  // a relief's tile takes shadows, casts none
      // Its shadow: swept along the beam down to 2 m below the lowest ground
      // that takes shadows (none for a geom lower than that).
      const double len = std::clamp((c.z() - shadow_floor_z_m + r + 2.0) / -beam->z(), 0.0, 500.0);
      c += 0.5 * len * *beam;
      r += 0.5 * len;
    }
    bool visible = r < 0;
    const bool tile = g.type == mjGEOM_PLANE || relief_tile;
    // A plant's road is seen far along it; ground tiles are not drawn that
    // far (its name asked only of a plane the far cull would leave out).
    const auto road = [&] {
      return g.type == mjGEOM_PLANE && model_geom &&
             named(model->names + model->name_geomadr[g.objid], kRoadPlanePrefix);
    };
    if (!visible && far_tile_m > 0 && tile && (c - pos).norm() > far_tile_m + r && !road()) continue;
    if (!visible) {
      const Eigen::Vector3d d = c - pos;
      const Eigen::Vector3d q(d.dot(right), d.dot(up), d.dot(fwd));
      visible = q.z() > cam.frustum_near - r && q.z() < cam.frustum_far + r;
      for (const Eigen::Vector3d& n : planes) visible = visible && q.dot(n) <= r;
    }
    if (!visible) continue;
    scn->geoms[kept] = g;
    // Segmentation paints a geom by its segid, mjv_updateScene's index of it.
    if (scn->geoms[kept].segid >= 0) scn->geoms[kept].segid = kept;
    ++kept;
  }
  const int culled = scn->ngeom - kept;
  scn->ngeom = kept;
  return culled;
}

void Renderer::apply_ground_stream() {
  if (stream_ == nullptr) return;
  const std::vector<std::uint64_t>& versions = stream_->slot_versions();
  uploaded_.resize(versions.size(), 0);  // version 0: as mjr_makeContext uploaded the slot
  for (std::size_t i = 0; i < versions.size(); ++i)
    if (uploaded_[i] != versions[i]) {
      mjr_uploadTexture(stream_->model(), &con_, stream_->slot_textures()[i]);
      uploaded_[i] = versions[i];
    }
  for (int i = 0; i < scene_.ngeom; ++i) {
    mjvGeom& g = scene_.geoms[i];
    if (g.objtype != mjOBJ_GEOM || g.category != mjCAT_STATIC) continue;
    const int tex = stream_->texture_of_geom(g.objid);
    if (tex >= 0) g.texid = tex;
  }
}

void Renderer::set_shadows(bool on) { scene_.flags[mjRND_SHADOW] = on ? 1 : 0; }

void Renderer::render(const mjModel* model, mjData* data, int camera_id, cv::Mat* rgb, cv::Mat* depth_m) {
  // Another renderer of this process (or none, once it was destroyed) may
  // hold the thread's current context.
  gl_->make_current();
  camera_.type = mjCAMERA_FIXED;
  camera_.fixedcamid = camera_id;
  mjv_updateScene(model, data, &option_, nullptr, &camera_, mjCAT_ALL, &scene_);
  culled_ = cull_ ? cull_to_view(&scene_, static_cast<double>(width_) / height_, far_tile_m_, model,
                                 shadow_floor_z_m_)
                  : 0;
  select_relief_detail(&scene_, model, relief_detail_m_);
  apply_ground_stream();
  if (stable_shadows_) {
    const double texel_m = shadow_texel_m(con_.shadowClip, con_.shadowSize);
    for (int i = 0; i < scene_.nlight; ++i) {
      mjvLight& light = scene_.lights[i];
      if (light.directional && light.castshadow) snap_to_shadow_texels(light.pos, light.dir, texel_m);
    }
  }
  const mjrRect viewport{0, 0, width_, height_};
  mjr_render(viewport, &scene_, &con_);
  mjr_readPixels(rgb ? rgb_buf_.data() : nullptr, depth_m ? depth_buf_.data() : nullptr, viewport, &con_);

  if (rgb != nullptr) {
    rgb->create(height_, width_, CV_8UC3);
    for (int r = 0; r < height_; ++r) {
      const unsigned char* src = rgb_buf_.data() + static_cast<std::size_t>(height_ - 1 - r) * width_ * 3;
      std::copy(src, src + static_cast<std::size_t>(width_) * 3, rgb->ptr<unsigned char>(r));
    }
  }
  if (depth_m != nullptr) copy_depth(model, depth_m);
}

void Renderer::copy_depth(const mjModel* model, cv::Mat* depth_m) const {
  const double extent = model->stat.extent;
  const double n = model->vis.map.znear * extent;
  const double f = model->vis.map.zfar * extent;
  depth_m->create(height_, width_, CV_32FC1);
  for (int r = 0; r < height_; ++r) {
    const float* src = depth_buf_.data() + static_cast<std::size_t>(height_ - 1 - r) * width_;
    float* dst = depth_m->ptr<float>(r);
    for (int c = 0; c < width_; ++c) dst[c] = depth_from_buffer(src[c], n, f);
  }
}

void Renderer::render_geom_ids(const mjModel* model, mjData* data, int camera_id, cv::Mat* geom_id,
                               cv::Mat* depth_m) {
  gl_->make_current();
  camera_.type = mjCAMERA_FIXED;
  camera_.fixedcamid = camera_id;
  mjv_updateScene(model, data, &option_, nullptr, &camera_, mjCAT_ALL, &scene_);
  culled_ = cull_ ? cull_to_view(&scene_, static_cast<double>(width_) / height_, far_tile_m_, model,
                                 shadow_floor_z_m_)
                  : 0;
  select_relief_detail(&scene_, model, relief_detail_m_);
  const unsigned char shadow = scene_.flags[mjRND_SHADOW];
  scene_.flags[mjRND_SEGMENT] = 1;
  scene_.flags[mjRND_IDCOLOR] = 1;
  scene_.flags[mjRND_SHADOW] = 0;
  const mjrRect viewport{0, 0, width_, height_};
  mjr_render(viewport, &scene_, &con_);
  mjr_readPixels(rgb_buf_.data(), depth_m ? depth_buf_.data() : nullptr, viewport, &con_);
  scene_.flags[mjRND_SEGMENT] = 0;
  scene_.flags[mjRND_IDCOLOR] = 0;
  scene_.flags[mjRND_SHADOW] = shadow;
  // IDCOLOR paints scene geom s as the 24-bit number s + 1 (0: background).
  geom_id->create(height_, width_, CV_32SC1);
  for (int r = 0; r < height_; ++r) {
    const unsigned char* src = rgb_buf_.data() + static_cast<std::size_t>(height_ - 1 - r) * width_ * 3;
    int* dst = geom_id->ptr<int>(r);
    for (int c = 0; c < width_; ++c, src += 3) {
      const int seg = (src[0] | (src[1] << 8) | (src[2] << 16)) - 1;
      const bool is_geom = seg >= 0 && seg < scene_.ngeom && scene_.geoms[seg].objtype == mjOBJ_GEOM;
      dst[c] = is_geom ? scene_.geoms[seg].objid : -1;
    }
  }
  if (depth_m != nullptr) copy_depth(model, depth_m);
}

}  // namespace pvb::sim
