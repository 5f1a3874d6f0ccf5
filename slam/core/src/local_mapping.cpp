#include "pvb/slam/core/local_mapping.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <set>

#include "pvb/common/text.hpp"
#include "pvb/common/threads.hpp"
#include "pvb/slam/core/matcher.hpp"
#include "pvb/slam/core/patch_refine.hpp"
#include "pvb/slam/optim/optimizer.hpp"

namespace pvb::slam {

CullDecision recent_point_rule(double found_ratio, int num_observations, std::uint64_t first_kf_id,
                               std::uint64_t current_kf_id) {
  constexpr int kThObs = 3;  // stereo / RGB-D
  if (found_ratio < 0.25) return CullDecision::kErase;
  if (current_kf_id >= first_kf_id + 2 && num_observations <= kThObs) return CullDecision::kErase;
  if (current_kf_id >= first_kf_id + 3) return CullDecision::kDone;
  return CullDecision::kKeep;
}

void erase_outlier_observations(const BaProblem& problem, const std::vector<std::size_t>& outlier_edges,
                                const std::vector<std::shared_ptr<KeyFrame>>& kfs,
                                const std::vector<std::shared_ptr<MapPoint>>& pts) {
  for (std::size_t e : outlier_edges) {
    const BaEdge& edge = problem.edges[e];
    const auto& k = kfs[edge.keyframe];
    const auto& mp = pts[edge.point];
    const long idx = mp->index_in(k->id());
    if (idx < 0) continue;
    if (k->map_points()[static_cast<std::size_t>(idx)] == mp) k->set_map_point(static_cast<std::size_t>(idx), nullptr);
    mp->erase_observation(k->id());
  }
}

bool is_redundant_keyframe(const KeyFrame& kf, double th_depth_m, double ratio, int observers) {
  const Frame& f = kf.frame();
  int num_points = 0, redundant = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const auto& mp = f.map_points[i];
    if (!mp || mp->bad()) continue;
    if (f.depth_m[i] > th_depth_m || f.depth_m[i] <= 0) continue;
    ++num_points;
    if (mp->num_observations() <= observers) continue;
    const int level = f.keys_un[i].octave;
    int n = 0;
    for (const auto& [kid, o] : mp->observations()) {
      if (kid == kf.id()) continue;
      auto other = o.kf.lock();
      if (!other || other->bad()) continue;
      if (o.octave <= level + 1 && ++n >= observers) break;
    }
    if (n >= observers) ++redundant;
  }
  return num_points > 0 && redundant > ratio * num_points;
}

LocalMapping::LocalMapping(Map& map, std::shared_ptr<const CameraModel> cam, const LocalMappingOptions& options)
    : map_(map), cam_(std::move(cam)), options_(options) {
  const RobotSettings& robot = options_.motion.robot;
  if (uses_wheels(options_.motion.setup) && robot.wheel_calibration.enabled)
    wheel_calibrator_.emplace(robot.drive.track_m, robot.wheel_calibration);
}

LocalMapping::~LocalMapping() { stop(); }

void LocalMapping::start() {
  if (worker_.joinable()) return;
  on_worker_ = true;  // before the thread starts, so it sees the value
  worker_ = std::thread([this] {
    set_thread_name("pvb-mapping");
    if (!worker_error_.run([this] { run(); })) queue_.close();  // later keyframes are refused
  });
}

void LocalMapping::stop() {
  queue_.close();
  if (worker_.joinable()) worker_.join();
  on_worker_ = false;  // the worker is gone
}

void LocalMapping::insert(std::shared_ptr<KeyFrame> kf) {
  worker_error_.rethrow();
  ++pending_;
  if (on_worker_) {
    // Push and flag together, as the worker clears the flag and looks at
    // the queue together: a keyframe queued before that look makes the
    // worker skip the BA, one queued after it stops the BA, and no flag of
    // an earlier keyframe can land on a later keyframe's BA.
    std::lock_guard<std::mutex> lock(stop_mutex_);
    if (!queue_.push(std::move(kf))) {
      --pending_;
      return;
    }
    stop_ba_ = true;
  } else {
    process(kf);
  }
}

