#include "pvb/slam/core/loop_closing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>

#include "loop_correction.hpp"
#include "loop_verification.hpp"
#include "pvb/common/clock.hpp"
#include "pvb/geometry/angles.hpp"
#include "pvb/slam/core/local_mapping.hpp"
#include "pvb/slam/core/matcher.hpp"
#include "pvb/slam/optim/optimizer.hpp"

namespace pvb::slam {
namespace {

using detail::pose_difference;
/// Best-scoring keyframes of the map, one by one, that a merge or a large
/// loop correction is also verified against (as a relocalisation is,
/// Tracking.relocLookalikes).
constexpr std::size_t kLookalikes = 10;

/// The grouped candidates of a merge can all lie at one of two look-alike
/// places (a ground texture repeating along the route), and no later check
/// tells them apart; a loop that corrects the keyframe by metres may have
/// found the next row instead of its own.  The map's best-scoring keyframes
/// one by one (those of map `map_id` that `skip` leaves) are verified too,
/// and each that verifies is added to `places` for the ambiguity check.
void add_lookalikes(const PlaceRecognizer& place, const Map& map, const LoopClosingOptions& options,
                    const KeyFrame& kf, const std::vector<std::shared_ptr<KeyFrame>>& tried,
                    std::uint32_t map_id, const std::function<bool(std::uint64_t)>& skip,
                    std::vector<VerifiedPlace>* places) {
  for (const auto& c : place.lookalike_candidates(map, place.bag_of(kf), kLookalikes, skip)) {
    if (map.map_of(*c) != map_id || std::find(tried.begin(), tried.end(), c) != tried.end()) continue;
    const LoopMatch m = verify_loop(kf, c, options);
    if (m.accepted) places->push_back({m.T_c_w.inverse().translation(), m.inliers, true});
  }
}

}  // namespace

LoopClosing::LoopClosing(Map& map, const LoopClosingOptions& options, PlaceRecognizer* place)
    : map_(map), options_(options), place_(place) {}

LoopClosingStats LoopClosing::stats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return stats_;
}

LoopDetectTotals LoopClosing::detect_totals() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return {stats_.detect_ms.count(), stats_.detect_ms_total};
}

std::vector<std::shared_ptr<KeyFrame>> LoopClosing::propose(const std::shared_ptr<KeyFrame>& kf) {
  std::vector<std::shared_ptr<KeyFrame>> candidates;
  if (place_ && !options_.pose_proximity) {
    // Within the keyframe's own map, or from a provisional map into the map's own frame (a merge).
    const std::uint32_t own = map_.map_of(*kf);
    for (const auto& c : place_->loop_candidates(map_, *kf, options_.min_keyframe_gap))
      if (const std::uint32_t m = map_.map_of(*c); m == own || m == 0) candidates.push_back(c);
    if (static_cast<int>(candidates.size()) > options_.max_candidates) candidates.resize(options_.max_candidates);
    return candidates;
  }
  for (const auto& cand : pose_candidates(map_, *kf, options_)) {
    Frame probe = kf->frame();
    std::fill(probe.map_points.begin(), probe.map_points.end(), nullptr);
    if (search_keyframe_bruteforce(*cand, probe, kThLow, 0.75) >= options_.min_matches) candidates.push_back(cand);
  }
  return candidates;
}

