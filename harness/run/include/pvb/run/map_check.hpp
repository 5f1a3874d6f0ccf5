#pragma once
// Is a SLAM map's error noise or bias?  map-check puts every keyframe of a
// map snapshot at its ground-truth pose, fits the points to their
// measurements there, and then runs a global bundle adjustment (keyframe 0
// fixed) from that start:
//   - with the measurements as they are: where the best fit of all the
//     measurements lies, i.e. the error no optimiser can remove;
//   - with synthetic measurements, many draws: the projections of the fitted
//     points plus (a) Gaussian noise of the measured RMS, or (b) the measured
//     residuals with random signs (the same sizes on the same measurements,
//     no systematic part).  These give the error that noise alone leaves on
//     this map's geometry (which keyframes see which points, at what depth).
// When the measured fit is worse than the sign-flipped draws and keeps a
// per-axis rotation bias, the measurements carry a systematic error; when it
// lies among the draws, the map is noise-limited.
#include <cstdint>
#include <string>
#include <vector>

#include "pvb/eval/trajectory.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/slam/core/map_snapshot.hpp"

namespace pvb::run {

struct MapCheckOptions {
  int draws = 20;                ///< synthetic draws per noise kind (0: none)
  std::uint32_t seed = 1;        ///< first draw's seed; draw k uses seed + k
  double max_time_diff_s = 0.02; ///< keyframe to ground-truth association
};

/// Keyframe trajectory error after se3 alignment, and the signed rotation
/// error per consecutive keyframe pair (camera axes: x pitch, y yaw, z roll).
struct MapCheckFit {
  double ate_rmse_m = 0;
  geom::Vec3d rot_mean_deg = geom::Vec3d::Zero();  ///< mean per keyframe pair
  geom::Vec3d rot_t = geom::Vec3d::Zero();         ///< mean / standard error
};

struct MapCheckResult {
  std::size_t keyframes = 0, points = 0, measurements = 0;
  MapCheckFit estimate;  ///< the keyframe poses as the snapshot holds them
  MapCheckFit measured;  ///< global BA from ground truth, measurements as they are
  /// Whitened residual RMS (u, v, u_right; pixels / scale^octave) at ground
  /// truth after the point fit, over residuals under 3.
  geom::Vec3d residual_rms = geom::Vec3d::Zero();
  std::vector<MapCheckFit> gaussian;      ///< one per draw
  std::vector<MapCheckFit> sign_flipped;  ///< one per draw
};

/// Runs the check.  Throws pvb::Error when fewer than 3 keyframes associate
/// with `gt` or keyframe 0 has no ground truth.
MapCheckResult check_map(const slam::MapSnapshot& map, const eval::Trajectory& gt, const MapCheckOptions& options);

/// The result as a short text report: one line per fit, then a reading.
/// The reading calls the measurements systematic when the measured fit is
/// worse than every sign-flipped draw or keeps a per-axis rotation bias with
/// |t| > 3, and noise-limited otherwise.
std::string format_map_check(const MapCheckResult& result);

}  // namespace pvb::run