std::string to_json(const LocalMappingStats& stats) {
  return "{\"keyframes\": " + std::to_string(stats.keyframes) +
         ", \"local_ba\": " + std::to_string(stats.local_ba) +
         ", \"local_ba_stopped\": " + std::to_string(stats.local_ba_stopped) +
         ", \"busy_ms\": " + json_number(stats.busy_ms, 6) +
         ", \"local_ba_ms\": " + json_number(stats.local_ba_ms, 6) + "}";
}

LocalMappingStats LocalMapping::stats() const {
  LocalMappingStats s;
  s.keyframes = processed_.load();
  s.local_ba = ba_runs_.load();
  s.local_ba_stopped = ba_stopped_.load();
  s.busy_ms = busy_ms();
  s.local_ba_ms = static_cast<double>(ba_us_.load()) / 1000.0;
  return s;
}

void LocalMapping::run() {
  while (auto kf = queue_.pop()) process(*kf);
}

void LocalMapping::process(const std::shared_ptr<KeyFrame>& kf) {
  const auto t0 = std::chrono::steady_clock::now();
  struct BusyTimer {  // adds the time of this call to busy_us_, however it returns
    std::atomic<std::int64_t>& total;
    std::chrono::steady_clock::time_point t0;
    ~BusyTimer() {
      total += std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0).count();
    }
  } timer{busy_us_, t0};
  {
    std::lock_guard<std::mutex> lock(map_.mutex());
    process_new_keyframe(kf);
    cull_recent_points(kf);
    create_new_points(kf);
    if (queue_.size() == 0) fuse_with_neighbors(kf);
    if (options_.align_patches) {
      align_keyframe_observations(*kf, options_.patch_align);
      for (const auto& k : kf->best_covisibles(-1)) align_keyframe_observations(*k, options_.patch_align);
    }
  }
  bool queue_empty = false;
  {
    std::lock_guard<std::mutex> lock(stop_mutex_);
    stop_ba_ = false;
    queue_empty = queue_.size() == 0;
  }
  if (queue_empty) {
    if (options_.local_ba) local_bundle_adjustment(kf);
    std::lock_guard<std::mutex> lock(map_.mutex());
    cull_keyframes(kf);
  }
  if (options_.motion.setup != sensor::SensorSetup::kCamera) initialize_inertial(kf);
  if (wheel_calibrator_) calibrate_wheels(kf);
  if (options_.align_patches || spill_) {
    std::lock_guard<std::mutex> lock(map_.mutex());
    leave_local_map(kf);
  }
  if (spill_ && spilled_since_release_ >= options_.spill_release_every) {
    spill_->release_resident();
    spilled_since_release_ = 0;
  }
  if (after_keyframe_) after_keyframe_(kf);
  ++processed_;
  --pending_;
}

/// Keyframes that have left the local map (neither among the newest
/// options_.pyramid_window keyframes nor covisible with kf) release their
/// pyramid and put their features into the spill.  A released pyramid is
/// not rebuilt (the image is gone), so a point whose reference keyframe has
/// lost it is matched without alignment; spilled features are read from
/// the spill's file wherever the keyframe is used again.
void LocalMapping::leave_local_map(const std::shared_ptr<KeyFrame>& kf) {
  const auto holds_local_data = [&](const KeyFrame& k) {
    return k.frame().pyramid || (spill_ && !k.frame().features_spilled());
  };
  if (holds_local_data(*kf)) in_window_.push_back(kf);
  std::set<std::uint64_t> covisible;
  for (const auto& k : kf->best_covisibles(-1)) covisible.insert(k->id());
  const std::size_t n = in_window_.size();
  const std::size_t window = static_cast<std::size_t>(std::max(0, options_.pyramid_window));
  std::deque<std::weak_ptr<KeyFrame>> kept;
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = in_window_[i].lock();
    if (!k || k->bad() || !holds_local_data(*k)) continue;
    if (i + window >= n || covisible.count(k->id())) {
      kept.push_back(k);
      continue;
    }
    k->release_pyramid();
    if (spill_) {
      k->spill_features(spill_);
      ++spilled_since_release_;
    }
  }
  in_window_.swap(kept);
}