std::vector<std::shared_ptr<KeyFrame>> LoopClosing::detect(const std::shared_ptr<KeyFrame>& kf) {
  const std::vector<std::shared_ptr<KeyFrame>> candidates = propose(kf);
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    stats_.candidates += static_cast<int>(candidates.size());
  }
  if (candidates.empty()) {
    groups_.clear();
    return {};
  }
  // ORB-SLAM2 DetectLoop: a candidate group is consistent with a previous
  // group when they share a keyframe; its count grows by one per keyframe.
  std::vector<Group> next;
  std::vector<bool> extended(groups_.size(), false);
  std::vector<std::shared_ptr<KeyFrame>> enough;
  for (const auto& cand : candidates) {
    Group g;
    g.ids.insert(cand->id());
    for (const auto& n : cand->best_covisibles(-1)) g.ids.insert(n->id());
    bool consistent_any = false, added = false;
    for (std::size_t i = 0; i < groups_.size(); ++i) {
      const bool shares = std::any_of(g.ids.begin(), g.ids.end(), [&](std::uint64_t id) { return groups_[i].ids.count(id) > 0; });
      if (!shares) continue;
      consistent_any = true;
      const int consistency = groups_[i].consistency + 1;
      if (!extended[i]) {
        next.push_back({g.ids, consistency});
        extended[i] = true;
      }
      if (consistency >= options_.consistency && !added) {
        enough.push_back(cand);
        added = true;
      }
    }
    if (!consistent_any) next.push_back({g.ids, 0});
  }
  groups_ = std::move(next);
  return enough;
}

double LoopClosing::path_length_m(std::uint64_t from, std::uint64_t to) const {
  double length = 0;
  const KeyFrame* prev = nullptr;
  for (auto it = map_.keyframes().lower_bound(from); it != map_.keyframes().end() && it->first <= to; ++it) {
    if (it->second->bad()) continue;
    if (prev) length += (it->second->camera_center_w() - prev->camera_center_w()).norm();
    prev = it->second.get();
  }
  return length;
}

double LoopClosing::max_correction_deg(double path_m) const {
  return options_.max_correction_deg + options_.max_correction_deg_per_km * path_m / 1000.0;
}

double LoopClosing::drift_bound_m(const KeyFrame& kf, double path_m, double angle_deg) const {
  // Drift along the path, plus the swing of a rotation drift: a small
  // rotation and a sideways move look alike in the image, so tracking that
  // drifts in rotation turns the camera about the scene it holds, and the
  // correction moves the camera centre by 2 sin(angle / 2) x the scene depth.
  const double swing_m = 2.0 * std::sin(angle_deg / geom::kRadToDeg / 2.0) * detail::scene_median_depth_m(kf);
  return options_.drift_floor_m + options_.max_drift_rate * path_m + swing_m;
}

namespace {

/// What refused `cand` for `kf`; a verified candidate carries its pose.
LoopRefusal refusal_of(const KeyFrame& kf, const KeyFrame& cand, const char* reason, const LoopMatch& m,
                       bool verified, double dist_m = 0, double angle_deg = 0, double bound_m = 0) {
  LoopRefusal r;
  r.keyframe_id = kf.id();
  r.loop_keyframe_id = cand.id();
  r.t_ns = kf.t_ns();
  r.loop_t_ns = cand.t_ns();
  r.reason = reason;
  r.verified = verified;
  if (verified) r.T_cur_loop = m.T_c_w * cand.T_c_w().inverse();
  r.inliers = m.inliers;
  r.correction_m = dist_m;
  r.correction_deg = angle_deg;
  r.drift_bound_m = bound_m;
  return r;
}

}  // namespace

struct LoopClosing::VerifyState {
  VerifyTally tally;
  std::vector<VerifiedPlace> places;
  std::shared_ptr<KeyFrame> loop_kf;
  LoopMatch* best = nullptr;
  double best_dist_m = 0, best_angle_deg = 0;
  /// Keeps the refusal of the candidate that got furthest (rank: the
  /// geometry's stage, then the caps, then the drift bound).
  void refuse(int rank, LoopRefusal r) {
    if (rank <= tally.refusal_rank) return;
    tally.refusal_rank = rank;
    tally.refusal = std::move(r);
  }
};

bool LoopClosing::far_beyond_bounds(const KeyFrame& kf, const LoopMatch& first, double path_m) const {
  double dist_m = 0, angle_deg = 0;
  pose_difference(first.T_c_w, kf.T_c_w(), &dist_m, &angle_deg);
  const auto far = [](double value_m, double bound_m) { return value_m > 1.5 * bound_m + 0.5; };
  if (far(dist_m, options_.max_correction_m)) return true;
  return options_.max_drift_rate > 0 && far(dist_m, drift_bound_m(kf, path_m, angle_deg));
}

