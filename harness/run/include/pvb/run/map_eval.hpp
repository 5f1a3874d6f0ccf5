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

/// A dense map written by write_dense_maps(): "corrected" (every keyframe
/// at its final pose), "live" (each at the pose it was made with) and, when
/// a loop was closed, "before_loop" and "after_loop" (the corrected map
/// around it).
struct DenseMapFile {
  std::string name;
  std::string file;         ///< PointCloud.ply for the corrected map, PointCloud_<name>.ply for the others
  std::size_t points = 0;   ///< points written (corrected and live maps; 0 for the loop's)
};

/// Writes the maps of a stopped System with dense mapping on into `dir`,
/// corrected first (System::write_point_cloud() re-bins the final poses),
/// each streamed from the mapper without holding it whole.  Throws
/// pvb::IoError when a file cannot be written.
std::vector<DenseMapFile> write_dense_maps(slam::System& system, const std::string& dir);

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
