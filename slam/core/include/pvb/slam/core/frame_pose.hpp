#pragma once
// A frame's pose from its matched map points.
#include "pvb/slam/core/frame.hpp"
#include "pvb/slam/core/map.hpp"

namespace pvb::slam {

/// Pose-only optimisation of `f` against its matched map points (robust,
/// ORB-SLAM2's four rounds): sets f.T_c_w and has_pose, and marks f.outlier
/// (cleared first).  Returns the inlier count (0 with fewer than 3 matches).
int optimize_frame_pose(Frame& f);

}  // namespace pvb::slam
