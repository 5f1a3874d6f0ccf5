// Global relocalisation (Tracking's members): candidates from place
// recognition or the recent keyframes, each matched, PnP RANSAC and pose
// optimisation, then the ambiguity and look-alike checks; the probes for a
// provisional map's merge.  The rest of Tracking is in tracking.cpp.
#include <algorithm>
#include <set>

#include "pvb/common/text.hpp"
#include "pvb/slam/core/frame_pose.hpp"
#include "pvb/slam/core/tracking.hpp"

namespace pvb::slam {

const char* to_string(TrackingStats::RelocFailure f) {
  using F = TrackingStats::RelocFailure;
  switch (f) {
    case F::kNone: return "none";
    case F::kNoCandidates: return "no candidates";
    case F::kFewMatches: return "too few descriptor matches";
    case F::kPnp: return "no PnP pose";
    case F::kFewInliers: return "too few pose inliers";
    case F::kAmbiguous: return "ambiguous";
    case F::kLookalike: return "look-alike place";
    case F::kOdometry: return "outside the wheels' bound";
    case F::kLocalMap: return "local map after relocalisation";
  }
  return "?";
}

namespace {

/// Why no relocalisation candidate matched, at the furthest step any got to.
std::string no_match_reason(std::size_t candidates, bool with_place, int best_matches, int with_matches,
                            int best_pnp, int with_pnp, int best_inliers, int min_inliers,
                            TrackingStats::RelocFailure* kind) {
  using F = TrackingStats::RelocFailure;
  const std::string n = std::to_string(candidates);
  if (candidates == 0) {
    *kind = F::kNoCandidates;
    return with_place ? "relocalisation: 0 candidates from place recognition"
                      : "relocalisation: no keyframe to try";
  }
  std::string why = "relocalisation: " + n + (candidates == 1 ? " candidate, " : " candidates, ");
  if (with_matches == 0) {
    *kind = F::kFewMatches;
    return why + "best " + std::to_string(best_matches) + " descriptor matches (need 15)";
  }
  why += std::to_string(with_matches) + " with 15+ descriptor matches (best " + std::to_string(best_matches) + "), ";
  if (with_pnp == 0) {
    *kind = F::kPnp;
    return why + "no PnP RANSAC pose (best " + std::to_string(best_pnp) + " inliers, need 10)";
  }
  *kind = F::kFewInliers;
  return why + std::to_string(with_pnp) + " with a PnP pose, best " + std::to_string(best_inliers) +
         " pose inliers (need " + std::to_string(min_inliers) + ")";
}

}  // namespace

void Tracking::record_relocalisation(const Frame& f) {
  RelocEvent e;
  e.frame_id = f.id;
  e.t_ns = f.t_ns;
  e.keyframe_id = reloc_kf_->id();
  e.keyframe_frame_id = reloc_kf_->frame_id();
  e.keyframe_t_ns = reloc_kf_->t_ns();
  e.candidates = reloc_candidates_;
  e.inliers = stats_.inliers;
  e.T_f_kf = f.T_c_w * reloc_kf_->T_c_w().inverse();
  relocs_.push_back(e);
}

std::vector<std::shared_ptr<KeyFrame>> Tracking::recent_keyframes() const {
  // The most recent keyframes and the covisibility neighbours of the last
  // reference keyframe (without a vocabulary).
  std::vector<std::shared_ptr<KeyFrame>> cands;
  std::set<std::uint64_t> seen;
  const auto& kfs = map_.keyframes();
  int k = 0;
  for (auto it = kfs.rbegin(); it != kfs.rend() && k < 10; ++it, ++k) {
    cands.push_back(it->second);
    seen.insert(it->first);
  }
  if (ref_kf_ && !ref_kf_->bad())
    for (const auto& c : ref_kf_->best_covisibles(10))
      if (seen.insert(c->id()).second) cands.push_back(c);
  return cands;
}

int Tracking::relocalize_against(Frame& f, const KeyFrame& kf, const place::FeatureVector* f_features,
                                 int* matches, int* pnp) {
  std::fill(f.map_points.begin(), f.map_points.end(), nullptr);
  *matches = f_features ? search_keyframe_by_bow(kf, f, *f_features, kThLow, 0.75)
                        : search_keyframe_bruteforce(kf, f, kThLow, 0.75);
  if (*matches < 15) return 0;
  const int pnp_inliers = pnp_ransac_on_matches(f, 10);
  if (pnp) *pnp = pnp_inliers;
  if (pnp_inliers < 10) return 0;
  int good = optimize_frame_pose(f);
  if (good < 10) return 0;
  int map_matches = 0;
  discard_outliers(f, &map_matches);
  if (good < 50) {
    // more matches by projection of the candidate's points with a wide window
    std::vector<ProjectedPoint> proj;
    for (const auto& mp : kf.map_points()) {
      if (!mp || mp->bad()) continue;
      if (std::find(f.map_points.begin(), f.map_points.end(), mp) != f.map_points.end()) continue;
      ProjectedPoint p;
      if (project_in_frustum(f, mp, &p)) proj.push_back(p);
    }
    search_local_points(f, proj, 10.0 / 4.0);
    good = optimize_frame_pose(f);
    discard_outliers(f, &map_matches);
  }
  return good;
}

bool Tracking::relocalize(Frame& f) {
  std::shared_ptr<KeyFrame> kf;
  int candidates = 0;
  if (std::string why = relocalise_in(f, std::nullopt, &kf, &candidates, &stats_.reloc_failure); !why.empty())
    return fail(why);
  last_reloc_frame_id_ = f.id;
  reloc_kf_ = std::move(kf);
  reloc_candidates_ = candidates;
  return true;
}

std::string Tracking::relocalise_in(Frame& f, std::optional<std::uint32_t> only_map, std::shared_ptr<KeyFrame>* kf_out,
                                    int* candidates, TrackingStats::RelocFailure* kind) {
  using F = TrackingStats::RelocFailure;
  F no_kind = F::kNone;
  if (!kind) kind = &no_kind;
  // Candidates from the bag of words anywhere in the map (ORB-SLAM2
  // DetectRelocalizationCandidates), or the recent keyframes without one.
  place::FeatureVector f_features;
  place::BowVector bow;
  std::vector<std::shared_ptr<KeyFrame>> cands;
  if (place_) {
    place_->transform(f, &bow, &f_features);
    cands = place_->relocalisation_candidates(map_, bow);
    if (only_map)
      cands.erase(std::remove_if(cands.begin(), cands.end(), [&](const auto& k) { return map_.map_of(*k) != *only_map; }),
                  cands.end());
    if (cands.size() > kMaxRelocCandidates) cands.resize(kMaxRelocCandidates);
  } else {
    cands = recent_keyframes();
  }
  // over the candidates, for the failure reason
  int best_matches = 0, with_matches = 0, best_pnp = 0, with_pnp = 0, best_inliers = 0;
  std::vector<std::pair<Frame, std::shared_ptr<KeyFrame>>> found;
  std::vector<int> found_inliers;
  // In this map's frame while lost in it, the wheels bound where f can be:
  // a match beyond is no candidate (nor a rival for the ambiguity check).
  const bool odometry_bound = !only_map.has_value();
  std::string refused;
  for (const auto& kf : cands) {
    if (kf->bad()) continue;
    Frame trial = f;
    int matches = 0, pnp = 0;
    const int good = relocalize_against(trial, *kf, place_ ? &f_features : nullptr, &matches, &pnp);
    best_matches = std::max(best_matches, matches);
    with_matches += matches >= 15;
    best_pnp = std::max(best_pnp, pnp);
    with_pnp += pnp >= 10;
    best_inliers = std::max(best_inliers, good);
    if (good < kRelocMinInliers) continue;
    if (std::string why = odometry_bound ? odometry_refuses(f, trial) : std::string(); !why.empty()) {
      if (refused.empty()) refused = why + " (keyframe " + std::to_string(kf->id()) + ")";
      continue;
    }
    found.emplace_back(std::move(trial), kf);
    found_inliers.push_back(good);
    if (!options_.reloc_ambiguity_check) break;
  }
  std::fill(f.map_points.begin(), f.map_points.end(), nullptr);
  if (found.empty() && !refused.empty()) {
    *kind = F::kOdometry;
    return refused;
  }
  if (found.empty())
    return no_match_reason(cands.size(), place_ != nullptr, best_matches, with_matches, best_pnp, with_pnp,
                           best_inliers, kRelocMinInliers, kind);
  *kind = F::kAmbiguous;
  for (std::size_t i = 0; i < found.size(); ++i)
    for (std::size_t j = i + 1; j < found.size(); ++j)
      if ((found[i].first.camera_center_w() - found[j].first.camera_center_w()).norm() >
          options_.reloc_ambiguity_distance_m)
        return "relocalisation: ambiguous (keyframes " + std::to_string(found[i].second->id()) + " and " +
               std::to_string(found[j].second->id()) + " both matched, at places " +
               format_fixed((found[i].first.camera_center_w() - found[j].first.camera_center_w()).norm(), 2) +
               " m apart)";
  const std::size_t best = static_cast<std::size_t>(
      std::max_element(found_inliers.begin(), found_inliers.end()) - found_inliers.begin());
  if (place_ && options_.reloc_ambiguity_check && options_.reloc_lookalikes > 0) {
    *kind = F::kLookalike;
    std::string why = lookalike(f, found[best].first, bow, f_features, cands, only_map);
    if (!why.empty()) return why;
  }
  *kind = F::kNone;
  f = std::move(found[best].first);
  *kf_out = found[best].second;
  *candidates = static_cast<int>(cands.size());
  return {};
}

void Tracking::probe_merge(const Frame& f) {
  if (!place_ || options_.merge_reloc_every <= 0 || !ref_kf_) return;
  const std::uint32_t from = map_.map_of(*ref_kf_);
  if (from == 0 || ++since_merge_probe_ < options_.merge_reloc_every) return;
  since_merge_probe_ = 0;
  Frame probe = f;
  std::shared_ptr<KeyFrame> kf;
  int candidates = 0;
  if (!relocalise_in(probe, 0u, &kf, &candidates).empty()) return;
  merge_hint_ = MergeHint{from, probe.T_c_w.inverse() * f.T_c_w, std::move(kf)};
}

std::string Tracking::lookalike(const Frame& f, const Frame& found, const place::BowVector& bow,
                                const place::FeatureVector& f_features,
                                const std::vector<std::shared_ptr<KeyFrame>>& tried,
                                std::optional<std::uint32_t> only_map) {
  // The grouped candidates can all lie at one of two look-alike places (a
  // ground texture repeating along the route): the best-scoring keyframes
  // one by one are tried too, and one matching elsewhere makes it ambiguous.
  // A best-scoring keyframe at another place that does not match is tried
  // through its best covisibles: its neighbours may see the view's part of
  // that place better (a frame between two keyframes of it).
  std::set<std::uint64_t> seen;
  for (const auto& kf : tried) seen.insert(kf->id());
  const double far_m = options_.reloc_ambiguity_distance_m;
  const auto matches_elsewhere = [&](const KeyFrame& kf) -> std::string {
    Frame trial = f;
    int matches = 0;
    if (relocalize_against(trial, kf, &f_features, &matches) < kRelocMinInliers) return {};
    const double apart_m = (trial.camera_center_w() - found.camera_center_w()).norm();
    if (apart_m <= far_m) return {};
    if (!only_map && !odometry_refuses(f, trial).empty()) return {};  // where the wheels say f cannot be
    return "relocalisation: ambiguous (look-alike keyframe " + std::to_string(kf.id()) + " matched at a place " +
           format_fixed(apart_m, 2) + " m from the candidates')";
  };
  const auto other_map = [&](const KeyFrame& kf) { return only_map && map_.map_of(kf) != *only_map; };
  for (const auto& kf : place_->lookalike_candidates(map_, bow, static_cast<std::size_t>(options_.reloc_lookalikes))) {
    if (other_map(*kf) || !seen.insert(kf->id()).second) continue;
    if (std::string why = matches_elsewhere(*kf); !why.empty()) return why;
    if ((kf->camera_center_w() - found.camera_center_w()).norm() <= far_m) continue;
    for (const auto& n : kf->best_covisibles(kLookalikeNeighbours)) {
      if (n->bad() || other_map(*n) || !seen.insert(n->id()).second) continue;
      if (std::string why = matches_elsewhere(*n); !why.empty()) return why;
    }
  }
  return {};
}

}  // namespace pvb::slam
