#pragma once
// ORB feature extraction as ORB-SLAM2 does it (Mur-Artal & Tardos 2017,
// ORBextractor): a scale pyramid, FAST per grid cell with a fallback
// threshold, quadtree distribution of the corners over the image, the
// intensity-centroid orientation and the 256-bit steered BRIEF (rBRIEF)
// descriptor with the learned 31x31 test pattern.
#include <opencv2/core.hpp>
#include <vector>

namespace pvb::slam {

/// Parameters of OrbExtractor; defaults are ORB-SLAM2's TUM1.yaml values.
struct OrbParams {
  int num_features = 1000;     ///< features kept over all levels
  double scale_factor = 1.2;   ///< scale between consecutive pyramid levels
  int num_levels = 8;          ///< pyramid levels
  int ini_fast_threshold = 20; ///< FAST threshold tried first in each cell
  int min_fast_threshold = 7;  ///< FAST threshold used where a cell has no corner
  /// Sub-pixel keypoints: fit a quadratic to the FAST score of the 3x3
  /// neighbourhood at the keypoint's level and move the keypoint to its
  /// peak (at most half a level pixel).  ORB-SLAM2 keeps whole level pixels.
  bool sub_pixel = true;
};

/// Keypoints and their descriptors, one row of `descriptors` per keypoint.
struct OrbFeatures {
  /// Keypoints in level-0 pixel coordinates; `octave` is the pyramid level,
  /// `angle` the orientation in degrees, `size` the patch diameter (31 px
  /// scaled to level 0), `response` the FAST score.
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  ///< CV_8U, N x 32 (256 bits per row)
};

/// FAST-9 (16-pixel circle) corner score at (x, y): the largest t for which
/// 9 contiguous circle pixels are all brighter than centre + t or all darker
/// than centre - t, minus one, as cv::FAST's score (0 where no arc passes
/// t = 1).  (x, y) must lie at least 3 px inside the image.
int fast9_score(const cv::Mat& grey, int x, int y);

/// Offset (dx, dy), each in [-0.5, 0.5], of the peak of the quadratic fitted
/// to a 3x3 grid of scores s[row][col] centred on s[1][1]; (0, 0) where the
/// fit has no maximum.
cv::Point2f quadratic_peak_offset(const float s[3][3]);

/// ORB extractor.  Holds the pyramid and scratch buffers so that repeated
/// calls reuse memory; not thread-safe (one per thread).
class OrbExtractor {
 public:
  explicit OrbExtractor(const OrbParams& params = {});

  /// Extracts features from an 8-bit image (grey, BGR or BGRA; colour is
  /// converted).  Returns at most params.num_features keypoints.  Throws
  /// pvb::Error for an empty image or one of another type.
  OrbFeatures extract(const cv::Mat& image);

  /// Scale of pyramid level `level` relative to level 0 (scale_factor^level).
  double level_scale(int level) const { return scales_.at(level); }

  const OrbParams& params() const { return params_; }

  /// The level images of the last extract() (level 0 is the grey input);
  /// views into buffers that the next extract() overwrites.
  const std::vector<cv::Mat>& pyramid() const { return pyramid_; }

 private:
  void build_pyramid(const cv::Mat& grey);
  std::vector<cv::KeyPoint> detect_level(int level, int num_wanted) const;

  OrbParams params_;
  std::vector<double> scales_;           ///< scale_factor^level
  std::vector<int> features_per_level_;  ///< geometric split of num_features
  std::vector<int> umax_;                ///< half-width of the circular patch per row
  std::vector<cv::Mat> pyramid_;         ///< level images (views into padded_)
  std::vector<cv::Mat> padded_;          ///< level images with a reflected border
};

/// Steered BRIEF descriptor (256 bits) of one keypoint given in the
/// coordinates of `image` (which must have >= 19 px of valid border around
/// it).  `image` is expected to be smoothed already (ORB-SLAM2 uses a 7x7
/// Gaussian, sigma 2).  Exposed for testing against OpenCV.
void compute_rbrief(const cv::Mat& image, const cv::KeyPoint& kp, unsigned char* desc32);

/// Intensity-centroid orientation in degrees of the circular patch of radius
/// 15 px around `pt` (Rosin 1999, as in ORB).
float ic_angle_deg(const cv::Mat& image, cv::Point2f pt, const std::vector<int>& umax);

/// Per-row half-widths of the circular patch of radius `half_patch` px.
std::vector<int> circular_patch_umax(int half_patch);

}  // namespace pvb::slam
