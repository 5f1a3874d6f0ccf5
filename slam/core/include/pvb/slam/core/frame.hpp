#pragma once
// A tracked image: ORB features with undistorted positions, depth and
// virtual right coordinate per keypoint, their map-point associations and
// the camera pose.  A value type: copying shares map points (shared_ptr)
// and descriptor pixels (cv::Mat), which are never modified in place.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/core/feature_spill.hpp"
#include "pvb/slam/core/reports.hpp"
#include "pvb/slam/features/orb_extractor.hpp"
#include "pvb/slam/features/patch_align.hpp"
#include "pvb/slam/optim/optimizer.hpp"

namespace pvb::slam {

class MapPoint;

/// Camera model shared by all frames of a run (immutable after creation).
struct CameraModel {
  StereoIntrinsics K;          ///< fx, fy, cx, cy, bf
  int width = 640, height = 480;
  cv::Mat K_cv;                ///< 3x3 CV_64F, for OpenCV calls
  cv::Mat dist_cv;             ///< 1x5 CV_64F (k1 k2 p1 p2 k3); empty: no distortion
  /// With distortion: the undistorted position of every image pixel
  /// (CV_32FC2, height x width), from cv::undistortPoints once per run.
  cv::Mat undistort_table;
  double th_depth_m = 3.0;     ///< close/far threshold, metres
  /// Undistorted image bounds (ORB-SLAM2 ComputeImageBounds).
  double min_x = 0, max_x = 640, min_y = 0, max_y = 480;
  /// Scale pyramid: scale_factor^level, its square and inverse square.
  std::vector<double> scale, level_sigma2, inv_level_sigma2;
  double log_scale_factor = std::log(1.2);
  int num_levels = 8;
  /// Grid for the area search (ORB-SLAM2: 64 x 48 cells over the bounds).
  static constexpr int kGridCols = 64, kGridRows = 48;
  double grid_inv_w = 0, grid_inv_h = 0;

  /// Builds the model; dist may be all zero.
  static CameraModel make(const StereoIntrinsics& K, int width, int height, const std::vector<double>& dist,
                          double th_depth_m, double scale_factor, int num_levels);
  bool in_bounds(double u, double v) const { return u >= min_x && u < max_x && v >= min_y && v < max_y; }
  /// Projection (u, v) of p_c (no check on z).
  Eigen::Vector2d project(const Eigen::Vector3d& p_c) const {
    return {K.fx * p_c.x() / p_c.z() + K.cx, K.fy * p_c.y() / p_c.z() + K.cy};
  }
  /// Point in the camera frame of undistorted pixel uv at depth z_m.
  Eigen::Vector3d unproject(const Eigen::Vector2d& uv, double z_m) const {
    return {(uv.x() - K.cx) * z_m / K.fx, (uv.y() - K.cy) * z_m / K.fy, z_m};
  }
  /// Undistorted position of the image (distorted) position px: identity
  /// without distortion, else the table read bilinearly (positions outside
  /// the image are clamped to its border).  Within 2e-3 px of
  /// cv::undistortPoints for TUM1.yaml's Kinect distortion (tested).
  Eigen::Vector2d undistort(const Eigen::Vector2d& px) const;
  /// Predicted pyramid level of a point at `dist_m` with max distance `max_dist_m`.
  int predict_scale(double dist_m, double max_dist_m) const;
};

/// A keypoint as SLAM keeps it after extraction: cv::KeyPoint's position,
/// orientation and level (16 bytes; cv::KeyPoint's size, response and
/// class id, 12 bytes more, are not used after extraction).
struct Keypoint {
  cv::Point2f pt;   ///< px
  float angle = 0;  ///< orientation, degrees (cv::KeyPoint::angle)
  int octave = 0;   ///< pyramid level
};

/// The area-search index of a frame: keypoint indices grouped by grid cell
/// in one array (cell c's in [start[c], start[c + 1]), in keypoint order),
/// with 16-bit entries while the frame has fewer than 65536 keypoints.  A
/// vector per cell, as ORB-SLAM2 keeps it, costs 24 bytes per cell and a
/// heap block per occupied one: 75 KB and more per frame at 64 x 48 cells.
class KeypointGrid {
 public:
  KeypointGrid() = default;
  /// cell_of[i]: the cell (row-major) of keypoint i, or -1 outside the grid.
  KeypointGrid(const std::vector<int>& cell_of, int num_cells);
  bool empty() const { return start16_.empty() && start32_.empty(); }
  /// Calls f(i) for each keypoint i in the cell, in ascending order.
  template <typename F>
  void for_each_in_cell(int cell, F&& f) const {
    const auto c = static_cast<std::size_t>(cell);
    if (!start16_.empty()) {
      for (std::uint32_t k = start16_[c]; k < start16_[c + 1]; ++k) f(static_cast<std::size_t>(index16_[k]));
    } else {
      for (std::uint32_t k = start32_[c]; k < start32_[c + 1]; ++k) f(static_cast<std::size_t>(index32_[k]));
    }
  }
  std::size_t memory_bytes() const;   ///< on the heap
  std::size_t spilled_bytes() const;  ///< in a FeatureSpill
  /// Moves the index into `spill`.
  void spill_to(FeatureSpill* spill);

