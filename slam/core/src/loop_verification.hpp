#pragma once
// What loop detection (loop_closing.cpp) takes from the geometric
// verification of candidates (loop_verification.cpp).
#include "pvb/geometry/se3.hpp"
#include "pvb/slam/core/map.hpp"

namespace pvb::slam::detail {

/// Median depth of the keyframe's map points in its camera (ORB-SLAM2
/// ComputeSceneMedianDepth); 0 without points.
double scene_median_depth_m(const KeyFrame& kf);

/// Rotation angle (degrees) and camera-centre distance (metres) between two poses T_c_w.
void pose_difference(const geom::SE3d& a, const geom::SE3d& b, double* dist_m, double* angle_deg);

}  // namespace pvb::slam::detail
