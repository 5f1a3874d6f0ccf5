#include "pvb/slam/core/tracking.hpp"

#include "pvb/common/text.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "pvb/slam/core/frame_pose.hpp"

namespace pvb::slam {

const char* to_string(TrackingState s) {
  switch (s) {
    case TrackingState::kNotInitialized: return "not_initialized";
    case TrackingState::kOk: return "ok";
    case TrackingState::kLost: return "lost";
    case TrackingState::kDeadReckoning: return "dead_reckoning";
  }
  return "?";
}

const char* to_string(TrackingMethod m) {
  switch (m) {
    case TrackingMethod::kNone: return "none";
    case TrackingMethod::kInitialization: return "init";
    case TrackingMethod::kMotionModel: return "motion";
    case TrackingMethod::kReferenceKeyFrame: return "refkf";
    case TrackingMethod::kRelocalization: return "reloc";
    case TrackingMethod::kDeadReckoning: return "dead_reckoning";
    case TrackingMethod::kAfterBlind: return "after_blind";
    case TrackingMethod::kCarriedRestart: return "carried_restart";
  }
  return "?";
}

void IdMarks::new_pass() {
  ++pass_;
  if (pass_ == 0) {  // wrapped: clear the stamps once every 2^32 passes
    std::fill(stamp_.begin(), stamp_.end(), 0);
    pass_ = 1;
  }
  sparse_.clear();
}

bool IdMarks::mark(std::uint64_t id) {
  if (id >= kDenseLimit) return sparse_.insert(id).second;
  if (id >= stamp_.size()) stamp_.resize(std::max<std::size_t>(id + 1, 2 * stamp_.size()), 0);
  if (stamp_[id] == pass_) return false;
  stamp_[id] = pass_;
  return true;
}

bool IdMarks::marked(std::uint64_t id) const {
  if (id >= kDenseLimit) return sparse_.count(id) > 0;
  return id < stamp_.size() && stamp_[id] == pass_;
}

Tracking::Tracking(Map& map, std::shared_ptr<const CameraModel> cam, const TrackingOptions& options,
                   const PlaceRecognizer* place)
    : map_(map), cam_(std::move(cam)), options_(options), pe_matcher_(options.pe_match), place_(place) {}

std::shared_ptr<KeyFrame> Tracking::track(Frame f, bool mapping_idle, std::size_t mapping_queue) {
  std::lock_guard<std::mutex> lock(map_.mutex());
  stats_ = {};
  if (state_ == TrackingState::kLost && may_begin_map_ && options_.new_map_after_lost > 0 &&
      lost_in_row_ >= options_.new_map_after_lost) {
    // Lost in the loaded map for too long: a provisional map begins here.
    state_ = TrackingState::kNotInitialized;
    provisional_ = map_.begin_provisional();
    lost_in_row_ = 0;
    lost_odom_.reset();
  }
  if (state_ == TrackingState::kNotInitialized) return start_map(f);
  if (state_ == TrackingState::kLost) carry_lost_odometry(f);

  const bool was_tracking = state_ == TrackingState::kOk || state_ == TrackingState::kDeadReckoning;
  bool ok = track_by_state(f);
  if (ok) ok = track_local_map(f);
  if (!ok && stats_.method == TrackingMethod::kRelocalization) {
    stats_.reloc_failure = TrackingStats::RelocFailure::kLocalMap;
    stats_.failure = "relocalisation: keyframe " + std::to_string(reloc_kf_->id()) + " matched; " + stats_.failure;
  }
  if (ok) probe_merge(f);
  if (ok && stats_.method == TrackingMethod::kRelocalization) record_relocalisation(f);
  const bool dead = !ok && was_tracking && motion_ && dead_reckon(f);
  if (dead) stats_.method = TrackingMethod::kDeadReckoning;
  if (ok || dead) lost_odom_.reset();
  else if (was_tracking) begin_lost_odometry();
  if (!dead) blind_.reset();
  state_ = ok ? TrackingState::kOk : dead ? TrackingState::kDeadReckoning : TrackingState::kLost;
  lost_in_row_ = ok || dead ? 0 : lost_in_row_ + 1;
  if (!ok && !dead && !was_tracking)
    if (std::shared_ptr<KeyFrame> kf = restart_at_carried_pose(f)) return kf;
  update_motion_state(f, ok);

  std::shared_ptr<KeyFrame> new_kf;
  if (ok) new_kf = after_tracked(f, mapping_idle, mapping_queue);
  else velocity_.reset();
  last_is_keyframe_ = static_cast<bool>(new_kf);
  if ((ok || dead) && ref_kf_) T_last_ref_ = f.T_c_w * ref_kf_->T_c_w().inverse();
  last_ = std::move(f);
  if (!ok && !dead) last_.has_pose = false;
  return new_kf;
}

std::shared_ptr<KeyFrame> Tracking::start_map(Frame& f) {
  if (!initialize(f)) return nullptr;
  stats_.method = TrackingMethod::kInitialization;
  stats_.new_keyframe = true;
  state_ = TrackingState::kOk;
  last_kf_frame_id_ = f.id;
  update_motion_state(f, false);
  last_is_keyframe_ = true;
  T_last_ref_ = geom::SE3d::Identity();
  last_ = f;
  return ref_kf_;
}

bool Tracking::track_by_state(Frame& f) {
  bool ok = false;
  if (state_ == TrackingState::kDeadReckoning) {
    replace_in_last_frame();
    ok = track_after_blind(f);
    if (ok) stats_.method = TrackingMethod::kAfterBlind;
  } else if (state_ == TrackingState::kOk) {
    replace_in_last_frame();
    if ((velocity_ || inertial_ready()) && f.id >= last_reloc_frame_id_ + 2) {
      ok = track_with_motion_model(f);
      if (ok) stats_.method = TrackingMethod::kMotionModel;
    }
    if (!ok) {
      ok = track_reference_keyframe(f);
      if (ok) stats_.method = TrackingMethod::kReferenceKeyFrame;
    }
  } else {
    ok = relocalize(f);
    if (ok) stats_.method = TrackingMethod::kRelocalization;
  }
  return ok;
}

std::shared_ptr<KeyFrame> Tracking::after_tracked(Frame& f, bool mapping_idle, std::size_t mapping_queue) {
  if (last_.has_pose) velocity_ = f.T_c_w * last_.T_c_w.inverse();
  else velocity_.reset();
  // drop visual-odometry points (not in the map) and outliers
  for (std::size_t i = 0; i < f.size(); ++i) {
    const auto& mp = f.map_points[i];
    if (mp && mp->num_observations() < 1) {
      f.map_points[i] = nullptr;
      f.outlier[i] = 0;
    }
  }
  std::shared_ptr<KeyFrame> new_kf;
  if (need_new_keyframe(f, mapping_idle, mapping_queue)) {
    new_kf = create_keyframe(f);
    stats_.new_keyframe = true;
  }
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.map_points[i] && f.outlier[i]) f.map_points[i] = nullptr;
  return new_kf;
}

