#include "pvb/eval/associate.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <tuple>
#include <utility>

#include "pvb/geometry/time.hpp"

namespace pvb::eval {

namespace {

/// max_diff and offset in ns; EvalError when they are out of range.
std::pair<std::int64_t, std::int64_t> checked_window_ns(const AssociationOptions& options) {
  char text[160];
  if (!(options.max_diff_s > 0.0 && options.max_diff_s <= kMaxAssociationDiffS)) {
    std::snprintf(text, sizeof text, "association: max-diff %g s is not in (0, %g] s", options.max_diff_s,
                  kMaxAssociationDiffS);
    throw EvalError(text);
  }
  const std::optional<std::int64_t> offset_ns = geom::checked_seconds_to_ns(options.offset_s);
  if (!offset_ns) {
    std::snprintf(text, sizeof text, "association: offset %g s is not in [-%g, %g] s", options.offset_s,
                  geom::kMaxAbsTimeS, geom::kMaxAbsTimeS);
    throw EvalError(text);
  }
  return {geom::seconds_to_ns(options.max_diff_s), *offset_ns};
}

}  // namespace

std::vector<IndexPair> associate(const Trajectory& gt, const Trajectory& est,
                                 const AssociationOptions& options) {
  // An estimate whose time plus offset leaves int64 has no partner; the
  // window ends saturate, and |t_gt - t| < max_diff <= 1e9 s: no overflow.
  const auto [max_diff_ns, offset_ns] = checked_window_ns(options);
  struct Candidate {
    std::int64_t diff_ns;
    std::size_t gt, est;
  };
  std::vector<Candidate> candidates;
  // Both trajectories are sorted, so the ground-truth window of each estimate
  // only moves forward.
  std::size_t lo = 0;
  for (std::size_t e = 0; e < est.size(); ++e) {
    const std::optional<std::int64_t> t_checked = geom::checked_add_ns(est.poses[e].t_ns, offset_ns);
    if (!t_checked) continue;
    const std::int64_t t = *t_checked;
    const std::int64_t t_lo = geom::saturating_add_ns(t, -max_diff_ns),
                       t_hi = geom::saturating_add_ns(t, max_diff_ns);
    while (lo < gt.size() && gt.poses[lo].t_ns <= t_lo) ++lo;
    for (std::size_t g = lo; g < gt.size() && gt.poses[g].t_ns < t_hi; ++g) {
      const std::int64_t d = gt.poses[g].t_ns - t;
      candidates.push_back({d < 0 ? -d : d, g, e});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::tie(a.diff_ns, a.gt, a.est) < std::tie(b.diff_ns, b.gt, b.est);
  });
  std::vector<char> gt_used(gt.size(), 0), est_used(est.size(), 0);
  std::vector<IndexPair> out;
  for (const Candidate& c : candidates) {
    if (gt_used[c.gt] || est_used[c.est]) continue;
    gt_used[c.gt] = est_used[c.est] = 1;
    out.push_back({c.gt, c.est});
  }
  std::sort(out.begin(), out.end(), [](const IndexPair& a, const IndexPair& b) { return a.gt < b.gt; });
  return out;
}

std::vector<IndexPair> associate_or_throw(const Trajectory& gt, const Trajectory& est,
                                          const AssociationOptions& options) {
  if (gt.empty()) throw EvalError("ground truth " + gt.source + " holds no poses");
  if (est.empty()) throw EvalError("estimate " + est.source + " holds no poses");
  std::vector<IndexPair> pairs = associate(gt, est, options);
  if (!pairs.empty()) return pairs;
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "no poses associate within max-diff %.4g s at offset %.4g s: ground truth '%s' spans "
                "[%s, %s] s (%zu poses), estimate '%s' spans [%s, %s] s (%zu poses); if the clocks "
                "differ, pass --offset S (added to estimate times), or widen --max-diff S",
                options.max_diff_s, options.offset_s, gt.source.c_str(),
                geom::format_tum_time(gt.t_begin_ns()).c_str(), geom::format_tum_time(gt.t_end_ns()).c_str(),
                gt.size(), est.source.c_str(), geom::format_tum_time(est.t_begin_ns()).c_str(),
                geom::format_tum_time(est.t_end_ns()).c_str(), est.size());
  throw EvalError(buf);
}

}  // namespace pvb::eval
