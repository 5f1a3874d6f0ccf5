#include "pvb/sim/truth_surface.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pvb/scenes/ground_relief.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/simulator.hpp"

namespace pvb::sim {

const char* to_string(SurfaceClass c) {
  switch (c) {
    case SurfaceClass::kGround: return "ground";
    case SurfaceClass::kPanel: return "panel";
    case SurfaceClass::kFrame: return "frame";
    case SurfaceClass::kPost: return "post";
    case SurfaceClass::kWall: return "wall";
    case SurfaceClass::kShrub: return "shrub";
    case SurfaceClass::kOther: break;
  }
  return "other";
}

SurfaceClass classify_geom(const mjModel* m, int g) {
  const int mat = m->geom_matid[g];
  if (mat < 0) return SurfaceClass::kOther;
  const std::string name = mj_id2name(m, mjOBJ_MATERIAL, mat) ? mj_id2name(m, mjOBJ_MATERIAL, mat) : "";
  if (name.rfind("ground", 0) == 0) return SurfaceClass::kGround;  // "ground", or a varied ground's tiles "groundtK"
  // "a<array>panel<variant>" a module, "a<array>slab<variant>" a table's modules as one slab
  if (name.find("panel") != std::string::npos || name.find("slab") != std::string::npos)
    return SurfaceClass::kPanel;
  if (name == "backsheet") return SurfaceClass::kFrame;
  if (name == "steel") return m->geom_size[3 * g + 2] > 0.2 ? SurfaceClass::kPost : SurfaceClass::kFrame;
  if (name == "brick" || name == "plaster") return SurfaceClass::kWall;
  if (name == "foliage" || name == "bark") return SurfaceClass::kShrub;
  return SurfaceClass::kOther;
}

Eigen::Vector3d geom_normal(const mjModel* m, const mjData* d, int g, const Eigen::Vector3d& p_w,
                            const Eigen::Vector3d& eye_w) {
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> R(d->geom_xmat + 9 * g);
  const Eigen::Map<const Eigen::Vector3d> x(d->geom_xpos + 3 * g);
  const Eigen::Map<const Eigen::Vector3d> size(m->geom_size + 3 * g);
  const Eigen::Vector3d p = R.transpose() * (p_w - x);
  Eigen::Vector3d n;
  switch (m->geom_type[g]) {
    case mjGEOM_PLANE: n = Eigen::Vector3d::UnitZ(); break;
    case mjGEOM_BOX: {  // the face the point is nearest to, relative to the half sizes
      Eigen::Index axis = 0;
      (p.cwiseAbs().cwiseQuotient(size)).maxCoeff(&axis);
      n = Eigen::Vector3d::Unit(axis) * (p[axis] < 0 ? -1.0 : 1.0);
      break;
    }
    case mjGEOM_HFIELD: {  // the ground relief: its triangle's normal, as MuJoCo interpolates it
      const int h = m->geom_dataid[g];
      const mjtNum* hs = m->hfield_size + 4 * h;
      n = scenes::grid_surface(m->hfield_data + m->hfield_adr[h], hs[2], m->hfield_nrow[h], m->hfield_ncol[h], hs[0],
                               hs[1], p.x(), p.y())
              .normal;
      break;
    }
    case mjGEOM_SPHERE: n = p; break;
    case mjGEOM_ELLIPSOID: n = p.cwiseQuotient(size.cwiseProduct(size)); break;
    case mjGEOM_CYLINDER:
      n = std::abs(p.z()) >= size[1] - 1e-4 ? Eigen::Vector3d(0, 0, p.z() < 0 ? -1 : 1)
                                           : Eigen::Vector3d(p.x(), p.y(), 0);
      break;
    default: return (eye_w - p_w).normalized();
  }
  return (R * n).normalized();
}

namespace {

/// The samples, one per voxel, in the order their voxels were first seen,
/// found by voxel key through an open-addressed table (linear probing): the
/// pixels of a route look a voxel up tens of millions of times.
class VoxelSamples {
 public:
  VoxelSamples() { rehash(1u << 16); }
  /// The index of voxel `key`'s sample; `*added` when it is new (then default).
  std::size_t find_or_add(std::int64_t key, bool* added) {
    if (2 * (samples_.size() + 1) > slots_.size()) rehash(2 * slots_.size());
    std::size_t i = slot_of(key);
    for (; slots_[i].index != kEmpty; i = (i + 1) & mask_)
      if (slots_[i].key == key) {
        *added = false;
        return slots_[i].index;
      }
    slots_[i] = {key, static_cast<std::uint32_t>(samples_.size())};
    samples_.emplace_back(key, TruthSample{});
    *added = true;
    return slots_[i].index;
  }
  TruthSample& operator[](std::size_t i) { return samples_[i].second; }
  /// (voxel key, sample) pairs.
  std::vector<std::pair<std::int64_t, TruthSample>>& samples() { return samples_; }