void Tracking::start_in_map(bool localise_only) {
  state_ = TrackingState::kLost;
  localise_only_ = localise_only;
  may_begin_map_ = !localise_only;
}

bool Tracking::initialize(Frame& f) {
  const int with_depth = f.num_with_depth();
  if (with_depth <= options_.min_init_points) {
    const std::string why = "initialisation: only " + std::to_string(with_depth) +
                            " keypoints with depth (need more than " + std::to_string(options_.min_init_points) + ")";
    return options_.two_view_start ? start_from_two_views(f, why) : fail(why);
  }
  start_ref_.reset();
  if (const std::optional<std::string> wait = waiting_for_accelerometer(f))
    return fail("initialisation: " + *wait);
  f.T_c_w = first_pose();
  f.has_pose = true;
  auto kf = map_.create_keyframe(f);
  attach_motion(kf);
  if (provisional_ > 0) {  // its own frame until merged: a root like keyframe 0
    kf->set_provisional(provisional_);
    kf->make_root();
  }
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.depth_m[i] > 0) add_point_from_depth(f, kf, i);
  ref_kf_ = kf;
  local_kfs_ = {kf};
  return true;
}

bool Tracking::start_from_two_views(Frame& f, const std::string& why) {
  if (const std::optional<std::string> wait = waiting_for_accelerometer(f)) return fail(why + "; " + *wait);
  if (!start_ref_) {
    start_ref_ = f;
    start_ref_->T_c_w = first_pose();
    return fail(why + "; two views: frame " + std::to_string(f.id) + " is the first view");
  }
  std::string two_view_why;
  TwoViewFailure failure = TwoViewFailure::kNotYet;
  const std::optional<TwoViewStart> s = two_view_start(*start_ref_, f, options_.two_view, &two_view_why, &failure);
  if (!s) {
    const std::string text = why + "; two views from frame " + std::to_string(start_ref_->id) + ": " + two_view_why;
    if (failure == TwoViewFailure::kFewMatches) {  // the view has moved on: a new first view
      start_ref_ = f;
      start_ref_->T_c_w = first_pose();
    }
    return fail(text);
  }
  build_two_view_map(f, *s);
  start_ref_.reset();
  return true;
}