 private:
  FeatureArray<std::uint16_t> start16_, index16_;  ///< fewer than 65536 keypoints
  FeatureArray<std::uint32_t> start32_, index32_;  ///< otherwise
};

/// Heap bytes of the buffer a cv::Mat refers to (0 for a view of memory
/// OpenCV did not allocate): the data with OpenCV's alignment slack and its
/// reference-count block.
std::size_t mat_heap_bytes(const cv::Mat& m);

class Frame {
 public:
  Frame() = default;
  /// Builds a frame from features extracted on the image and the depth map
  /// (metres, 0 = invalid).
  Frame(std::uint64_t id, std::int64_t t_ns, OrbFeatures features, const cv::Mat& depth_m,
        std::shared_ptr<const CameraModel> cam);
  /// A frame from what a map file keeps of a keyframe: keypoints as
  /// detected and undistorted, descriptors (N x 32 CV_8U) and depth per
  /// keypoint (<= 0: none); sizes must agree.  No map points yet, no pose.
  static Frame from_saved(std::uint64_t id, std::int64_t t_ns, std::vector<cv::Point2f> keys,
                          std::vector<Keypoint> keys_un, cv::Mat descriptors, std::vector<float> depth_m,
                          std::shared_ptr<const CameraModel> cam);

  std::size_t size() const { return keys_un.size(); }
  /// Indices of keypoints within radius_px of (u, v) with octave in
  /// [min_level, max_level] (max_level < 0: any).
  std::vector<std::size_t> features_in_area(double u, double v, double radius_px, int min_level = -1,
                                            int max_level = -1) const;
  /// The same into `out` (cleared first; ascending), so that a search over
  /// many points reuses one buffer.
  void features_in_area(double u, double v, double radius_px, int min_level, int max_level,
                        std::vector<std::size_t>* out) const;
  /// World point of keypoint i from its depth; precondition depth_m[i] > 0.
  Eigen::Vector3d unproject_world(std::size_t i) const;
  /// Keypoints with a depth.
  int num_with_depth() const;
  /// (depth, keypoint index) of the keypoints with depth, nearest first.
  std::vector<std::pair<float, std::size_t>> keypoints_by_depth() const;
  /// Observation of keypoint i for the optimiser.
  Observation observation(std::size_t i) const;
  /// Moves keypoint i to image (distorted) position `to_px`: keys[i] is
  /// set, keys_un[i] becomes its undistorted position (CameraModel::
  /// undistort), and u_right[i] follows.  The grid index is not rebuilt;
  /// the shifts are far smaller than its cells.
  void move_keypoint(std::size_t i, const Eigen::Vector2d& to_px);
  Eigen::Vector3d camera_center_w() const { return T_c_w.inverse().translation(); }
  /// What this frame holds, by structure.
  FrameMemory memory() const;
  /// Frees the keypoints and all that goes with them (descriptors, depths,
  /// map points, the grid, the pyramid): the frame keeps its pose and time
  /// and has no keypoints (size() 0).
  void release_features();
  /// Frees the pyramid and the alignment marks, which serve only alignment
  /// to it (a frame without a pyramid is never aligned).
  void release_pyramid();
  /// Moves the keypoints, descriptors, depths and the grid into `spill`
  /// (a keyframe that has left the local map): the values and every
  /// reader stay the same, the memory is the spill's file.  Once only;
  /// a frame without features stays as it is.
  void spill_features(const std::shared_ptr<FeatureSpill>& spill);
  bool features_spilled() const { return spill_ != nullptr; }

  std::uint64_t id = 0;
  std::int64_t t_ns = 0;
  std::shared_ptr<const CameraModel> cam;

 private:
  /// Where the features lie, when spilled; kept alive while they do.
  /// Declared before every array it may hold, so it is destroyed after
  /// them (a frame may outlive the System that made the spill).
  std::shared_ptr<FeatureSpill> spill_;

 public:
  /// Positions as detected (distorted image px); level and orientation are
  /// keys_un's.  Without distortion these are keys_un's positions, but a
  /// keypoint moved by patch alignment may differ from its keys_un in the
  /// last bit (move_keypoint), so both are kept.
  FeatureArray<cv::Point2f> keys;
  FeatureArray<Keypoint> keys_un;  ///< undistorted
  cv::Mat descriptors;                ///< N x 32 CV_8U
  FeatureArray<float> depth_m;        ///< per keypoint, <= 0 invalid
  FeatureArray<float> u_right;        ///< u - bf / depth, < 0 when no depth
  std::vector<std::shared_ptr<MapPoint>> map_points;  ///< per keypoint, may be null
  std::vector<std::uint8_t> outlier;  ///< per keypoint, set by pose optimisation
  geom::SE3d T_c_w = geom::SE3d::Identity();
  bool has_pose = false;
  /// The grey image pyramid (raw, distorted pixels), for aligning matches
  /// to keyframe patches; null when patch alignment is off.  Shared, never
  /// modified.
  std::shared_ptr<const ImagePyramid> pyramid;
  /// Per keypoint, the id of the map point its patch alignment was last
  /// tried for (kNotAligned: never).
  static constexpr std::uint64_t kNotAligned = ~std::uint64_t(0);
  std::vector<std::uint64_t> aligned_for;

 private:
  /// The virtual right-camera coordinate u - bf / depth (ORB-SLAM2's RGB-D uR).
  float right_coordinate(float u_un, float depth) const { return static_cast<float>(u_un - cam->K.bf / depth); }
  /// Map-point slots, outlier and alignment marks, and the area grid, for
  /// the keypoints in keys_un.
  void build_index();

  KeypointGrid grid_;  ///< keypoints by cell (CameraModel::kGridCols x kGridRows), as detected
};


/// Hamming distance of two 32-byte descriptors.
int descriptor_distance(const cv::Mat& a, const cv::Mat& b);
int descriptor_distance(const unsigned char* a, const unsigned char* b);

}  // namespace pvb::slam
