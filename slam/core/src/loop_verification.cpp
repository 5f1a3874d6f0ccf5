#include "loop_verification.hpp"

#include <algorithm>
#include <set>
#include <unordered_set>

#include "pvb/geometry/angles.hpp"
#include "pvb/slam/core/frame_pose.hpp"
#include "pvb/slam/core/loop_closing.hpp"
#include "pvb/slam/core/matcher.hpp"

namespace pvb::slam {
namespace {

using geom::kRadToDeg;
/// A keyframe confirms a held-back merge when it verifies this close to the
/// pose the transform predicts (or within maxCorrection, if smaller).
constexpr double kMergeConfirmTolerance_m = 0.5;

/// Nearest-rank quantile q of the values (0 for none).
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

/// Optical axis (z) of a keyframe in the world frame.
Eigen::Vector3d optical_axis_w(const KeyFrame& kf) { return kf.T_c_w().linear().row(2).transpose(); }

/// Pose-only optimisation of `f` against its map points (all keypoints with
/// a point); drops the outliers.  Returns the inlier count.
int optimize_and_prune(Frame& f) {
  const int inliers = optimize_frame_pose(f);
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.outlier[i]) {
      f.map_points[i] = nullptr;
      f.outlier[i] = 0;
    }
  return inliers;
}

/// Matches by projection, at the probe's pose, the points of `root`, its
/// covisibles and, with two rings, theirs, that the probe does not hold yet.
/// Covisible keyframes share most of their points, so each is projected
/// once (hashed sets: with ordered ones, the group's tens of thousands of
/// observations took a fifth of loop detection's time on a plant).
void search_around(Frame* probe, const std::shared_ptr<KeyFrame>& root, int rings) {
  std::unordered_set<std::uint64_t> in_group = {root->id()};
  std::vector<std::shared_ptr<KeyFrame>> group = {root};
  for (std::size_t begin = 0, ring = 0; ring < static_cast<std::size_t>(rings); ++ring) {
    const std::size_t end = group.size();
    for (std::size_t i = begin; i < end; ++i)
      for (const auto& n : group[i]->best_covisibles(-1))
        if (in_group.insert(n->id()).second) group.push_back(n);
    begin = end;
  }
  std::size_t observations = probe->size();
  for (const auto& g : group) observations += g->map_points().size();
  std::unordered_set<std::uint64_t> have;
  have.reserve(observations);
  for (const auto& mp : probe->map_points)
    if (mp) have.insert(mp->id());
  std::vector<ProjectedPoint> proj;
  for (const auto& g : group)
    for (const auto& mp : g->map_points()) {
      if (!mp || mp->bad() || !have.insert(mp->id()).second) continue;
      ProjectedPoint p;
      if (project_in_frustum(*probe, mp, &p)) proj.push_back(p);
    }
  search_local_points(*probe, proj, 10.0 / 4.0);
}

}  // namespace

namespace detail {

double scene_median_depth_m(const KeyFrame& kf) {
  std::vector<double> z;
  for (const auto& mp : kf.map_points())
    if (mp && !mp->bad()) z.push_back((kf.T_c_w() * mp->p_w()).z());
  return quantile(std::move(z), 0.5);
}

void pose_difference(const geom::SE3d& a, const geom::SE3d& b, double* dist_m, double* angle_deg) {
  *dist_m = (a.inverse().translation() - b.inverse().translation()).norm();
  *angle_deg = geom::rotation_angle_rad(a.linear() * b.linear().transpose()) * kRadToDeg;
}

}  // namespace detail

