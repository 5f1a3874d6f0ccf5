#pragma once
// A start from two views, for a depth camera that gives too little depth
// to start from one frame (a Kinect in the sun): keypoints matched between
// a first view and a later one, the essential matrix of their motion, the
// points triangulated, and the scale from the few keypoints that have a
// measured depth in either view (docs/slam.md, "Starting without depth").
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pvb/slam/core/frame.hpp"
#include "pvb/slam/core/matcher.hpp"
#include "pvb/slam/core/options.hpp"

namespace pvb::slam {

/// Why a pair of views gave no start: too few matches (a new first view is
/// due), or not yet (wait for more motion).
enum class TwoViewFailure { kFewMatches, kNotYet };

struct TwoViewStart {
  geom::SE3d T_cur_ref;                  ///< the second view from the first, metres
  std::vector<IndexMatch> matches;       ///< (first-view keypoint, second-view keypoint) of each point
  std::vector<Eigen::Vector3d> p_ref_m;  ///< each point in the first view's frame
  int scale_points = 0;                  ///< depth ratios the scale is the median of
  double scale_spread = 0;
  double median_parallax_deg = 0;
};

/// Keypoint matches between two views of nearly the same place: each
/// keypoint of `ref` against those of `cur` within radius_px at its own
/// octave, best Hamming distance <= kThLow and < 0.9 x the second best,
/// one per keypoint of `cur`, then the orientation check.
std::vector<IndexMatch> search_for_start(const Frame& ref, const Frame& cur, double radius_px);

/// The start from `ref` and `cur`, or nothing with the reason in `why` and
/// its kind in `failure`.  Deterministic (OpenCV's RANSAC with its fixed
/// seed).
std::optional<TwoViewStart> two_view_start(const Frame& ref, const Frame& cur, const TwoViewOptions& o,
                                           std::string* why, TwoViewFailure* failure);

}  // namespace pvb::slam
