// Fuzz target: Vocabulary::load, both formats (our binary one and DBoW2's
// text format), then a transform and a score with what was loaded, which
// walk the tree the file described.  Any input must give a vocabulary or a
// pvb::Error.
#include <cstddef>
#include <cstdint>

#include <opencv2/core.hpp>

#include "fuzz_input.hpp"
#include "pvb/common/error.hpp"
#include "pvb/slam/place/vocabulary.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = pvb::fuzz::write_input("input.voc", data, size);
  try {
    const pvb::slam::place::Vocabulary voc = pvb::slam::place::Vocabulary::load(path);
    if (voc.empty()) return 0;
    cv::Mat descriptors(4, 32, CV_8U);
    for (int r = 0; r < descriptors.rows; ++r)
      for (int c = 0; c < 32; ++c) descriptors.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(r * 61 + c * 7);
    pvb::slam::place::BowVector bow;
    pvb::slam::place::FeatureVector fv;
    voc.transform(descriptors, &bow, &fv);
    (void)pvb::slam::place::Vocabulary::score(bow, bow);
  } catch (const pvb::Error&) {
  }
  return 0;
}
