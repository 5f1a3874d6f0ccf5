#pragma once
// What loop detection (loop_closing.cpp) and loop correction
// (loop_correction.cpp) share: a provisional map's frame and its merge.
#include <memory>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/core/map.hpp"

namespace pvb::slam::detail {

/// A provisional map's frame in the map's own (T_into_from), from its
/// keyframe `kf`'s pose there, `T_c_w_into`.
inline geom::SE3d frame_into(const geom::SE3d& T_c_w_into, const KeyFrame& kf) {
  return T_c_w_into.inverse() * kf.T_c_w();
}

/// A merge: the provisional map of `kf` moves rigidly into the frame of
/// `loop_kf`'s map, where the verification put `kf` (`T_c_w_into`), and
/// its spanning tree is hung under `loop_kf` (ORB-SLAM3 MergeLocal, scale 1).
void merge_into(Map& map, const std::shared_ptr<KeyFrame>& kf, const std::shared_ptr<KeyFrame>& loop_kf,
                const geom::SE3d& T_c_w_into);

}  // namespace pvb::slam::detail