bool LoopClosing::judge(const KeyFrame& kf, const std::shared_ptr<KeyFrame>& cand, LoopMatch m, double path_m,
                        bool merge, bool first_pose, VerifyState* st) const {
  static constexpr const char* kStageNames[3] = {"matches", "ransac", "inliers"};
  VerifyTally& tally = st->tally;
  if (!m.accepted && !first_pose) {
    const auto stage = static_cast<std::size_t>(m.stage);
    ++tally.refused_at[stage];
    st->refuse(static_cast<int>(stage), refusal_of(kf, *cand, kStageNames[stage], m, false));
    return false;
  }
  if (first_pose) ++tally.refused_first_pose;
  double dist_m = 0, angle_deg = 0;
  pose_difference(m.T_c_w, kf.T_c_w(), &dist_m, &angle_deg);
  if (!merge && (dist_m > options_.max_correction_m || angle_deg > max_correction_deg(path_m))) {
    ++tally.refused_correction;
    st->refuse(3, refusal_of(kf, *cand, "correction", m, true, dist_m, angle_deg));
    return false;
  }
  if (!first_pose) st->places.push_back({m.T_c_w.inverse().translation(), m.inliers, false});
  const double bound_m = drift_bound_m(kf, path_m, angle_deg);
  if (!merge && options_.max_drift_rate > 0 && dist_m > bound_m) {
    ++tally.drift;
    st->refuse(4, refusal_of(kf, *cand, "drift", m, true, dist_m, angle_deg, bound_m));
    return false;
  }
  if (first_pose) return false;  // far beyond a bound: not reached
  if (!st->loop_kf || m.inliers > st->best->inliers) {
    *st->best = std::move(m);
    st->loop_kf = cand;
    st->best_dist_m = dist_m;
    st->best_angle_deg = angle_deg;
  }
  return !options_.ambiguity_check;  // ORB-SLAM2: the first verified candidate
}

std::shared_ptr<KeyFrame> LoopClosing::verify(const std::shared_ptr<KeyFrame>& kf,
                                              const std::vector<std::shared_ptr<KeyFrame>>& consistent,
                                              bool merge, LoopMatch* best) {
  const auto t0 = std::chrono::steady_clock::now();
  VerifyState st;
  st.best = best;
  // Candidates whose first pose lies far beyond a bound: on a plant most
  // verified candidates are rows away, and the guided search is most of a
  // verification.  They are rival places only beside a loop in reach.
  struct Waiting {
    std::shared_ptr<KeyFrame> cand;
    Frame probe;
    LoopMatch m;
    double path_m;
  };
  std::vector<Waiting> waiting;
  for (const auto& cand : consistent) {
    ++st.tally.verified;
    Frame probe = loop_probe(*kf);
    LoopMatch m;
    double path_m = 0;  // both bounds grow with it
    if (verify_by_descriptors(*kf, *cand, options_, &probe, &m)) {
      path_m = path_length_m(cand->id(), kf->id());
      if (!merge && far_beyond_bounds(*kf, m, path_m)) {
        waiting.push_back({cand, std::move(probe), std::move(m), path_m});
        continue;
      }
      verify_by_projection(cand, options_, &probe, &m);
    }
    if (judge(*kf, cand, std::move(m), path_m, merge, false, &st)) break;
  }
  const bool finish = st.loop_kf && options_.ambiguity_check;
  for (auto& w : waiting) {
    if (finish) verify_by_projection(w.cand, options_, &w.probe, &w.m);
    judge(*kf, w.cand, std::move(w.m), w.path_m, merge, !finish, &st);
  }
  VerifyTally& tally = st.tally;
  tally.lookalike_checked = !merge && st.loop_kf && st.best_dist_m > options_.lookalike_check_above_m;
  if (st.loop_kf && (merge || tally.lookalike_checked) && options_.ambiguity_check && place_)
    add_lookalikes(*place_, map_, options_, *kf, consistent, merge ? 0 : map_.map_of(*kf),
                   merge ? std::function<bool(std::uint64_t)>{}
                         : own_neighbourhood(*kf, kf->best_covisibles(-1), options_.min_keyframe_gap),
                   &st.places);
  tally.ambiguous = options_.ambiguity_check &&
                    places_apart(st.places, options_.ambiguity_distance_m, options_.ambiguity_inlier_share);
  if (tally.ambiguous && st.loop_kf)
    tally.refusal = refusal_of(*kf, *st.loop_kf, "ambiguous", *best, true, st.best_dist_m, st.best_angle_deg);
  else if (tally.ambiguous)  // every verified candidate was over the drift bound, and they lie apart
    tally.refusal.reason = "ambiguous";
  tally.verify_ms = ms_since(t0);
  add_tally(tally, st.loop_kf != nullptr);
  return tally.ambiguous ? nullptr : st.loop_kf;
}