void Tracking::build_two_view_map(Frame& f, const TwoViewStart& s) {
  Frame& ref = *start_ref_;
  ref.has_pose = true;
  f.T_c_w = s.T_cur_ref * ref.T_c_w;
  f.has_pose = true;
  const auto kf0 = map_.create_keyframe(ref);
  if (provisional_ > 0) {  // its own frame until merged: a root like keyframe 0
    kf0->set_provisional(provisional_);
    kf0->make_root();
  }
  const auto kf1 = map_.create_keyframe(f);
  kf1->set_provisional(provisional_);
  // The motion sensors' chain starts at the second keyframe: the first
  // view's interval was not kept apart.
  attach_motion(kf1);
  const geom::SE3d T_w_ref = ref.T_c_w.inverse();
  for (std::size_t k = 0; k < s.matches.size(); ++k) {
    const auto [i0, i1] = std::pair(s.matches[k].i1, s.matches[k].i2);
    auto mp = map_.create_point(T_w_ref * s.p_ref_m[k], kf0);
    mp->add_observation(kf0, i0);
    kf0->set_map_point(i0, mp);
    mp->add_observation(kf1, i1);
    kf1->set_map_point(i1, mp);
    mp->compute_distinctive_descriptor();
    mp->update_normal_and_depth();
    f.map_points[i1] = mp;
  }
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.depth_m[i] > 0 && !f.map_points[i]) add_point_from_depth(f, kf1, i);
  stats_.two_view_points = static_cast<int>(s.matches.size());
  stats_.two_view_scale_points = s.scale_points;
  start_kf_ = kf0;
  ref_kf_ = kf1;
  local_kfs_ = {kf0, kf1};
}

bool Tracking::fail(const std::string& why) {
  if (!stats_.failure.empty()) stats_.failure += "; ";
  stats_.failure += why;
  return false;
}

void Tracking::replace_in_last_frame() {
  for (auto& mp : last_.map_points)
    if (mp)
      if (auto r = mp->replaced()) mp = r;
}

void Tracking::update_last_frame() {
  // The reference keyframe may have moved in local BA since.
  if (ref_kf_ && !ref_kf_->bad()) last_.T_c_w = T_last_ref_ * ref_kf_->T_c_w();
  if (last_is_keyframe_) return;
  // Visual-odometry points: the closest keypoints with depth that have no map
  // point get a temporary point (ORB-SLAM2 UpdateLastFrame for RGB-D).
  const auto by_depth = last_.keypoints_by_depth();
  int n = 0;
  for (const auto& [d, i] : by_depth) {
    const auto& mp = last_.map_points[i];
    if (!mp || mp->num_observations() < 1) {
      auto tmp = std::make_shared<MapPoint>(next_temp_point_id_++, last_.unproject_world(i), nullptr);
      last_.map_points[i] = tmp;
    }
    ++n;
    if (d > cam_->th_depth_m && n > 100) break;
  }
}

void Tracking::discard_outliers(Frame& f, int* map_matches) {
  int n = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!f.map_points[i]) continue;
    if (f.outlier[i]) {
      f.map_points[i] = nullptr;
      f.outlier[i] = 0;
    } else if (f.map_points[i]->num_observations() > 0) {
      ++n;
    }
  }
  *map_matches = n;
}

