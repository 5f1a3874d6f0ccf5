#pragma once
// One-to-one association of two trajectories by time stamp, exactly as the
// TUM RGB-D benchmark's associate.py does it.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pvb/eval/trajectory.hpp"

namespace pvb::eval {

/// Largest max_diff_s associate() accepts, seconds.
constexpr double kMaxAssociationDiffS = 1e9;

struct AssociationOptions {
  double max_diff_s = 0.02;  ///< a pair must satisfy |t_gt - (t_est + offset)| < max_diff
  double offset_s = 0.0;     ///< added to every estimate time stamp
};

/// Indices of one associated pose pair.
struct IndexPair {
  std::size_t gt = 0;   ///< index into the ground-truth trajectory
  std::size_t est = 0;  ///< index into the estimated trajectory
};

/// Associates poses one-to-one: every pair with |t_gt - (t_est + offset)| <
/// max_diff is a candidate; candidates are taken closest first (ties by
/// ground-truth time, then estimate time), each stamp at most once.  The
/// result is sorted by time.  Returns an empty vector when nothing associates.
/// Throws EvalError when max_diff_s is not in (0, kMaxAssociationDiffS] or
/// |offset_s| > geom::kMaxAbsTimeS.
std::vector<IndexPair> associate(const Trajectory& gt, const Trajectory& est,
                                 const AssociationOptions& options = {});

/// As associate(), but throws EvalError when nothing associates; the message
/// gives both time ranges and suggests --offset or --max-diff.
std::vector<IndexPair> associate_or_throw(const Trajectory& gt, const Trajectory& est,
                                          const AssociationOptions& options = {});

}  // namespace pvb::eval
