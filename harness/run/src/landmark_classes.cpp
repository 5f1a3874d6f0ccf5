#include "landmark_classes.hpp"

#include <cmath>
#include <limits>
#include <unordered_map>

#include "pvb/common/error.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/truth_surface.hpp"

namespace pvb::run {
namespace {

constexpr double kCellM = 0.1;     ///< grid cell of the nearest-sample search
constexpr double kLabelM = 0.05;   ///< a landmark further from every sample is unlabelled

std::int64_t cell_key(int x, int y, int z) {
  return (std::int64_t(x) * 73856093) ^ (std::int64_t(y) * 19349663) ^ (std::int64_t(z) * 83492791);
}

Eigen::Vector3i cell_of(const Eigen::Vector3d& p) {
  return {static_cast<int>(std::floor(p.x() / kCellM)), static_cast<int>(std::floor(p.y() / kCellM)),
          static_cast<int>(std::floor(p.z() / kCellM))};
}

/// The class of the sample nearest to p within kLabelM, or -1.
int nearest_class(const std::unordered_map<std::int64_t, std::vector<int>>& grid,
                  const std::vector<sim::TruthSample>& truth, const Eigen::Vector3d& p) {
  const Eigen::Vector3i c = cell_of(p);
  double best = kLabelM;
  int cls = -1;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = grid.find(cell_key(c.x() + dx, c.y() + dy, c.z() + dz));
        if (it == grid.end()) continue;
        for (int i : it->second) {
          const double d = (truth[i].p_w - p).norm();
          if (d < best) best = d, cls = static_cast<int>(truth[i].cls);
        }
      }
  return cls;
}

}  // namespace

void classify_matched_landmarks(slam::System& system, sim::GlBackend backend, MapReport* r) {
  if (!r->load || !r->T_world_map) return;
  const std::string file = map_scenario_file(r->load->app_json);
  if (file.empty()) {
    r->matched_landmarks_note = "the map names no scenario file";
    return;
  }
  std::vector<sim::TruthSample> truth;
  try {
    sim::TruthSurfaceOptions o;
    o.voxel_m = 0.02;
    o.every = 10;
    truth = sim::sample_truth_surface(scenes::load_scenario(file), backend, o);
  } catch (const Error& e) {
    r->matched_landmarks_note = std::string("the map's scenario could not be rendered: ") + e.what();
    return;
  }
  std::unordered_map<std::int64_t, std::vector<int>> grid;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Eigen::Vector3i c = cell_of(truth[i].p_w);
    grid[cell_key(c.x(), c.y(), c.z())].push_back(static_cast<int>(i));
  }
  std::vector<int> counts(sim::kSurfaceClasses, 0);
  int total = 0, unlabelled = 0;
  for (const auto& l : system.landmark_uses()) {
    const auto before = r->found_at_load.find(l.id);
    if (before == r->found_at_load.end() || l.found <= before->second) continue;
    ++total;
    const int cls = nearest_class(grid, truth, *r->T_world_map * l.p_w);
    if (cls < 0) ++unlabelled;
    else ++counts[cls];
  }
  r->matched_landmarks = {{"total", total}};
  for (int c = 0; c < sim::kSurfaceClasses; ++c)
    r->matched_landmarks.emplace_back(sim::to_string(static_cast<sim::SurfaceClass>(c)), counts[c]);
  r->matched_landmarks.emplace_back("unlabelled", unlabelled);
}

}  // namespace pvb::run