bool Tracking::track_with_motion_model(Frame& f) {
  update_last_frame();
  // The IMU's prediction once its state is trusted, else constant velocity.
  f.T_c_w = inertial_ready() ? predicted_pose(nullptr) : *velocity_ * last_.T_c_w;
  std::fill(f.map_points.begin(), f.map_points.end(), nullptr);
  std::vector<IndexMatch> m = search_by_projection(f, last_, options_.motion_th, options_.motion_ratio);
  if (m.size() < 20) {
    std::fill(f.map_points.begin(), f.map_points.end(), nullptr);
    m = search_by_projection(f, last_, 2 * options_.motion_th, options_.motion_ratio);
  }
  stats_.coarse_matches = static_cast<int>(m.size());
  stats_.matches_kept = stats_.coarse_matches;
  if (m.size() < 20)
    return fail("motion model: only " + std::to_string(m.size()) + " matches by projection (need 20)");

  // Scoring record (stats_.motion); pixel pairs (last keypoint, current keypoint).
  auto& rec = stats_.motion;
  rec.undistorted.resize(m.size());
  rec.raw.resize(m.size());
  rec.octaves.resize(m.size());
  rec.pe_keep.assign(m.size(), 1);
  for (std::size_t k = 0; k < m.size(); ++k) {
    const auto to_eigen = [](const cv::Point2f& p) { return Eigen::Vector2d(p.x, p.y); };
    rec.undistorted[k] = {to_eigen(last_.keys_un[m[k].i1].pt), to_eigen(f.keys_un[m[k].i2].pt)};
    rec.raw[k] = {to_eigen(last_.keys[m[k].i1]), to_eigen(f.keys[m[k].i2])};
    rec.octaves[k] = {last_.keys_un[m[k].i1].octave, f.keys_un[m[k].i2].octave};
  }

  if (options_.use_pe_match && options_.pe_skip_low_parallax) {
    stats_.translation_parallax_px = translation_parallax_px(m, velocity_ ? *velocity_ : f.T_c_w * last_.T_c_w.inverse());
    stats_.pe_skipped = stats_.translation_parallax_px < options_.pe_match.inlier_threshold_px;
  }
  if (options_.use_pe_match && !stats_.pe_skipped) {
    // PE-match on the pixel pairs (last keypoint, current keypoint), paper sec. 3.
    const auto t0 = std::chrono::steady_clock::now();
    PeMatchResult r;
    pe_matcher_.match(rec.undistorted.data(), rec.undistorted.size(), r);
    if (r.F) {
      int kept = 0;
      for (std::size_t k = 0; k < m.size(); ++k) {
        if (r.inlier_mask[k]) ++kept;
        else f.map_points[m[k].i2] = nullptr;
      }
      rec.pe_keep = r.inlier_mask;
      stats_.matches_kept = kept;
    }
    stats_.pe_match_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (stats_.matches_kept < 10)
      return fail("motion model: PE-match kept " + std::to_string(stats_.matches_kept) + " of " +
                  std::to_string(stats_.coarse_matches) + " matches (need 10)");
  }

  optimize_frame_pose(f);
  rec.pose_inlier.resize(m.size());
  for (std::size_t k = 0; k < m.size(); ++k)
    rec.pose_inlier[k] = (f.map_points[m[k].i2] && !f.outlier[m[k].i2]) ? 1 : 0;
  int map_matches = 0;
  discard_outliers(f, &map_matches);
  if (map_matches < 10)
    return fail("motion model: only " + std::to_string(map_matches) +
                " map matches after pose optimisation (need 10)");
  return true;
}

double Tracking::translation_parallax_px(const std::vector<IndexMatch>& m, const geom::SE3d& T_cur_last) const {
  // For each match with depth in the last frame: its point p in the last
  // camera, and the distance between its projections under the predicted
  // motion with and without the translation, |pi(R p + t) - pi(R p)|.
  const StereoIntrinsics& K = cam_->K;
  const Eigen::Matrix3d R = T_cur_last.linear();
  const Eigen::Vector3d t = T_cur_last.translation();
  std::vector<double> d;
  d.reserve(m.size());
  for (const IndexMatch& mm : m) {
    const double z = last_.depth_m[mm.i1];
    if (!(z > 0)) continue;
    const cv::Point2f& uv = last_.keys_un[mm.i1].pt;
    const Eigen::Vector3d p = cam_->unproject(Eigen::Vector2d(uv.x, uv.y), z);
    const Eigen::Vector3d a = R * p, b = a + t;
    if (!(a.z() > 0) || !(b.z() > 0)) continue;
    const double du = K.fx * (b.x() / b.z() - a.x() / a.z()), dv = K.fy * (b.y() / b.z() - a.y() / a.z());
    d.push_back(std::hypot(du, dv));
  }
  if (d.size() < 8) return std::numeric_limits<double>::infinity();
  const auto mid = d.begin() + static_cast<long>(d.size() / 2);
  std::nth_element(d.begin(), mid, d.end());
  return *mid;
}

bool Tracking::track_reference_keyframe(Frame& f) {
  if (!ref_kf_ || ref_kf_->bad()) return fail("reference keyframe: none (culled)");
  std::fill(f.map_points.begin(), f.map_points.end(), nullptr);
  const int n = search_keyframe_bruteforce(*ref_kf_, f, kThLow, 0.7);
  if (n < 15) return fail("reference keyframe: only " + std::to_string(n) + " descriptor matches (need 15)");
  f.T_c_w = last_.has_pose ? last_.T_c_w : ref_kf_->T_c_w();
  optimize_frame_pose(f);
  int map_matches = 0;
  discard_outliers(f, &map_matches);
  if (map_matches < 10)
    return fail("reference keyframe: only " + std::to_string(map_matches) +
                " map matches after pose optimisation (need 10)");
  return true;
}

