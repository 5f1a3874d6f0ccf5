// The tracker's local map (ORB-SLAM2 UpdateLocalMap / TrackLocalMap): the
// keyframes around the frame's points, their points projected and matched,
// patch alignment of the matches, and the pose optimised on them.
#include <algorithm>
#include <chrono>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "pvb/slam/core/frame_pose.hpp"
#include "pvb/slam/core/patch_refine.hpp"
#include "pvb/slam/core/tracking.hpp"

namespace pvb::slam {

std::pair<int, std::uint64_t> least_shared_kept(std::vector<std::pair<int, std::uint64_t>> shared, int n) {
  if (n <= 0 || shared.size() <= static_cast<std::size_t>(n)) return {0, 0};
  const auto nth = shared.begin() + (n - 1);
  std::nth_element(shared.begin(), nth, shared.end(), std::greater<>());
  return *nth;
}

void Tracking::update_local_map(const Frame& f) {
  // Local keyframes: those observing the frame's points, their best
  // covisibles, children and parent (ORB-SLAM2 UpdateLocalKeyFrames).
  std::map<std::uint64_t, std::pair<std::shared_ptr<KeyFrame>, int>> counter;
  for (const auto& mp : f.map_points) {
    if (!mp || mp->bad()) continue;
    for (const auto& [kid, o] : mp->observations()) {
      auto kf = o.kf.lock();
      if (!kf || kf->bad()) continue;
      auto& c = counter[kid];
      c.first = kf;
      ++c.second;
    }
  }
  local_kfs_.clear();
  std::set<std::uint64_t> in_local;
  std::shared_ptr<KeyFrame> best;
  int best_n = 0;
  std::vector<std::pair<int, std::uint64_t>> shared;
  shared.reserve(counter.size());
  for (const auto& [kid, c] : counter) shared.emplace_back(c.second, kid);
  const std::pair<int, std::uint64_t> least_kept = least_shared_kept(std::move(shared), options_.max_observing_keyframes);
  for (const auto& [kid, c] : counter) {
    if (c.second > best_n) {
      best_n = c.second;
      best = c.first;
    }
    if (std::make_pair(c.second, kid) < least_kept) continue;
    local_kfs_.push_back(c.first);
    in_local.insert(kid);
  }
  const std::size_t direct = local_kfs_.size();
  const auto max_local = static_cast<std::size_t>(std::max(0, options_.max_local_keyframes));
  for (std::size_t k = 0; k < direct && local_kfs_.size() < max_local; ++k) {
    const auto kf = local_kfs_[k];
    for (const auto& n : kf->best_covisibles(10))
      if (in_local.insert(n->id()).second) {
        local_kfs_.push_back(n);
        break;
      }
    for (const auto& c : kf->children())
      if (!c->bad() && in_local.insert(c->id()).second) {
        local_kfs_.push_back(c);
        break;
      }
    if (auto p = kf->parent())
      if (!p->bad() && in_local.insert(p->id()).second) local_kfs_.push_back(p);
  }
  if (best) ref_kf_ = best;

  local_points_.clear();
  local_marks_.new_pass();
  for (const auto& kf : local_kfs_)
    for (const auto& mp : kf->map_points())
      if (mp && !mp->bad() && local_marks_.mark(mp->id())) local_points_.push_back(mp);
}

bool Tracking::track_local_map(Frame& f) {
  update_local_map(f);
  stats_.local_keyframes = static_cast<int>(local_kfs_.size());
  stats_.local_points = static_cast<int>(local_points_.size());
  frame_marks_.new_pass();
  for (const auto& mp : f.map_points)
    if (mp && !mp->bad()) {
      mp->increase_visible();
      frame_marks_.mark(mp->id());
    }
  std::vector<ProjectedPoint> proj;
  proj.reserve(local_points_.size());
  for (const auto& mp : local_points_) {
    if (frame_marks_.marked(mp->id())) continue;
    ProjectedPoint p;
    if (project_in_frustum(f, mp, &p)) {
      mp->increase_visible();
      proj.push_back(p);
    }
  }
  const double th = f.id < last_reloc_frame_id_ + 2 ? 5.0 : 3.0;
  search_local_points(f, proj, th);
  if (options_.align_patches && f.pyramid) {
    const auto t0 = std::chrono::steady_clock::now();
    align_matches(f);
    stats_.align_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  optimize_frame_pose(f);
  matches_inliers_ = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const auto& mp = f.map_points[i];
    if (!mp || f.outlier[i]) continue;
    mp->increase_found();
    if (mp->num_observations() > 0) ++matches_inliers_;
  }
  stats_.inliers = matches_inliers_;
  if (f.id < last_reloc_frame_id_ + static_cast<std::uint64_t>(options_.max_frames) && last_reloc_frame_id_ > 0 &&
      matches_inliers_ < 50)
    return fail("local map: only " + std::to_string(matches_inliers_) +
                " inliers after pose optimisation (need 50 just after relocalisation)");
  if (matches_inliers_ < 30)
    return fail("local map: only " + std::to_string(matches_inliers_) + " inliers after pose optimisation (need 30)");
  return true;
}

void Tracking::align_matches(Frame& f) {
  for (std::size_t i = 0; i < f.size(); ++i) {
    const auto& mp = f.map_points[i];
    if (!mp || mp->bad() || mp->num_observations() < 1) continue;
    ++stats_.align_tried;
    if (align_to_reference(f, i, *mp, options_.patch_align)) ++stats_.aligned;
  }
}

}  // namespace pvb::slam
