#pragma once
// Ground truth for feature matches: homography pairs (Oxford) and
// RGB-D pairs with depth, poses and intrinsics (TUM layout, simulator).
#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pvb/geometry/pinhole.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/slam/pematch/fundamental.hpp"

namespace pvb::harness {

/// Label of one match against ground truth.
enum class MatchLabel : std::uint8_t {
  kWrong = 0,
  kCorrect = 1,
  kUnknown = 2,  ///< cannot be checked (no valid depth at the first point)
};

/// Reads a 3x3 homography written as nine numbers (Oxford H1toNp files).
/// Throws IoError when the file is missing or malformed, a number is not
/// finite, or the matrix is singular.
Eigen::Matrix3d load_homography(const std::string& path);

/// Correct when H maps p1 to within threshold_px of p2.
std::vector<MatchLabel> label_by_homography(const std::vector<slam::PointMatch>& m, const Eigen::Matrix3d& H,
                                            double threshold_px = 3.0);

/// The camera of an ORB-SLAM2 RGB-D settings file, as the matching
/// experiment uses it.
struct CameraSettings {
  geom::PinholeIntrinsics K;
  cv::Mat dist_coeffs;               ///< 1x5 (k1 k2 p1 p2 k3), or empty when zero
  double depth_map_factor = 5000.0;  ///< raw depth units per metre
};

/// Reads the settings file with slam::read_settings (every key it requires,
/// the ranges it accepts: IoError or ConfigError otherwise) and keeps its
/// camera: Camera.fx/fy/cx/cy/width/height, k1, k2, p1, p2, k3 and
/// DepthMapFactor.
CameraSettings load_camera_settings(const std::string& path);

/// Loads a 16-bit depth PNG as metres (CV_32F, 0 = invalid).  Throws IoError
/// for a missing, damaged or unreadable file and for an image without any
/// valid depth (all zero).
cv::Mat load_depth_m(const std::string& path, double depth_map_factor);

/// Parses a TUM pose "tx ty tz qx qy qz qw" (T_w_c); throws ConfigError
/// naming `what` when it is not seven numbers.
geom::SE3d parse_tum_pose(const std::string& text, const std::string& what);

/// Pose T_w_c at time t_s from a TUM groundtruth.txt, interpolated
/// (translation linear, rotation slerp) between the bracketing stamps.
/// Throws IoError when the file cannot be read or when the nearest sample
/// is further than max_gap_s from t_s (outside the trajectory, the nearest
/// end pose is used if it is within max_gap_s).
geom::SE3d tum_pose_at(const std::string& groundtruth_path, double t_s, double max_gap_s = 0.05);

/// RGB-D ground truth for a pair of frames.
struct RgbdGroundTruth {
  cv::Mat depth1_m, depth2_m;  ///< CV_32F metres, 0 = invalid, in raw (distorted) pixels
  geom::PinholeIntrinsics K;
  cv::Mat dist_coeffs;         ///< empty: no distortion
  geom::SE3d T_c2_c1 = geom::SE3d::Identity();  ///< inv(T_w_c2) * T_w_c1
  double threshold_px = 3.0;
  /// depth check: |z_pred - depth2| <= depth_tol_rel * z_pred + depth_tol_abs_m
  double depth_tol_rel = 0.05;
  double depth_tol_abs_m = 0.02;
};

/// Labels matches given in raw pixels (`raw`) with their undistorted
/// positions (`undist`, same order; equal to raw when there is no
/// distortion).  Correct when p1 back-projected with its depth and moved by
/// T_c2_c1 projects within threshold_px of p2 (undistorted pixels) and,
/// where depth2 is valid at p2, the depths agree.  No valid depth at p1:
/// kUnknown.
std::vector<MatchLabel> label_by_rgbd(const std::vector<slam::PointMatch>& raw,
                                      const std::vector<slam::PointMatch>& undist, const RgbdGroundTruth& gt);

/// Undistorts pixel coordinates with K and dist (identity when dist is empty).
std::vector<slam::PointMatch> undistort_matches(const std::vector<slam::PointMatch>& raw,
                                                const geom::PinholeIntrinsics& K, const cv::Mat& dist);

}  // namespace pvb::harness