bool Tracking::need_new_keyframe(const Frame& f, bool mapping_idle, std::size_t mapping_queue) {
  if (localise_only_) return false;
  const std::size_t num_kfs = map_.num_keyframes();
  const auto max_frames = static_cast<std::uint64_t>(options_.max_frames);
  const int min_obs = num_kfs <= 2 ? 2 : 3;
  const int ref_matches = ref_kf_ ? ref_kf_->num_tracked_points(min_obs) : 0;
  int tracked_close = 0, non_tracked_close = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (f.depth_m[i] > 0 && f.depth_m[i] < cam_->th_depth_m) {
      if (f.map_points[i] && !f.outlier[i]) ++tracked_close;
      else ++non_tracked_close;
    }
  }
  stats_.kf_tracked_close = tracked_close;
  stats_.kf_untracked_close = non_tracked_close;
  stats_.kf_ref_points = ref_matches;
  if (ref_kf_) {
    stats_.kf_ref_all = ref_kf_->num_tracked_points(1);
    for (std::size_t i = 0; i < f.size(); ++i)
      if (f.map_points[i] && !f.outlier[i] && f.map_points[i]->index_in(ref_kf_->id()) >= 0)
        ++stats_.kf_ref_shared;
  }
  if (last_reloc_frame_id_ > 0 && f.id < last_reloc_frame_id_ + max_frames && num_kfs > max_frames)
    return false;
  const bool need_close =
      tracked_close < options_.kf_min_tracked_close && non_tracked_close > options_.kf_min_untracked_close;
  // "Tracking has fallen off the reference keyframe": ORB-SLAM2 compares the
  // inliers with 75 % (25 % when urgent) of the reference keyframe's points
  // with min_obs observations; with refOverlap it compares the reference
  // keyframe's points this frame tracks with that share (a third of it when
  // urgent) of all its points.
  bool weak = false, very_weak = false;
  if (options_.kf_ref_overlap > 0 && ref_kf_ && num_kfs >= 2) {
    weak = stats_.kf_ref_shared < options_.kf_ref_overlap * stats_.kf_ref_all;
    very_weak = stats_.kf_ref_shared < options_.kf_ref_overlap / 3.0 * stats_.kf_ref_all;
  } else {
    const double ref_ratio = num_kfs < 2 ? 0.4 : 0.75;
    weak = matches_inliers_ < ref_matches * ref_ratio;
    very_weak = matches_inliers_ < ref_matches * 0.25;
  }
  const bool c1a = f.id >= last_kf_frame_id_ + max_frames;
  const bool c1b = f.id >= last_kf_frame_id_ + static_cast<std::uint64_t>(options_.min_frames) && mapping_idle;
  const bool c1c = very_weak || need_close;
  const bool c2 = (weak || need_close) && matches_inliers_ > 15;
  if (!((c1a || c1b || c1c) && c2)) return false;
  return mapping_idle || mapping_queue < 3;
}

void Tracking::add_point_from_depth(Frame& f, const std::shared_ptr<KeyFrame>& kf, std::size_t i) {
  auto mp = map_.create_point(f.unproject_world(i), kf);
  mp->add_observation(kf, i);
  kf->set_map_point(i, mp);
  mp->compute_distinctive_descriptor();
  mp->update_normal_and_depth();
  f.map_points[i] = mp;
}

std::shared_ptr<KeyFrame> Tracking::add_keyframe_in_own_map(const Frame& f) {
  auto kf = map_.create_keyframe(f);
  if (ref_kf_) kf->set_provisional(ref_kf_->provisional());
  attach_motion(kf);
  return kf;
}

std::shared_ptr<KeyFrame> Tracking::create_keyframe(Frame& f) {
  auto kf = add_keyframe_in_own_map(f);
  ref_kf_ = kf;
  // New points from depth: the closest keypoints first, all nearer than the
  // close/far threshold and at least 100 (ORB-SLAM2 CreateNewKeyFrame).
  const auto by_depth = f.keypoints_by_depth();
  int n = 0;
  for (const auto& [d, i] : by_depth) {
    const auto& existing = f.map_points[i];
    if (!existing || existing->num_observations() < 1) {
      add_point_from_depth(f, kf, i);
      f.outlier[i] = 0;
    }
    ++n;
    if (d > cam_->th_depth_m && n > 100) break;
  }
  // Outliers are not handed to the keyframe.
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.outlier[i]) kf->set_map_point(i, nullptr);
  last_kf_frame_id_ = f.id;
  return kf;
}

}  // namespace pvb::slam