void LocalMapping::process_new_keyframe(const std::shared_ptr<KeyFrame>& kf) {
  const auto& pts = kf->map_points();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto mp = pts[i];
    if (!mp) continue;
    if (mp->bad()) {
      kf->set_map_point(i, nullptr);
      continue;
    }
    if (mp->index_in(kf->id()) < 0) {
      mp->add_observation(kf, i);
      mp->update_normal_and_depth();
      mp->compute_distinctive_descriptor();
    } else if (mp->first_kf_id() == kf->id()) {
      recent_points_.push_back(mp);  // created from this keyframe's depth
    }
  }
  kf->update_connections();
}

void LocalMapping::cull_recent_points(const std::shared_ptr<KeyFrame>& kf) {
  for (auto it = recent_points_.begin(); it != recent_points_.end();) {
    const auto& mp = *it;
    if (mp->bad()) {
      it = recent_points_.erase(it);
      continue;
    }
    switch (recent_point_rule(mp->found_ratio(), mp->num_observations(), mp->first_kf_id(), kf->id())) {
      case CullDecision::kErase:
        map_.erase_point(mp);
        it = recent_points_.erase(it);
        break;
      case CullDecision::kDone: it = recent_points_.erase(it); break;
      case CullDecision::kKeep: ++it; break;
    }
  }
}