std::vector<std::shared_ptr<KeyFrame>> pose_candidates(const Map& map, const KeyFrame& kf,
                                                       const LoopClosingOptions& options) {
  std::set<std::uint64_t> connected = {kf.id()};
  for (const auto& n : kf.best_covisibles(-1)) connected.insert(n->id());
  const Eigen::Vector3d c = kf.camera_center_w();
  const Eigen::Vector3d axis = optical_axis_w(kf);
  const double min_cos = std::cos(options.max_angle_deg / kRadToDeg);
  const std::uint32_t own = map.map_of(kf);
  std::vector<std::pair<double, std::shared_ptr<KeyFrame>>> found;
  for (const auto& [id, k] : map.keyframes()) {
    if (id + static_cast<std::uint64_t>(options.min_keyframe_gap) > kf.id()) break;  // ordered by id
    if (k->bad() || connected.count(id) || map.map_of(*k) != own) continue;
    const double d = (k->camera_center_w() - c).norm();
    if (d > options.search_radius_m) continue;
    if (optical_axis_w(*k).dot(axis) < min_cos) continue;
    found.emplace_back(d, k);
  }
  std::stable_sort(found.begin(), found.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::shared_ptr<KeyFrame>> out;
  for (const auto& [d, k] : found) {
    if (static_cast<int>(out.size()) >= options.max_candidates) break;
    out.push_back(k);
  }
  return out;
}

Frame loop_probe(const KeyFrame& kf) {
  Frame probe = kf.frame();  // a copy: its map_points become the loop-side matches
  std::fill(probe.map_points.begin(), probe.map_points.end(), nullptr);
  return probe;
}

bool verify_by_descriptors(const KeyFrame& kf, const KeyFrame& cand, const LoopClosingOptions& options,
                           Frame* probe, LoopMatch* out) {
  // Through the direct index when both have one (ORB-SLAM2 SearchByBoW):
  // only descriptors under the same vocabulary node are compared.
  const bool by_bow = !cand.features_by_node().empty() && !kf.features_by_node().empty();
  out->initial_matches = by_bow ? search_keyframe_by_bow(cand, *probe, kf.features_by_node(), kThLow, 0.75)
                                : search_keyframe_bruteforce(cand, *probe, kThLow, 0.75);
  if (out->initial_matches < options.min_matches) return false;
  out->stage = LoopMatch::Stage::kRansac;

  // EPnP RANSAC on the loop-side points against the new keyframe's keypoints.
  out->ransac_inliers = pnp_ransac_on_matches(*probe, options.min_matches / 2);
  if (out->ransac_inliers < options.min_matches / 2) return false;
  const int inliers = optimize_and_prune(*probe);
  if (inliers < options.min_matches / 2) return false;
  out->stage = LoopMatch::Stage::kInliers;
  out->inliers = inliers;
  out->T_c_w = probe->T_c_w;
  return true;
}

void verify_by_projection(const std::shared_ptr<KeyFrame>& cand, const LoopClosingOptions& options,
                          Frame* probe, LoopMatch* out) {
  // Guided search: the points of the candidate and its covisibles, projected
  // with the verified pose (ORB-SLAM2 SearchByProjection of mvpLoopMapPoints).
  search_around(probe, cand, 1);
  out->inliers = optimize_and_prune(*probe);
  out->T_c_w = probe->T_c_w;
  out->points = probe->map_points;
  out->accepted = out->inliers >= options.min_inliers;
  if (out->accepted) out->stage = LoopMatch::Stage::kAccepted;
}

LoopMatch verify_loop(const KeyFrame& kf, const std::shared_ptr<KeyFrame>& cand,
                      const LoopClosingOptions& options) {
  LoopMatch out;
  Frame probe = loop_probe(kf);
  if (verify_by_descriptors(kf, *cand, options, &probe, &out))
    verify_by_projection(cand, options, &probe, &out);
  return out;
}

bool places_apart(const std::vector<VerifiedPlace>& places, double distance_m, double inlier_share) {
  int most = 0;
  for (const auto& p : places) most = std::max(most, p.inliers);
  std::vector<Eigen::Vector3d> rivals_w;
  for (const auto& p : places)
    if (!p.lookalike || p.inliers >= inlier_share * most) rivals_w.push_back(p.centre_w);
  for (std::size_t i = 0; i < rivals_w.size(); ++i)
    for (std::size_t j = i + 1; j < rivals_w.size(); ++j)
      if ((rivals_w[i] - rivals_w[j]).norm() > distance_m) return true;
  return false;
}

LoopMatch verify_at(const KeyFrame& kf, const std::shared_ptr<KeyFrame>& cand, const geom::SE3d& T_c_w,
                    const LoopClosingOptions& options) {
  LoopMatch out;
  out.stage = LoopMatch::Stage::kInliers;
  Frame probe = loop_probe(kf);
  probe.T_c_w = T_c_w;
  search_around(&probe, cand, 2);
  out.initial_matches = static_cast<int>(std::count_if(probe.map_points.begin(), probe.map_points.end(),
                                                       [](const auto& mp) { return mp != nullptr; }));
  out.inliers = out.initial_matches > 0 ? optimize_and_prune(probe) : 0;
  out.T_c_w = probe.T_c_w;
  out.points = probe.map_points;
  double dist_m = 0, angle_deg = 0;
  detail::pose_difference(probe.T_c_w, T_c_w, &dist_m, &angle_deg);
  out.accepted = out.inliers >= options.min_inliers &&
                 dist_m <= std::min(options.max_correction_m, kMergeConfirmTolerance_m) &&
                 angle_deg <= options.max_correction_deg;
  if (out.accepted) out.stage = LoopMatch::Stage::kAccepted;
  return out;
}

}  // namespace pvb::slam
