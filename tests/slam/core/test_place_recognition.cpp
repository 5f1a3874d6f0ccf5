// The default vocabulary on real Kinect images.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/features/orb_extractor.hpp"
#include "pvb/slam/place/vocabulary.hpp"
#include "shared_data.hpp"

namespace pvb::slam {
namespace {

/// A file of the real Kinect excerpts in ../shared/data/tum.
std::string tum(const std::string& file) { return pvb::test::shared_path("data/tum/" + file); }

cv::Mat descriptors_of(const std::string& path) {
  const cv::Mat grey = cv::imread(path, cv::IMREAD_GRAYSCALE);
  EXPECT_FALSE(grey.empty()) << path;
  OrbExtractor extractor;
  return extractor.extract(grey).descriptors;
}

// The vocabulary was trained on simulated PV scenes and 12 outdoor photos;
// on the real indoor Kinect frames of ../shared/data/tum each image's best
// match among the other five is its own pair's other frame.
TEST(PlaceRecognitionRealFrames, EachKinectFrameScoresItsPairHighest) {
  const place::Vocabulary vocab = place::Vocabulary::load(kDefaultVocabularyPath);
  const std::vector<std::string> images = {tum("fr1_xyz_pair/rgb/1305031102.175304.png"),
                                           tum("fr1_xyz_pair/rgb/1305031102.275326.png"),
                                           tum("fr2_desk_pair/1.png"),
                                           tum("fr2_desk_pair/2.png"),
                                           tum("fr3_long_office_household_pair/rgb/1341847980.722988.png"),
                                           tum("fr3_long_office_household_pair/rgb/1341847982.998783.png")};
  std::vector<place::BowVector> bows(images.size());
  for (std::size_t i = 0; i < images.size(); ++i) vocab.transform(descriptors_of(images[i]), &bows[i]);
  for (std::size_t i = 0; i < images.size(); ++i) {
    std::size_t best = i;
    double best_score = -1;
    for (std::size_t j = 0; j < images.size(); ++j) {
      if (j == i) continue;
      const double s = place::Vocabulary::score(bows[i], bows[j]);
      if (s > best_score) {
        best_score = s;
        best = j;
      }
    }
    EXPECT_EQ(best, i ^ 1u) << images[i] << ": best " << images[best] << " (" << best_score << ")";
  }
}

}  // namespace
}  // namespace pvb::slam
