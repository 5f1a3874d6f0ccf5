#pragma once
// Ground-truth scoring of the motion model's coarse matches (pvbench slam
// --dump-matches): each match (last frame -> this frame) is labelled by
// harness/matching's label_by_rgbd from the last frame's depth and the
// ground-truth motion between the two frames; written per match to
// motion_matches.csv and summed for stats.json.
#include <opencv2/core.hpp>
#include <string>

#include "pvb/common/output_file.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/harness/matching/ground_truth.hpp"
#include "pvb/sensor/rgbd_frame.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"

namespace pvb::run {

class MotionMatchScorer {
 public:
  MotionMatchScorer(const std::string& out_dir, const std::string& gt_path, const slam::Settings& s);

  /// Scores the motion matches of `frame` (tracked as `r`) against the previous frame.
  void add(const sensor::RgbdFrame& frame, const slam::FrameResult& r);

  /// "motion_matches": {...} for stats.json.
  std::string json() const;

 private:
  static constexpr double kThresholdPx = 4.0;  ///< reprojection error of a correct match
  void remember(const sensor::RgbdFrame& frame, const geom::SE3d& T_w_c);

  std::string gt_path_;
  OutputFile csv_;
  harness::RgbdGroundTruth gt_;
  cv::Mat prev_depth_m_;
  geom::SE3d prev_T_w_c_ = geom::SE3d::Identity();
  long correct_ = 0, wrong_ = 0, kept_correct_ = 0, kept_wrong_ = 0, inlier_correct_ = 0, inlier_wrong_ = 0;
};

}  // namespace pvb::run
