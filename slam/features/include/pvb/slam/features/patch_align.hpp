#pragma once
// Sub-pixel refinement of a match by aligning image patches: the patch
// around a keypoint of a reference image, warped by the affine map that the
// geometry predicts, is aligned to the current image by inverse-
// compositional Gauss-Newton on the translation alone (mean-subtracted, so
// an offset in brightness does not matter).
//
// Why: FAST corners lag when the image zooms, so keypoints matched across a
// forward drive expand less than the scene and bundle adjustment reads the
// shortfall as pitch (docs/experiments/2026-11-21-lawnmower-pitch-bias-per-keyframe.md).
// A match aligned to its map point's reference patch is consistent with the
// reference keypoint instead, whatever that keypoint's own error.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace pvb::slam {

/// The level images of one frame (grey, CV_8U, level 0 first), as
/// OrbExtractor::pyramid() holds them.  Level pixel x lies at level-0
/// (x + 0.5) * W0 / Wl - 0.5 (per axis).
using ImagePyramid = std::vector<cv::Mat>;

/// Deep copy of an extractor's pyramid (its levels are views into a buffer
/// that the next extraction overwrites).
ImagePyramid copy_pyramid(const std::vector<cv::Mat>& levels);

struct PatchAlignParams {
  int half_size = 4;                  ///< patch (2 half_size + 1)^2 level pixels
  int max_iterations = 8;
  double converged_level_px = 0.01;   ///< stop when a step is shorter
  double max_shift_level_px = 1.5;    ///< reject a result further from the start
  /// Reject patches whose gradients constrain one direction much less than
  /// the other (an edge): smallest / largest eigenvalue of the Gauss-Newton
  /// matrix below this.
  double min_eigen_ratio = 0.02;
  double scale_factor = 1.2;          ///< pyramid scale between levels
};

/// Aligns the patch of `ref` around p_ref (level-0 px of the reference
/// image) to `cur` at pyramid level level_cur, starting at p_cur_start
/// (level-0 px).  A_cur_ref maps small offsets around p_ref to offsets
/// around the match in the current image (level-0 px); the reference level
/// sampled is the one whose scale matches.  On success writes the aligned
/// position (level-0 px) to *p_cur and returns true; returns false when a
/// patch leaves its image, the patch is an edge or flat, or the result
/// moved more than max_shift_level_px from the start.
bool align_patch(const ImagePyramid& ref, const Eigen::Vector2d& p_ref, const Eigen::Matrix2d& A_cur_ref,
                 const ImagePyramid& cur, int level_cur, const Eigen::Vector2d& p_cur_start,
                 const PatchAlignParams& params, Eigen::Vector2d* p_cur);

}  // namespace pvb::slam