void LocalMapping::create_new_points(const std::shared_ptr<KeyFrame>& kf) {
  const CameraModel& cam = *cam_;
  const Frame& f1 = kf->frame();
  const Eigen::Vector3d o1 = kf->camera_center_w();
  const double baseline_m = cam.K.bf / cam.K.fx;
  for (const auto& kf2 : kf->best_covisibles(options_.covisible_for_triangulation)) {
    const Frame& f2 = kf2->frame();
    const Eigen::Vector3d o2 = kf2->camera_center_w();
    if ((o2 - o1).norm() < baseline_m) continue;  // RGB-D: too little parallax to gain anything
    const std::vector<IndexMatch> matches = search_for_triangulation(*kf, *kf2);
    for (const IndexMatch& m : matches) {
      if (kf->map_points()[m.i1] || kf2->map_points()[m.i2]) continue;
      const Keypoint& k1 = f1.keys_un[m.i1];
      const Keypoint& k2 = f2.keys_un[m.i2];
      const Eigen::Vector3d ray1 = kf->T_c_w().linear().transpose() *
                                   Eigen::Vector3d((k1.pt.x - cam.K.cx) / cam.K.fx, (k1.pt.y - cam.K.cy) / cam.K.fy, 1);
      const Eigen::Vector3d ray2 = kf2->T_c_w().linear().transpose() *
                                   Eigen::Vector3d((k2.pt.x - cam.K.cx) / cam.K.fx, (k2.pt.y - cam.K.cy) / cam.K.fy, 1);
      const double cos_parallax = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
      const double cos_stereo1 = f1.depth_m[m.i1] > 0 ? std::cos(2 * std::atan2(baseline_m / 2, f1.depth_m[m.i1])) : 2.0;
      const double cos_stereo2 = f2.depth_m[m.i2] > 0 ? std::cos(2 * std::atan2(baseline_m / 2, f2.depth_m[m.i2])) : 2.0;
      const double cos_stereo = std::min(cos_stereo1, cos_stereo2);
      Eigen::Vector3d p_w;
      if (cos_parallax > 0 && cos_parallax < cos_stereo && cos_parallax < 0.9998) {
        // linear triangulation (DLT) of the two views
        Eigen::Matrix<double, 4, 4> A;
        const Eigen::Matrix<double, 3, 4> P1 = kf->T_c_w().matrix().topRows<3>();
        const Eigen::Matrix<double, 3, 4> P2 = kf2->T_c_w().matrix().topRows<3>();
        const double x1 = (k1.pt.x - cam.K.cx) / cam.K.fx, y1 = (k1.pt.y - cam.K.cy) / cam.K.fy;
        const double x2 = (k2.pt.x - cam.K.cx) / cam.K.fx, y2 = (k2.pt.y - cam.K.cy) / cam.K.fy;
        A.row(0) = x1 * P1.row(2) - P1.row(0);
        A.row(1) = y1 * P1.row(2) - P1.row(1);
        A.row(2) = x2 * P2.row(2) - P2.row(0);
        A.row(3) = y2 * P2.row(2) - P2.row(1);
        Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
        const Eigen::Vector4d X = svd.matrixV().col(3);
        if (std::abs(X(3)) < 1e-12) continue;
        p_w = X.head<3>() / X(3);
      } else if (f1.depth_m[m.i1] > 0 && cos_stereo1 < cos_stereo2) {
        p_w = f1.unproject_world(m.i1);
      } else if (f2.depth_m[m.i2] > 0) {
        p_w = f2.unproject_world(m.i2);
      } else {
        continue;
      }
      // in front of both, reprojection error within chi2 bounds
      bool good = true;
      for (int v = 0; v < 2 && good; ++v) {
        const Frame& fv = v == 0 ? f1 : f2;
        const std::size_t iv = v == 0 ? m.i1 : m.i2;
        const Eigen::Vector3d p_c = fv.T_c_w * p_w;
        if (p_c.z() <= 0) {
          good = false;
          break;
        }
        good = observation_chi2(cam.K, fv.T_c_w, p_w, fv.observation(iv)) <
               (fv.u_right[iv] >= 0 ? 7.8 : 5.991);
      }
      if (!good) continue;
      const double d1 = (p_w - o1).norm(), d2 = (p_w - o2).norm();
      if (d1 == 0 || d2 == 0) continue;
      const double ratio_dist = d2 / d1;
      const double ratio_octave = cam.scale[k1.octave] / cam.scale[k2.octave];
      const double factor = 1.5 * cam.scale[1];
      if (ratio_dist * factor < ratio_octave || ratio_dist > ratio_octave * factor) continue;
      auto mp = map_.create_point(p_w, kf);
      mp->add_observation(kf, m.i1);
      mp->add_observation(kf2, m.i2);
      kf->set_map_point(m.i1, mp);
      kf2->set_map_point(m.i2, mp);
      mp->compute_distinctive_descriptor();
      mp->update_normal_and_depth();
      recent_points_.push_back(mp);
    }
  }
}

void LocalMapping::fuse_with_neighbors(const std::shared_ptr<KeyFrame>& kf) {
  std::vector<std::shared_ptr<KeyFrame>> targets;
  std::set<std::uint64_t> seen = {kf->id()};
  for (const auto& n : kf->best_covisibles(10)) {
    if (!seen.insert(n->id()).second) continue;
    targets.push_back(n);
    for (const auto& n2 : n->best_covisibles(5))
      if (seen.insert(n2->id()).second) targets.push_back(n2);
  }
  for (const auto& t : targets) fuse(map_, t, kf->map_points());
  std::vector<std::shared_ptr<MapPoint>> candidates;
  std::set<std::uint64_t> cand_ids;
  for (const auto& t : targets)
    for (const auto& mp : t->map_points())
      if (mp && !mp->bad() && cand_ids.insert(mp->id()).second) candidates.push_back(mp);
  fuse(map_, kf, candidates);
  for (const auto& mp : kf->map_points())
    if (mp && !mp->bad()) {
      mp->compute_distinctive_descriptor();
      mp->update_normal_and_depth();
    }
  kf->update_connections();
}

