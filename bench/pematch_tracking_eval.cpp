// PE-match variants on the motion-model coarse matches of real tracking
// runs, scored against ground truth.
//
// Input: one or more motion_matches.csv written by
//   pvbench slam ... --dump-matches
// (per frame the coarse matches of the motion model, labelled from depth and
// ground-truth poses by harness/matching's label_by_rgbd).  Every variant
// filters exactly the same coarse sets, so their precision and recall
// compare directly; seeds 1..S average out PE-match's randomness.
//
// Usage: pematch_tracking_eval [--seeds S] FILE.csv [FILE.csv ...]
#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "pvb/slam/pematch/pe_match.hpp"

namespace {

using pvb::slam::PeMatchParams;
using pvb::slam::PointMatch;

/// The coarse matches of one frame with their ground-truth labels.
struct CoarseFrame {
  std::vector<PointMatch> pairs;
  std::vector<int> label;  ///< 0 wrong, 1 correct, 2 unknown (harness::MatchLabel)
  std::vector<int> octave; ///< octave of the keypoint in the current frame
};

std::vector<CoarseFrame> read_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "pematch_tracking_eval: %s: cannot open\n", path.c_str());
    std::exit(2);
  }
  std::map<long, CoarseFrame> by_frame;
  std::string line;
  std::getline(in, line);  // header
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream ss(line);
    long frame;
    int oct1, oct2, label, keep, inlier;
    double u1, v1, u2, v2;
    if (!(ss >> frame >> oct1 >> oct2 >> u1 >> v1 >> u2 >> v2 >> label >> keep >> inlier)) {
      std::fprintf(stderr, "pematch_tracking_eval: %s:%d: expected 10 numbers\n", path.c_str(), line_no);
      std::exit(2);
    }
    CoarseFrame& f = by_frame[frame];
    f.pairs.push_back({Eigen::Vector2d(u1, v1), Eigen::Vector2d(u2, v2)});
    f.label.push_back(label);
    f.octave.push_back(oct2);
  }
  std::vector<CoarseFrame> out;
  for (auto& [k, f] : by_frame) out.push_back(std::move(f));
  return out;
}

/// CPU time of this thread, ms (the machine may be shared: wall time would
/// count other processes' time slices).
double cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

struct Variant {
  std::string name;
  PeMatchParams params;
};

}  // namespace

int main(int argc, char** argv) {
  int seeds = 3;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seeds" && i + 1 < argc) seeds = std::atoi(argv[++i]);
    else files.push_back(a);
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: pematch_tracking_eval [--seeds S] motion_matches.csv [...]\n");
    return 2;
  }

  std::vector<Variant> variants;
  const PeMatchParams slam = PeMatchParams::for_slam();
  variants.push_back({"paper SLAM (j50, stall 6, eq.8 3px)", slam});
  for (double thr : {2.0, 4.0, 5.0, 6.0}) {
    PeMatchParams p = slam;
    p.inlier_threshold_px = thr;
    variants.push_back({"eq.8 " + std::to_string(thr).substr(0, 3) + "px", p});
  }
  {
    PeMatchParams p = slam;
    p.refine = true;
    variants.push_back({"refine (IRLS Sampson) 3px", p});
  }
  for (double thr : {2.0, 3.0, 4.0}) {
    PeMatchParams p = slam;
    p.distance = pvb::slam::EpipolarDistance::kSampson;
    p.inlier_threshold_px = thr;
    variants.push_back({"Sampson " + std::to_string(thr).substr(0, 3) + "px", p});
  }
  for (double thr : {2.0, 3.0}) {
    PeMatchParams p = slam;
    p.distance = pvb::slam::EpipolarDistance::kSampson;
    p.inlier_threshold_px = thr;
    p.refine = true;
    variants.push_back({"Sampson " + std::to_string(thr).substr(0, 3) + "px + refine", p});
  }
  {
    PeMatchParams p = PeMatchParams::for_pairs();
    variants.push_back({"pair values (j100, stall 8) 3px", p});
  }

  std::vector<CoarseFrame> frames;
  for (const auto& f : files) {
    auto v = read_csv(f);
    frames.insert(frames.end(), std::make_move_iterator(v.begin()), std::make_move_iterator(v.end()));
  }
  long correct = 0, wrong = 0, unknown = 0;
  for (const auto& f : frames)
    for (int l : f.label) (l == 1 ? correct : l == 0 ? wrong : unknown) += 1;
  std::printf("%zu frames, %ld coarse matches: %ld correct, %ld wrong (%.2f %%), %ld unknown; %d seeds\n",
              frames.size(), correct + wrong + unknown, correct, wrong, 100.0 * wrong / std::max(1L, correct + wrong),
              unknown, seeds);
  std::printf("%-38s %9s %9s %12s %12s %8s %8s\n", "variant", "precision", "recall", "wrong_removed",
              "good_removed", "no_model", "cpu_ms/call");

  for (const Variant& v : variants) {
    long kept_correct = 0, kept_wrong = 0, no_model = 0, calls = 0;
    double ms = 0;
    pvb::slam::PeMatcher matcher(v.params);
    pvb::slam::PeMatchResult r;
    for (int s = 1; s <= seeds; ++s) {
      matcher.params().seed = static_cast<std::uint32_t>(s);
      for (const auto& f : frames) {
        const double t0 = cpu_ms();
        matcher.match(f.pairs.data(), f.pairs.size(), r);
        ms += cpu_ms() - t0;
        ++calls;
        for (std::size_t k = 0; k < f.pairs.size(); ++k) {
          const bool keep = !r.F || r.inlier_mask[k];  // no model: tracking keeps every match
          if (!keep) continue;
          if (f.label[k] == 1) ++kept_correct;
          else if (f.label[k] == 0) ++kept_wrong;
        }
        no_model += r.F ? 0 : 1;
      }
    }
    const double tot_correct = static_cast<double>(correct) * seeds, tot_wrong = static_cast<double>(wrong) * seeds;
    std::printf("%-38s %9.4f %9.4f %11.1f%% %11.2f%% %8ld %8.3f\n", v.name.c_str(),
                static_cast<double>(kept_correct) / std::max(1L, kept_correct + kept_wrong),
                kept_correct / std::max(1.0, tot_correct), 100.0 * (1.0 - kept_wrong / std::max(1.0, tot_wrong)),
                100.0 * (1.0 - kept_correct / std::max(1.0, tot_correct)), no_model, ms / std::max(1L, calls));
  }
  // Baseline reference: keep everything.
  std::printf("%-38s %9.4f %9.4f %11.1f%% %11.2f%%\n", "no filter (baseline)",
              static_cast<double>(correct) / std::max(1L, correct + wrong), 1.0, 0.0, 0.0);
  return 0;
}
