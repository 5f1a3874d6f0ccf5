#pragma once
// A SLAM run's dense maps scored against the scenario's true surface
// (docs/map_accuracy.md): the pieces `pvbench eval-map` and `pvbench run`
// share.  The true surface is sampled once per run and every map (the
// corrected one, the live one, the corrected one around the first loop
// correction) is scored against it.
#include <string>
#include <utility>
#include <vector>

#include "pvb/eval/align.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/eval/map_accuracy.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/report/map_scores.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/gl_context.hpp"
#include "pvb/sim/truth_surface.hpp"
#include "pvb/slam/core/system.hpp"
#include "pvb/slam/dense/point_cloud.hpp"

namespace pvb::run {

/// A run's dense maps by name: "corrected" (every keyframe at its final
/// pose), "live" (each at the pose it was made with) and, when a loop was
/// closed, "before_loop" and "after_loop" (the corrected map around it).
using NamedClouds = std::vector<std::pair<std::string, slam::dense::PointCloud>>;

/// The maps of a stopped System with dense mapping on, corrected first
/// (System::point_cloud() re-bins the final poses).
NamedClouds dense_maps(slam::System& system);

/// The file of map `name`: PointCloud.ply for the corrected map,
/// PointCloud_<name>.ply for the others.
std::string dense_map_file(const std::string& name);

/// Writes every map as PLY into `dir`; returns the file names.  Throws
/// pvb::IoError when a file cannot be written.
std::vector<std::string> write_dense_maps(const NamedClouds& maps, const std::string& dir);

/// How a map goes from SLAM's world (its first camera) into the ground
/// truth's world.
enum class MapAlignment {
  kFirstFrame,  ///< the first estimated pose put on its ground truth (default)
  kAte,         ///< the trajectory's SE(3) alignment, as for the ATE
};
const char* to_string(MapAlignment a);

/// The transform for `alignment`; `ate` is the trajectory's evaluation
/// against `gt` (its pairs and alignment).
eval::Sim3Transform map_to_world(MapAlignment alignment, const eval::EvalResult& ate, const eval::Trajectory& gt,
                                 const eval::Trajectory& est);

/// The map's points in the world, of unknown range.
std::vector<eval::MapPoint> map_in_world(const slam::dense::PointCloud& cloud, const eval::Sim3Transform& T);

/// The true surface seen along the scenario's route, as evaluation points.
std::vector<eval::SurfacePoint> true_surface(const scenes::Scenario& scenario, sim::GlBackend backend,
                                             const sim::TruthSurfaceOptions& options);

/// The map's points with their class and error as PLY properties
/// (binary, float x y z, uchar class, float error), for CloudCompare or
/// MeshLab.  Throws pvb::IoError when the file cannot be written.
void write_map_errors_ply(const std::string& path, const std::vector<eval::MapPoint>& map,
                          const std::vector<eval::MapPointScore>& scores);

}  // namespace pvb::run