void LocalMapping::local_bundle_adjustment(const std::shared_ptr<KeyFrame>& kf) {
  BaProblem problem;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  std::vector<std::shared_ptr<MapPoint>> pts;
  {
    std::lock_guard<std::mutex> lock(map_.mutex());
    if (kf->bad()) return;
    std::map<std::uint64_t, std::size_t> kf_index, pt_index;
    auto add_kf = [&](const std::shared_ptr<KeyFrame>& k, bool fixed) {
      kf_index[k->id()] = problem.keyframes.size();
      problem.keyframes.push_back({k->id(), k->T_c_w(), fixed || k->id() == 0 || k->root() || k->fixed()});
      kfs.push_back(k);
    };
    add_kf(kf, false);
    for (const auto& n : kf->best_covisibles(-1)) add_kf(n, false);
    const std::size_t num_local = kfs.size();
    for (std::size_t k = 0; k < num_local; ++k)
      for (const auto& mp : kfs[k]->map_points())
        if (mp && !mp->bad() && !pt_index.count(mp->id())) {
          pt_index[mp->id()] = problem.points.size();
          problem.points.push_back({mp->id(), mp->p_w()});
          pts.push_back(mp);
        }
    // Keyframes that see local points but are not local: fixed, they anchor the gauge.
    for (const auto& mp : pts)
      for (const auto& [kid, o] : mp->observations()) {
        if (kf_index.count(kid)) continue;
        auto k = o.kf.lock();
        if (k && !k->bad()) add_kf(k, true);
      }
    if (problem.keyframes.size() < 2) problem.keyframes[0].fixed = true;
    for (std::size_t p = 0; p < pts.size(); ++p)
      for (const auto& [kid, o] : pts[p]->observations()) {
        auto it = kf_index.find(kid);
        if (it == kf_index.end()) continue;
        problem.edges.push_back({it->second, p, kfs[it->second]->frame().observation(o.idx)});
      }
    if (options_.motion.setup != sensor::SensorSetup::kCamera) add_motion_terms(&problem, &kfs);
  }
  if (problem.edges.empty()) return;
  // Optimise without holding the map: tracking goes on with the old poses.
  BaOptions ba_options = options_.ba;
  ba_options.abort_flag = on_worker_ ? &stop_ba_ : nullptr;  // inline (sync) mode: never stopped
  ++ba_runs_;
  if (on_worker_ && stop_ba_.load()) {  // ORB-SLAM2 returns here too: the map is left alone
    ++ba_stopped_;
    return;
  }
  const auto t_ba = std::chrono::steady_clock::now();
  const BaResult result = slam::local_bundle_adjustment(&problem, cam_->K, ba_options);
  ba_us_ += std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t_ba).count();
  if (result.stopped) ++ba_stopped_;

  std::lock_guard<std::mutex> lock(map_.mutex());
  erase_outlier_observations(problem, result.outlier_edges, kfs, pts);
  for (std::size_t k = 0; k < kfs.size(); ++k)
    if (!problem.keyframes[k].fixed && !kfs[k]->bad()) kfs[k]->set_T_c_w(problem.keyframes[k].T_c_w);
  if (problem.inertial) write_motion_states(problem, kfs);
  for (std::size_t p = 0; p < pts.size(); ++p)
    if (!pts[p]->bad()) {
      pts[p]->set_p_w(problem.points[p].p_w);
      pts[p]->update_normal_and_depth();
    }
  map_.remove_bad_among(pts);  // the outliers' points are the only ones the adjustment makes bad
}

void LocalMapping::cull_keyframes(const std::shared_ptr<KeyFrame>& kf) {
  for (const auto& n : kf->best_covisibles(-1)) {
    if (n->id() == 0 || n->root() || n->bad() || !may_cull_in_time(*n)) continue;
    if (is_redundant_keyframe(*n, cam_->th_depth_m, options_.redundant_ratio, options_.redundant_observers) &&
        map_.erase_keyframe(n))
      culled_.push_back(n->id());
  }
}

}  // namespace pvb::slam
