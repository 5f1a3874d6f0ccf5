#pragma once
// Where the sun reaches: rays from the surface points a depth image sees
// towards the sun, cast against the scene's geoms on the CPU.  MuJoCo's
// shadow map is drawn into the colour image only; a second shadowed render
// would cost about as much as the first.
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <optional>
#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <unordered_map>
#include <vector>

#include "pvb/geometry/pinhole.hpp"
#include "pvb/geometry/se3.hpp"

namespace pvb::sim {

/// The geoms that can cast a shadow in one state of the simulator, binned
/// on a grid across the sun's direction so that a ray tests only the few
/// whose bounding spheres it may meet.  Geoms of the groups MuJoCo draws by
/// default (0-2) cast shadows; planes and height fields do not (the ground
/// does not shade itself here).  shadowed() is const and thread-safe.
/// Where the points that shadowed() will be asked about lie: within
/// radius_m of centre_w.
struct ShadeRegion {
  Eigen::Vector3d centre_w = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
};

class SunShadowCaster {
 public:
  /// With a region, geoms that no ray from a point in it towards the sun
  /// can meet are left out (a plant's thousands, of which a camera's few
  /// metres of depth see a handful): shadowed() then answers as without
  /// the region for every point in it, and for no point outside it.
  SunShadowCaster(const mjModel* m, const mjData* d, const Eigen::Vector3d& to_sun_w,
                  const std::optional<ShadeRegion>& region = std::nullopt);
  /// True when the ray from p_w towards the sun meets a geom farther than
  /// `start_m` along it (past the surface the point lies on).
  bool shadowed(const Eigen::Vector3d& p_w, double start_m = 0.02) const;

 private:
  /// The key of grid cell (i, j), counted in cells across the sun's direction.
  static std::uint64_t cell_key(long i, long j);
  const mjModel* m_;
  const mjData* d_;
  Eigen::Vector3d s_, e1_, e2_;  ///< towards the sun, and two axes across it
  double cell_m_ = 0.5;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;  ///< geom ids per cell
};

/// The sun's reach per pixel of `depth_m` (CV_32FC1, metres along the
/// optical axis, 0 = none) seen from T_w_c: CV_8UC1, 1 where the point is
/// lit, 0 where a geom shadows it, where there is no depth or where it is
/// deeper than `max_depth_m` (where the caller has no use for it).  Blocks of
/// `step` pixels are tested at their corners and split in quarters where
/// the corners differ (a shadow smaller than a block and missing all its
/// corners is missed); the result does not depend on the thread count.
cv::Mat sun_visibility(const SunShadowCaster& caster, const cv::Mat& depth_m,
                       const geom::PinholeIntrinsics& K, const geom::SE3d& T_w_c, int step = 16,
                       float max_depth_m = std::numeric_limits<float>::infinity());

}  // namespace pvb::sim