void LoopClosing::add_tally(const VerifyTally& t, bool found) {
  std::lock_guard<std::mutex> s(stats_mutex_);
  stats_.verified += t.verified;
  stats_.refused_matches += t.refused_at[0];
  stats_.refused_ransac += t.refused_at[1];
  stats_.refused_inliers += t.refused_at[2];
  stats_.refused_correction += t.refused_correction;
  stats_.refused_first_pose += t.refused_first_pose;
  stats_.lookalike_checked += t.lookalike_checked ? 1 : 0;
  stats_.verify_ms_total += t.verify_ms;
  if (t.ambiguous) ++stats_.refused_ambiguous;
  else if (!found && t.drift > 0) ++stats_.refused_drift;  // each refused detection counts under one check
  if (!t.ambiguous && (found || t.refusal_rank < 0)) return;
  stats_.keep_refusal(t.refusal);
}

std::shared_ptr<KeyFrame> LoopClosing::find(const std::shared_ptr<KeyFrame>& kf, LoopMatch* best, bool* merge,
                                            std::chrono::steady_clock::time_point t0) {
  std::vector<std::shared_ptr<KeyFrame>> consistent = detect(kf);
  // A provisional map that meets the map's own keyframes merges into them
  // (before any loop within itself).
  *merge = map_.map_of(*kf) != 0 && std::any_of(consistent.begin(), consistent.end(), [&](const auto& c) {
             return map_.map_of(*c) == 0;
           });
  if (*merge)
    consistent.erase(std::remove_if(consistent.begin(), consistent.end(),
                                    [&](const auto& c) { return map_.map_of(*c) != 0; }),
                     consistent.end());
  const std::shared_ptr<KeyFrame> loop_kf = consistent.empty() ? nullptr : verify(kf, consistent, *merge, best);
  const double detect_ms = ms_since(t0);
  std::lock_guard<std::mutex> s(stats_mutex_);
  stats_.detect_ms_total += detect_ms;
  stats_.detect_ms.add(detect_ms);
  if (!consistent.empty()) ++stats_.consistent;
  if (!consistent.empty() && !loop_kf) ++stats_.rejected;
  return loop_kf;
}

bool LoopClosing::confirm_merge(const std::shared_ptr<KeyFrame>& kf, LoopMatch* best,
                                std::shared_ptr<KeyFrame>* loop_kf) {
  PendingMerge& p = *pending_merge_;
  LoopMatch m = verify_at(*kf, p.anchor, kf->T_c_w() * p.T_into_from.inverse(), options_);
  std::lock_guard<std::mutex> s(stats_mutex_);
  if (!m.accepted) {
    ++stats_.merge_unconfirmed;
    pending_merge_.reset();
    return false;
  }
  ++stats_.merge_confirmed;
  p.T_into_from = detail::frame_into(m.T_c_w, *kf);
  // The next prediction is checked around the map's keyframe that saw most of these matches.
  std::map<std::uint64_t, std::pair<std::shared_ptr<KeyFrame>, int>> votes;
  for (const auto& mp : m.points)
    if (mp && !mp->bad())
      for (const auto& [kid, o] : mp->observations())
        if (auto k = o.kf.lock(); k && !k->bad() && map_.map_of(*k) == 0) {
          votes[kid].first = k;
          ++votes[kid].second;
        }
  int most = 0;
  for (const auto& [kid, v] : votes)
    if (v.second > most) {
      most = v.second;
      p.anchor = v.first;
    }
  if (++p.confirmed < options_.merge_confirmations) return false;
  *best = std::move(m);
  *loop_kf = p.anchor;
  pending_merge_.reset();
  return true;
}

