#pragma once
// The scene's true surface as the camera could have seen it along the
// route: for every k-th frame the simulator renders its exact depth and
// which geom each pixel shows, each pixel within the camera's depth range
// is put back into the world, and one sample is kept per voxel of a known
// size.  So every sample lies on a surface the camera saw (the visibility
// mask is the rendering itself), at a known density, labelled by class
// (from the geom's material), with the geom's analytic normal and the
// nearest range it was seen from.  The robot's own geoms are left out.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/gl_context.hpp"

typedef struct mjModel_ mjModel;
typedef struct mjData_ mjData;

namespace pvb::sim {

enum class SurfaceClass : int { kOther = 0, kGround, kPanel, kFrame, kPost, kWall, kShrub };
inline constexpr int kSurfaceClasses = 7;
const char* to_string(SurfaceClass c);

struct TruthSample {
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
  Eigen::Vector3d n_w = Eigen::Vector3d::UnitZ();
  SurfaceClass cls = SurfaceClass::kOther;
  double range_m = 0;  ///< nearest camera distance it was seen from
};

struct TruthSurfaceOptions {
  double voxel_m = 0.01;  ///< one sample per voxel of this size
  int every = 5;          ///< render every k-th frame
  int frames = 0;         ///< frames of the route (0: the scenario's duration)
};

/// Samples the surface seen along the scenario's route (its seed, its
/// frames).  Deterministic: the same scenario gives the same samples.
std::vector<TruthSample> sample_truth_surface(const scenes::Scenario& scenario, GlBackend backend,
                                              const TruthSurfaceOptions& options = {});

/// The class of a model geom, from its material's name.
SurfaceClass classify_geom(const mjModel* model, int geom_id);

/// The outward unit normal of geom `geom_id` at the world point `p_w` on
/// its surface (plane, height field, box, sphere, ellipsoid, cylinder; others: the
/// direction to `eye_w`).
Eigen::Vector3d geom_normal(const mjModel* model, const mjData* data, int geom_id, const Eigen::Vector3d& p_w,
                            const Eigen::Vector3d& eye_w);

}  // namespace pvb::sim
