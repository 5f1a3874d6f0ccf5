#pragma once
// Patch alignment of map-point observations (beyond ORB-SLAM2): every
// observation of a map point, in a tracked frame or a keyframe, is moved
// to where the point's reference-keyframe patch aligns, so that all of a
// point's observations agree with the keypoint it was created from.  FAST
// keypoints detected independently in each image do not: under a zoom they
// lag, and bundle adjustment reads the lag as pitch (docs/slam.md, "Patch
// alignment").  Callers hold Map::mutex().
#include <cstddef>

#include "pvb/slam/core/map.hpp"
#include "pvb/slam/features/patch_align.hpp"

namespace pvb::slam {

/// Aligns keypoint i of f, an observation of mp, to mp's reference-keyframe
/// patch, warped by the affine map that f's pose and the point's depth in
/// the reference predict (fronto-parallel patch).  On success moves
/// keys[i], keys_un[i] and u_right[i].  Returns false at once when f has
/// no pyramid; otherwise records mp as tried in f.aligned_for[i] and
/// returns false when there is nothing to align to (no live reference
/// keyframe with a pyramid, f is that keyframe) or align_patch fails.
bool align_to_reference(Frame& f, std::size_t i, const MapPoint& mp, const PatchAlignParams& params);

/// Aligns every observation of kf not yet tried for its current map point.
/// Returns {tried, aligned}.
std::pair<int, int> align_keyframe_observations(KeyFrame& kf, const PatchAlignParams& params);

}  // namespace pvb::slam