void LoopClosing::suggest_merge(std::uint32_t from, const geom::SE3d& T_into_from, std::shared_ptr<KeyFrame> anchor) {
  if (!options_.enabled || !anchor) return;
  std::lock_guard<std::mutex> lock(map_.mutex());
  if (pending_merge_ || from == 0 || anchor->bad() || map_.map_of(*anchor) != 0) return;
  pending_merge_ = PendingMerge{from, T_into_from, std::move(anchor), 1};
  groups_.clear();
  std::lock_guard<std::mutex> s(stats_mutex_);
  ++stats_.merge_suggested;
}

bool LoopClosing::process(const std::shared_ptr<KeyFrame>& kf) {
  if (!options_.enabled) return false;
  const auto t0 = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(map_.mutex());
  {
    std::lock_guard<std::mutex> s(stats_mutex_);
    ++stats_.keyframes;
  }
  if (kf->bad()) return false;
  LoopMatch best;
  std::shared_ptr<KeyFrame> loop_kf;
  bool merge = false;
  if (pending_merge_ && pending_merge_->from == map_.map_of(*kf)) {
    merge = true;
    if (!confirm_merge(kf, &best, &loop_kf)) return false;
  } else {
    if (any_loop_ && kf->id() < last_loop_kf_id_ + static_cast<std::uint64_t>(options_.keyframes_between_loops)) {
      groups_.clear();
      return false;
    }
    loop_kf = find(kf, &best, &merge, t0);
    if (!loop_kf) return false;
    if (merge && options_.merge_confirmations > 1) {  // held back until the next keyframes confirm it
      pending_merge_ = PendingMerge{map_.map_of(*kf), detail::frame_into(best.T_c_w, *kf), loop_kf, 1};
      groups_.clear();
      return false;
    }
  }
  close(kf, loop_kf, best, merge, ms_since(t0), lock);
  return true;
}

void LoopClosing::close(const std::shared_ptr<KeyFrame>& kf, const std::shared_ptr<KeyFrame>& loop_kf,
                        const LoopMatch& best, bool merge, double detect_ms, std::unique_lock<std::mutex>& lock) {
  LoopEvent event;
  event.keyframe_id = kf->id();
  event.frame_id = kf->frame_id();
  event.loop_keyframe_id = loop_kf->id();
  event.loop_frame_id = loop_kf->frame_id();
  event.t_ns = kf->t_ns();
  event.loop_t_ns = loop_kf->t_ns();
  event.T_cur_loop = best.T_c_w * loop_kf->T_c_w().inverse();
  event.inliers = best.inliers;
  pose_difference(best.T_c_w, kf->T_c_w(), &event.correction_m, &event.correction_deg);
  event.detect_ms = detect_ms;
  event.merge = merge;
  const auto t1 = std::chrono::steady_clock::now();
  if (merge) detail::merge_into(map_, kf, loop_kf, best.T_c_w);
  const double unlocked_ms = correct(kf, loop_kf, best, &event, lock);
  event.correct_ms = ms_since(t1);
  event.correct_locked_ms = event.correct_ms - unlocked_ms;
  if (options_.global_ba) {
    const auto t2 = std::chrono::steady_clock::now();
    global_bundle_adjustment(&event, map_.map_of(*loop_kf));
    event.global_ba_ms = ms_since(t2);
  }
  groups_.clear();
  any_loop_ = true;
  last_loop_kf_id_ = kf->id();
  std::lock_guard<std::mutex> s(stats_mutex_);
  stats_.loops.push_back(event);
}

}  // namespace pvb::slam
