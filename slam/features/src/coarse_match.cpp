#include "pvb/slam/features/coarse_match.hpp"

#include <opencv2/features2d.hpp>

namespace pvb::slam {

std::vector<FeatureMatch> match_hamming_ratio(const OrbFeatures& f1, const OrbFeatures& f2, double ratio) {
  std::vector<FeatureMatch> out;
  if (f1.descriptors.rows == 0 || f2.descriptors.rows < 2) return out;
  cv::BFMatcher matcher(cv::NORM_HAMMING, false);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(f1.descriptors, f2.descriptors, knn, 2);
  // best claim on each feature of image 2: index into `out`
  std::vector<int> claim(f2.descriptors.rows, -1);
  for (const auto& m : knn) {
    if (m.size() < 2) continue;
    if (!(m[0].distance < ratio * m[1].distance)) continue;
    FeatureMatch fm{m[0].queryIdx, m[0].trainIdx, static_cast<int>(m[0].distance)};
    int& c = claim[fm.i2];
    if (c < 0) {
      c = static_cast<int>(out.size());
      out.push_back(fm);
    } else if (fm.distance < out[c].distance) {
      out[c] = fm;
    }
  }
  return out;
}

}  // namespace pvb::slam
