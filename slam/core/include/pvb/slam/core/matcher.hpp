#pragma once
// Descriptor matching guided by geometry (ORB-SLAM2 ORBmatcher, without the
// bag of words): projection of the last frame's points under the motion
// model, projection of local map points, brute force against a keyframe,
// fusion of duplicates and the epipolar search for triangulation.
#include <cstddef>
#include <memory>
#include <vector>

#include "pvb/slam/core/map.hpp"

namespace pvb::slam {

constexpr int kThHigh = 100;     ///< ORB-SLAM2 TH_HIGH, bits
constexpr int kThLow = 50;       ///< ORB-SLAM2 TH_LOW, bits
constexpr int kHistoLength = 30; ///< orientation histogram bins

/// A match between keypoint `i1` of one image and `i2` of another.
struct IndexMatch {
  std::size_t i1 = 0;
  std::size_t i2 = 0;
};

/// Orientation consistency (paper sec. 3 step 4): histogram of the angle
/// differences in 30 bins; matches outside the three largest bins (the
/// second and third only if >= 10 % of the largest) are flagged false.
std::vector<std::uint8_t> orientation_consistent(const std::vector<float>& angle_diff_deg);

/// Motion-model search (paper sec. 3 steps 1-4): projects the map points of
/// `last` into `cur` (whose T_c_w is the predicted pose), searches a window
/// of th x scale(octave) px, keeps the best candidate when its distance is
/// <= TH_HIGH and < ratio x the second best, then applies the orientation
/// check.  Sets cur.map_points and returns the matches (last idx, cur idx).
std::vector<IndexMatch> search_by_projection(Frame& cur, const Frame& last, double th, double ratio);

/// Per-point data of a local map point predicted visible in a frame.
struct ProjectedPoint {
  std::shared_ptr<MapPoint> mp;
  double u = 0, v = 0, u_right = 0;  ///< predicted projection
  int level = 0;                     ///< predicted pyramid level
  double view_cos = 1;               ///< cosine of the viewing angle to the mean normal
};
/// Predicts where a map point appears in `frame` (ORB-SLAM2 isInFrustum with
/// the 0.5 viewing-cosine limit); false when it cannot be seen.
bool project_in_frustum(const Frame& frame, const std::shared_ptr<MapPoint>& mp, ProjectedPoint* out);

/// Local map search: matches the projected points into free keypoints of
/// `cur` within th x (2.5 or 4) x scale px, ratio 0.8 between candidates of
/// the same level.  Returns the number of new matches.
int search_local_points(Frame& cur, const std::vector<ProjectedPoint>& points, double th);

/// Brute force between the map points of `kf` and the keypoints of `cur`
/// (replaces ORB-SLAM2's bag-of-words search): best <= max_distance and
/// < ratio x second best, orientation check.  Sets cur.map_points.
int search_keyframe_bruteforce(const KeyFrame& kf, Frame& cur, int max_distance, double ratio);
/// The same through the direct index (ORB-SLAM2 SearchByBoW): only
/// descriptors under the same vocabulary node are compared (kf's by
/// kf.features_by_node(), cur's by `cur_features`).
int search_keyframe_by_bow(const KeyFrame& kf, Frame& cur, const place::FeatureVector& cur_features,
                           int max_distance, double ratio);

/// EPnP RANSAC (OpenCV, 300 iterations, 4 px, fixed seed) of cur's matched
/// map points against their undistorted keypoints, as relocalisation and
/// loop verification use it after search_keyframe_bruteforce.  Returns the
/// number of RANSAC inliers (0 when no pose was found).  Only when that is
/// >= min_inliers does it set cur.T_c_w and drop the outliers' matches.
int pnp_ransac_on_matches(Frame& cur, int min_inliers);

/// Which point survives when fuse() finds a keypoint already matched.
enum class FusePolicy {
  kMoreObservations,  ///< local mapping: the point with more observations
  kIncomingWins,      ///< loop closing: the projected (loop-side) point replaces the keyframe's
};
/// Projects `points` into keyframe kf and fuses: an empty keypoint gets the
/// observation, an occupied one is resolved by `policy`.
/// Returns the number of fused points.
int fuse(Map& map, const std::shared_ptr<KeyFrame>& kf, const std::vector<std::shared_ptr<MapPoint>>& points,
         double th = 3.0, FusePolicy policy = FusePolicy::kMoreObservations);

/// Epipolar search between the unmatched keypoints of kf1 and kf2 for
/// triangulation: descriptor distance <= TH_LOW, distance to the epipolar
/// line within the 95 % chi-square bound, not too close to the epipole,
/// orientation check.
std::vector<IndexMatch> search_for_triangulation(const KeyFrame& kf1, const KeyFrame& kf2);

}  // namespace pvb::slam
