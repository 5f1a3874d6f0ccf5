#pragma once
// Coarse matching of two feature sets: brute-force Hamming nearest neighbour
// with a ratio test (ORB-SLAM2's mfNNratio test, paper sec. 3 step 1).
#include <opencv2/core.hpp>
#include <vector>

#include "pvb/slam/features/orb_extractor.hpp"

namespace pvb::slam {

/// One coarse match between feature i1 of image 1 and i2 of image 2.
struct FeatureMatch {
  int i1 = 0;            ///< keypoint index in image 1
  int i2 = 0;            ///< keypoint index in image 2
  int distance = 0;      ///< Hamming distance, bits
};

/// Brute-force Hamming matching from image 1 to image 2 keeping a match when
/// best < ratio * second best.  A feature of image 2 is used at most once
/// (the closer of two claims wins), as in ORB-SLAM2's matchers.
std::vector<FeatureMatch> match_hamming_ratio(const OrbFeatures& f1, const OrbFeatures& f2,
                                              double ratio = 0.9);

}  // namespace pvb::slam
