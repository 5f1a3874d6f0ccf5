#include "motion_match_scorer.hpp"

#include <sstream>
#include <vector>

#include "pvb/common/text.hpp"

namespace pvb::run {

MotionMatchScorer::MotionMatchScorer(const std::string& out_dir, const std::string& gt_path,
                                     const slam::Settings& s)
    : gt_path_(gt_path), csv_(out_dir + "/motion_matches.csv") {
  csv_.append("frame,octave1,octave2,u1,v1,u2,v2,label,pe_keep,pose_inlier\n");
  gt_.K = s.K;
  if (s.has_distortion()) gt_.dist_coeffs = (cv::Mat_<double>(1, 5) << s.k1, s.k2, s.p1, s.p2, s.k3);
  gt_.threshold_px = kThresholdPx;
}

void MotionMatchScorer::add(const sensor::RgbdFrame& frame, const slam::FrameResult& r) {
  const geom::SE3d T_w_c = harness::tum_pose_at(gt_path_, static_cast<double>(frame.t_ns) * 1e-9);
  const auto& m = r.tracking.motion;
  if (prev_depth_m_.empty() || m.undistorted.empty()) {
    remember(frame, T_w_c);
    return;
  }
  gt_.depth1_m = prev_depth_m_;
  gt_.depth2_m = frame.depth_m;
  gt_.T_c2_c1 = T_w_c.inverse() * prev_T_w_c_;
  const std::vector<harness::MatchLabel> labels = harness::label_by_rgbd(m.raw, m.undistorted, gt_);
  std::ostringstream rows;
  for (std::size_t k = 0; k < labels.size(); ++k) {
    const int label = static_cast<int>(labels[k]);
    const int keep = m.pe_keep[k];
    const int inlier = k < m.pose_inlier.size() ? m.pose_inlier[k] : 0;
    rows << frame.index << "," << m.octaves[k][0] << "," << m.octaves[k][1] << "," << m.undistorted[k].p1.x()
         << "," << m.undistorted[k].p1.y() << "," << m.undistorted[k].p2.x() << "," << m.undistorted[k].p2.y()
         << "," << label << "," << keep << "," << inlier << "\n";
    if (labels[k] == harness::MatchLabel::kUnknown) continue;
    const bool correct = labels[k] == harness::MatchLabel::kCorrect;
    (correct ? correct_ : wrong_) += 1;
    if (keep) (correct ? kept_correct_ : kept_wrong_) += 1;
    if (inlier) (correct ? inlier_correct_ : inlier_wrong_) += 1;
  }
  csv_.append(rows.str());
  remember(frame, T_w_c);
}

std::string MotionMatchScorer::json() const {
  const auto ratio = [](long a, long b) { return b > 0 ? static_cast<double>(a) / static_cast<double>(b) : 0.0; };
  std::ostringstream js;
  js << "\"motion_matches\": {\"threshold_px\": " << kThresholdPx << ", \"correct\": " << correct_
     << ", \"wrong\": " << wrong_ << ", \"kept_correct\": " << kept_correct_ << ", \"kept_wrong\": " << kept_wrong_
     << ", \"pe_precision\": " << format_g(ratio(kept_correct_, kept_correct_ + kept_wrong_))
     << ", \"pe_recall\": " << format_g(ratio(kept_correct_, correct_))
     << ", \"pose_inlier_correct\": " << inlier_correct_ << ", \"pose_inlier_wrong\": " << inlier_wrong_ << "}";
  return js.str();
}

void MotionMatchScorer::remember(const sensor::RgbdFrame& frame, const geom::SE3d& T_w_c) {
  prev_depth_m_ = frame.depth_m.clone();
  prev_T_w_c_ = T_w_c;
}

}  // namespace pvb::run
