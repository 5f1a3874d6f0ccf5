#pragma once
// The matching experiment of the paper (sec. 5.1, Figs. 11-12, Table 1):
// ORB coarse matches, filtered by each method, scored against ground truth.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pvb/harness/matching/ground_truth.hpp"
#include "pvb/slam/features/coarse_match.hpp"
#include "pvb/slam/pematch/pe_match.hpp"

namespace pvb::harness {

/// Mismatch-removal methods compared on the same coarse matches.
enum class MatchMethod { kOrb, kHamming, kRansac, kMagsac, kPe, kPeRefined };

/// "orb", "hamming", "ransac", "magsac", "pe", "pe-refined".
const char* method_name(MatchMethod m);
/// All methods in report order.
std::vector<MatchMethod> all_methods();
/// Parses a method name or "all"; throws ConfigError on an unknown name.
std::vector<MatchMethod> parse_methods(const std::string& s);

/// Coarse matches of an image pair and their ground-truth labels.
struct CoarseSet {
  slam::OrbFeatures f1, f2;
  std::vector<slam::FeatureMatch> matches;
  std::vector<slam::PointMatch> raw;     ///< keypoint pixels
  std::vector<slam::PointMatch> points;  ///< pixels fed to the filters (undistorted when known)
  std::vector<MatchLabel> labels;
  double extract_match_ms = 0;           ///< ORB on both images + coarse matching
};

/// Smallest image side the experiment takes, pixels: ORB detects nothing
/// within 16 px of a border, and its default 8-level pyramid (scale 1.2)
/// must keep a level of at least a pixel.
constexpr int kMinImageSidePx = 64;

/// Throws IoError naming `path` when `image` is smaller than
/// kMinImageSidePx on a side.
void check_image_size(const cv::Mat& image, const std::string& path);

/// Extracts ORB features on both images and matches them (ratio test).
/// Throws pvb::Error when an image is smaller than kMinImageSidePx.
CoarseSet make_coarse_set(const cv::Mat& img1, const cv::Mat& img2, double ratio = 0.9);

/// Keep-mask of one method on a coarse set.  `seed` drives the randomised
/// methods (RANSAC/MAGSAC via cv::setRNGSeed, PE-match via its params).
std::vector<std::uint8_t> run_method(MatchMethod m, const CoarseSet& cs, unsigned seed,
                                     const slam::PeMatchParams& pe_params, slam::PeMatcher& pe);

/// Scores of one run.
struct RunScore {
  double precision = 0;  ///< correct kept / kept (0 when nothing kept)
  double recall = 0;     ///< correct kept / correct among coarse (0 when none correct)
  int kept = 0;          ///< kept matches with a known label
  double time_ms = 0;    ///< filter time
};

/// Mean, sample standard deviation, min and max of a series.
struct Spread {
  double mean = 0, std = 0, min = 0, max = 0;
};
Spread spread_of(const std::vector<double>& v);

/// Aggregate over runs for one method.
struct MethodReport {
  std::string name;
  Spread precision, recall, kept, time_ms;
  int coarse = 0;           ///< coarse matches with a known label
  int coarse_correct = 0;   ///< of which correct
  int unknown = 0;          ///< coarse matches without ground truth
  int runs = 0;
};

/// Precision/recall of a keep-mask (matches labelled kUnknown are ignored).
RunScore score_mask(const std::vector<std::uint8_t>& keep, const std::vector<MatchLabel>& labels);

/// Runs every method `runs` times with seeds seed, seed+1, ... and aggregates.
std::vector<MethodReport> run_experiment(const CoarseSet& cs, const std::vector<MatchMethod>& methods, int runs,
                                         unsigned seed, const slam::PeMatchParams& pe_params = {});

/// {"methods":[{"name":..,"precision":..,"recall":..,"kept":..,"coarse":..,"time_ms":..,
///   "precision_std":.., ...}, ...]} plus run metadata.
std::string reports_to_json(const std::vector<MethodReport>& reports, int runs, unsigned seed,
                            double extract_match_ms);

/// Image of the two frames side by side with the matches kept by `keep`:
/// green correct, red wrong, yellow unknown.
cv::Mat draw_matches(const cv::Mat& img1, const cv::Mat& img2, const CoarseSet& cs,
                     const std::vector<std::uint8_t>& keep);

}  // namespace pvb::harness