 private:
  static constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;
  struct Slot {  // the key too, so that a probe reads one cache line
    std::int64_t key;
    std::uint32_t index;
  };
  std::size_t slot_of(std::int64_t key) const {
    return static_cast<std::size_t>((static_cast<std::uint64_t>(key) * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void rehash(std::size_t slots) {
    slots_.assign(slots, Slot{0, kEmpty});
    mask_ = slots - 1;
    shift_ = 64;
    for (std::size_t n = slots; n > 1; n >>= 1) --shift_;
    for (std::uint32_t j = 0; j < samples_.size(); ++j) {
      std::size_t i = slot_of(samples_[j].first);
      while (slots_[i].index != kEmpty) i = (i + 1) & mask_;
      slots_[i] = {samples_[j].first, j};
    }
  }
  std::vector<std::pair<std::int64_t, TruthSample>> samples_;
  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
  int shift_ = 64;
};

/// The key of the voxel holding p: 21 bits an axis.
std::int64_t voxel_of(const Eigen::Vector3d& p, double size) {
  const auto q = [size](double v) { return static_cast<std::int64_t>(std::floor(v / size)) & 0x1FFFFF; };
  return (q(p.x()) << 42) | (q(p.y()) << 21) | q(p.z());
}

/// The class of every geom of the model, nullopt for the robot's own.
std::vector<std::optional<SurfaceClass>> geom_classes(const mjModel* m) {
  const int robot_body = mj_name2id(m, mjOBJ_BODY, kRobotBody);
  std::vector<std::optional<SurfaceClass>> classes(static_cast<std::size_t>(m->ngeom));
  for (int g = 0; g < m->ngeom; ++g)
    if (robot_body < 0 || m->body_rootid[m->geom_bodyid[g]] != robot_body)
      classes[static_cast<std::size_t>(g)] = classify_geom(m, g);
  return classes;
}

/// Adds the pixels of one rendered frame to the voxel map.
void add_frame(Simulator& sim, const cv::Mat& depth_m, const cv::Mat& geom_id, const scenes::Camera& cam,
               const std::vector<std::optional<SurfaceClass>>& classes, double voxel_m,
               VoxelSamples* voxels) {
  const geom::PinholeIntrinsics K = sim.intrinsics();
  const geom::SE3d T_w_c = sim.T_w_c();
  const Eigen::Vector3d eye = T_w_c.translation();
  // Neighbouring pixels mostly fall in one voxel: the last one is kept at
  // hand.
  std::int64_t last_key = -1;
  std::size_t last = 0;
  for (int v = 0; v < depth_m.rows; ++v)
    for (int u = 0; u < depth_m.cols; ++u) {
      const double z = depth_m.at<float>(v, u);
      const int g = geom_id.at<int>(v, u);
      if (g < 0 || z < cam.depth_range_m[0] || z > cam.depth_range_m[1] || !classes[static_cast<std::size_t>(g)])
        continue;
      const Eigen::Vector3d p_c((u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z);
      const Eigen::Vector3d p_w = T_w_c * p_c;
      const double range = p_c.norm();
      const std::int64_t key = voxel_of(p_w, voxel_m);
      if (key == last_key) {
        TruthSample& s = (*voxels)[last];
        s.range_m = std::min(s.range_m, range);
        continue;
      }
      bool added = false;
      last = voxels->find_or_add(key, &added);
      last_key = key;
      TruthSample& s = (*voxels)[last];
      if (added) {
        s.p_w = p_w;
        s.cls = *classes[static_cast<std::size_t>(g)];
        s.n_w = geom_normal(sim.model(), sim.data(), g, p_w, eye);
        s.range_m = range;
      } else if (range < s.range_m) {
        s.range_m = range;
      }
    }
}

}  // namespace

std::vector<TruthSample> sample_truth_surface(const scenes::Scenario& scenario, GlBackend backend,
                                              const TruthSurfaceOptions& options) {
  Simulator sim(scenario, SceneDetail::kGeometry);  // depth and geom ids: no texture needed
  Renderer renderer(sim.model(), backend, scenario.camera.width, scenario.camera.height);
  const std::vector<std::optional<SurfaceClass>> classes = geom_classes(sim.model());
  const int n = scenes::frame_count(scenario, options.frames);
  VoxelSamples voxels;
  cv::Mat depth, ids;
  for (int i = 0; i < n; ++i) {
    if (i > 0) sim.advance();
    if (i % std::max(1, options.every) != 0) continue;
    renderer.render_geom_ids(sim.model(), sim.data(), sim.camera_id(), &ids, &depth);
    add_frame(sim, depth, ids, scenario.camera, classes, options.voxel_m, &voxels);
  }
  // In voxel-key order, as the samples have always been listed.
  std::vector<std::pair<std::int64_t, TruthSample>>& sorted = voxels.samples();
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<TruthSample> out;
  out.reserve(sorted.size());
  for (const auto& [k, s] : sorted) out.push_back(s);
  return out;
}

}  // namespace pvb::sim
