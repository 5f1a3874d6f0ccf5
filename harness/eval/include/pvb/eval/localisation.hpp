#pragma once
// Localisation in a saved map, judged against ground truth without any
// alignment: the map's frame is known to the simulator (the pose of the
// mapping session's first camera), so a later session's poses, which SLAM
// gives in the map's frame, are compared with the ground truth brought into
// that frame.  That is what the robot experiences.
//
// Precision classes (Sattler et al., "Benchmarking 6DOF Outdoor Visual
// Localization in Changing Conditions", CVPR 2018): high (0.25 m, 2 deg),
// medium (0.5 m, 5 deg), coarse (5 m, 10 deg); plus a fine class (0.05 m,
// 1 deg) for a robot that must keep to its lane.  A pose more than 1 m or
// 10 deg off is in the wrong place: among look-alike rows, that is the wrong
// aisle.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pvb/eval/trajectory.hpp"
#include "pvb/geometry/se3.hpp"

namespace pvb::eval {

/// A precision class: a pose within both bounds is localised at it.
struct PrecisionClass {
  std::string name;
  double max_translation_m = 0;
  double max_rotation_deg = 0;
};

/// fine (0.05 m, 1 deg), high (0.25, 2), medium (0.5, 5), coarse (5, 10).
const std::vector<PrecisionClass>& precision_classes();

struct LocalisationOptions {
  double wrong_place_m = 1.0;     ///< a pose further off is in the wrong place
  double wrong_place_deg = 10.0;  ///< or turned further
  /// Ground truth and estimate associate when their time stamps differ by
  /// at most this (both come from the same frames in a simulated run).
  std::int64_t max_dt_ns = 1'000'000;
};

struct LocalisationScores {
  std::size_t frames = 0;                 ///< ground-truth frames of the session
  std::size_t posed = 0;                  ///< of them, with a pose in the map's frame
  std::vector<double> share_within;       ///< per precision class, of all frames
  std::size_t wrong_place = 0;            ///< poses beyond wrong_place_m or wrong_place_deg
  std::optional<std::size_t> first_pose_frame;  ///< index of the first frame with a pose
  double metres_to_first_pose = 0;        ///< driven (ground truth) until then
  double translation_median_m = 0;        ///< over the posed frames (0 when none)
  double rotation_median_deg = 0;
  double translation_max_m = 0;
  /// Per ground-truth frame: the errors, or -1 when it has no pose.
  std::vector<double> translation_error_m, rotation_error_deg;
};

/// Scores the estimate (T_map_c, in the map's frame) against the ground
/// truth (T_world_c) of the same session, with T_world_map the pose of the
/// map's frame in the world.  Every ground-truth frame counts: one without a
/// pose is not localised.
LocalisationScores score_localisation(const Trajectory& gt_world, const Trajectory& est_map,
                                      const geom::SE3d& T_world_map, const LocalisationOptions& options = {});

/// The scores as a JSON object (one line), null where there is no value.
std::string localisation_json(const LocalisationScores& s);

}  // namespace pvb::eval
