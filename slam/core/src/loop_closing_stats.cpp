#include <algorithm>
#include <cmath>

#include "pvb/common/text.hpp"
#include "pvb/slam/core/loop_closing.hpp"

namespace pvb::slam {

void DurationHistogram::add(double ms) {
  const double octaves = ms > kLowestMs ? std::log2(ms / kLowestMs) : 0.0;  // NaN falls in the first bin
  const int bin = std::clamp(static_cast<int>(octaves * kBinsPerOctave), 0, kBins - 1);
  ++counts_[static_cast<std::size_t>(bin)];
  ++count_;
  total_ms_ += std::isfinite(ms) ? ms : 0.0;
}

double DurationHistogram::quantile(double q) const {
  if (count_ == 0) return 0;
  // Nearest rank: the ceil(q n)-th smallest value (the first for q = 0).
  const auto rank =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(q * static_cast<double>(count_))));
  std::size_t seen = 0;
  int bin = 0;
  for (; bin < kBins - 1; ++bin)
    if ((seen += counts_[static_cast<std::size_t>(bin)]) >= rank) break;
  return kLowestMs * std::exp2((bin + 0.5) / kBinsPerOctave);
}

std::string to_json(const LoopClosingStats& stats) {
  const auto num = [](double v) { return json_number(v, 6); };
  std::string out = "{\"loops\": " + std::to_string(stats.loops.size()) + ", \"events\": [";
  for (std::size_t k = 0; k < stats.loops.size(); ++k) {
    const LoopEvent& e = stats.loops[k];
    out += std::string(k ? ", " : "") + "{\"keyframe\": " + std::to_string(e.keyframe_id) +
           ", \"frame\": " + std::to_string(e.frame_id) +
           ", \"loop_keyframe\": " + std::to_string(e.loop_keyframe_id) +
           ", \"loop_frame\": " + std::to_string(e.loop_frame_id) +
           ", \"inliers\": " + std::to_string(e.inliers) + ", \"correction_m\": " + num(e.correction_m) +
           ", \"correction_deg\": " + num(e.correction_deg) +
           ", \"fused_points\": " + std::to_string(e.fused_points) +
           ", \"graph_keyframes\": " + std::to_string(e.graph_keyframes) +
           ", \"graph_edges\": " + std::to_string(e.graph_edges) + ", \"detect_ms\": " + num(e.detect_ms) +
           ", \"correct_ms\": " + num(e.correct_ms) + ", \"correct_locked_ms\": " + num(e.correct_locked_ms) +
           ", \"global_ba_ms\": " + num(e.global_ba_ms) +
           ", \"global_ba_outliers\": " + std::to_string(e.global_ba_outliers) +
           ", \"merge\": " + (e.merge ? "true" : "false") + "}";
  }
  out += "], \"keyframes\": " + std::to_string(stats.keyframes) +
         ", \"candidates\": " + std::to_string(stats.candidates) +
         ", \"consistent\": " + std::to_string(stats.consistent) +
         ", \"rejected\": " + std::to_string(stats.rejected) +
         ", \"refused_drift\": " + std::to_string(stats.refused_drift) +
         ", \"refused_ambiguous\": " + std::to_string(stats.refused_ambiguous) +
         ", \"lookalike_checked\": " + std::to_string(stats.lookalike_checked) +
         ", \"merge_confirmed\": " + std::to_string(stats.merge_confirmed) +
         ", \"merge_unconfirmed\": " + std::to_string(stats.merge_unconfirmed) +
         ", \"merge_suggested\": " + std::to_string(stats.merge_suggested) +
         ", \"verified\": " + std::to_string(stats.verified) +
         ", \"refused_matches\": " + std::to_string(stats.refused_matches) +
         ", \"refused_ransac\": " + std::to_string(stats.refused_ransac) +
         ", \"refused_inliers\": " + std::to_string(stats.refused_inliers) +
         ", \"refused_correction\": " + std::to_string(stats.refused_correction) +
         ", \"refused_first_pose\": " + std::to_string(stats.refused_first_pose) + ", \"refusals\": " +
         std::to_string(stats.refusals.size() + static_cast<std::size_t>(stats.refusals_dropped)) +
         ", \"verify_ms_total\": " + num(stats.verify_ms_total) +
         ", \"detect_ms_median\": " + num(stats.detect_ms.quantile(0.5)) +
         ", \"detect_ms_p95\": " + num(stats.detect_ms.quantile(0.95)) +
         ", \"detect_ms_total\": " + num(stats.detect_ms_total) + "}";
  return out;
}

void LoopClosingStats::keep_refusal(LoopRefusal r, std::size_t cap) {
  if (refusals.size() >= cap) {
    const auto unverified =
        std::find_if(refusals.begin(), refusals.end(), [](const LoopRefusal& k) { return !k.verified; });
    ++refusals_dropped;
    if (!r.verified || unverified == refusals.end()) return;
    refusals.erase(unverified);
  }
  refusals.push_back(std::move(r));
}

}  // namespace pvb::slam
