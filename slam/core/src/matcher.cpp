#include "pvb/slam/core/matcher.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace pvb::slam {
namespace {

// The best and second-best descriptor distances seen so far, with the
// candidate (and its pyramid level) that gave the best.
struct BestTwo {
  int best = INT_MAX, second = INT_MAX;
  int best_level = -1, second_level = -1;
  std::size_t best_idx = 0;
  void offer(int d, std::size_t j, int level = -1) {
    if (d < best) {
      second = best;
      second_level = best_level;
      best = d;
      best_level = level;
      best_idx = j;
    } else if (d < second) {
      second = d;
      second_level = level;
    }
  }
};

const unsigned char* desc_row(const cv::Mat& d, std::size_t i) { return d.ptr<unsigned char>(static_cast<int>(i)); }

int angle_bin(float diff_deg) {
  float rot = diff_deg;
  while (rot < 0) rot += 360.0f;
  while (rot >= 360.0f) rot -= 360.0f;
  const int bin = static_cast<int>(rot * kHistoLength / 360.0f);
  return std::clamp(bin, 0, kHistoLength - 1);
}

}  // namespace

std::vector<std::uint8_t> orientation_consistent(const std::vector<float>& angle_diff_deg) {
  std::array<int, kHistoLength> histo{};
  for (float d : angle_diff_deg) ++histo[angle_bin(d)];
  // the three largest bins (ties: lower bin first); 2nd and 3rd need >= 10 % of the first
  std::array<int, kHistoLength> order{};
  for (int i = 0; i < kHistoLength; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return histo[a] > histo[b]; });
  std::array<bool, kHistoLength> keep{};
  keep[order[0]] = histo[order[0]] > 0;
  for (int k = 1; k < 3; ++k) keep[order[k]] = histo[order[k]] > 0 && histo[order[k]] >= 0.1 * histo[order[0]];
  std::vector<std::uint8_t> ok(angle_diff_deg.size());
  for (std::size_t i = 0; i < ok.size(); ++i) ok[i] = keep[angle_bin(angle_diff_deg[i])];
  return ok;
}

std::vector<IndexMatch> search_by_projection(Frame& cur, const Frame& last, double th, double ratio) {
  const CameraModel& cam = *cur.cam;
  const geom::SE3d& T_c_w = cur.T_c_w;
  // Where the current camera is, seen from the last one: moving forward or
  // backward restricts the pyramid levels to search (ORB-SLAM2).
  const Eigen::Vector3d t_l_c = last.T_c_w * cur.camera_center_w();
  const double baseline_m = cam.K.bf / cam.K.fx;
  const bool forward = t_l_c.z() > baseline_m;
  const bool backward = -t_l_c.z() > baseline_m;

  std::vector<IndexMatch> matches;
  std::vector<float> diffs;
  std::vector<std::size_t> cands;
  for (std::size_t i = 0; i < last.size(); ++i) {
    const auto& mp = last.map_points[i];
    if (!mp || last.outlier[i] || mp->bad()) continue;
    const Eigen::Vector3d p_c = T_c_w * mp->p_w();
    if (p_c.z() <= 0) continue;
    const Eigen::Vector2d uv = cam.project(p_c);
    if (!cam.in_bounds(uv.x(), uv.y())) continue;
    const int last_octave = last.keys_un[i].octave;
    const double radius = th * cam.scale[last_octave];
    if (forward) cur.features_in_area(uv.x(), uv.y(), radius, last_octave, -1, &cands);
    else if (backward) cur.features_in_area(uv.x(), uv.y(), radius, 0, last_octave, &cands);
    else cur.features_in_area(uv.x(), uv.y(), radius, std::max(0, last_octave - 1), last_octave + 1, &cands);
    if (cands.empty()) continue;
    const double ur = uv.x() - cam.K.bf / p_c.z();
    const unsigned char* d_mp = mp->descriptor() ? mp->descriptor() : desc_row(last.descriptors, i);
    BestTwo b;
    for (std::size_t j : cands) {
      if (cur.map_points[j] && cur.map_points[j]->num_observations() > 0) continue;
      if (cur.u_right[j] > 0 && std::abs(ur - cur.u_right[j]) > radius) continue;
      b.offer(descriptor_distance(d_mp, desc_row(cur.descriptors, j)), j);
    }
    const int best = b.best, second = b.second;
    const std::size_t best_idx = b.best_idx;
    if (best > kThHigh) continue;
    if (second != INT_MAX && best >= ratio * second) continue;
    if (cur.map_points[best_idx]) continue;  // taken by another point of this search
    cur.map_points[best_idx] = mp;
    matches.push_back({i, best_idx});
    diffs.push_back(last.keys_un[i].angle - cur.keys_un[best_idx].angle);
  }
  const std::vector<std::uint8_t> ok = orientation_consistent(diffs);
  std::vector<IndexMatch> kept;
  for (std::size_t k = 0; k < matches.size(); ++k) {
    if (ok[k]) kept.push_back(matches[k]);
    else cur.map_points[matches[k].i2] = nullptr;
  }
  return kept;
}

bool project_in_frustum(const Frame& frame, const std::shared_ptr<MapPoint>& mp, ProjectedPoint* out) {
  const CameraModel& cam = *frame.cam;
  const Eigen::Vector3d p_c = frame.T_c_w * mp->p_w();
  if (p_c.z() <= 0) return false;
  const Eigen::Vector2d uv = cam.project(p_c);
  if (!cam.in_bounds(uv.x(), uv.y())) return false;
  const Eigen::Vector3d po = mp->p_w() - frame.camera_center_w();
  const double dist = po.norm();
  if (dist < mp->min_distance() || dist > mp->max_distance()) return false;
  const double view_cos = po.dot(mp->normal()) / dist;
  if (view_cos < 0.5) return false;
  out->mp = mp;
  out->u = uv.x();
  out->v = uv.y();
  out->u_right = uv.x() - cam.K.bf / p_c.z();
  out->level = cam.predict_scale(dist, mp->max_distance());
  out->view_cos = view_cos;
  return true;
}

int search_local_points(Frame& cur, const std::vector<ProjectedPoint>& points, double th) {
  const CameraModel& cam = *cur.cam;
  constexpr double kRatio = 0.8;
  int n = 0;
  std::vector<std::size_t> cands;
  for (const ProjectedPoint& p : points) {
    if (p.mp->bad()) continue;
    const double r = th * (p.view_cos > 0.998 ? 2.5 : 4.0) * cam.scale[p.level];
    cur.features_in_area(p.u, p.v, r, p.level - 1, p.level, &cands);
    if (cands.empty()) continue;
    const unsigned char* d_mp = p.mp->descriptor();
    BestTwo b;
    for (std::size_t j : cands) {
      if (cur.map_points[j] && cur.map_points[j]->num_observations() > 0) continue;
      if (cur.u_right[j] > 0 && std::abs(p.u_right - cur.u_right[j]) > r) continue;
      b.offer(descriptor_distance(d_mp, desc_row(cur.descriptors, j)), j, cur.keys_un[j].octave);
    }
    if (b.best > kThHigh) continue;
    if (b.best_level == b.second_level && b.best > kRatio * b.second) continue;
    const std::size_t best_idx = b.best_idx;
    cur.map_points[best_idx] = p.mp;
    ++n;
  }
  return n;
}

namespace {

/// Keyframe-to-frame matches as ORB-SLAM2 keeps them: one per frame
/// keypoint (the nearest wins), then the orientation check.
class KeyFrameMatches {
 public:
  KeyFrameMatches(const Frame& kff, Frame& cur, int max_distance, double ratio)
      : kff_(kff), cur_(cur), max_distance_(max_distance), ratio_(ratio),
        taken_dist_(cur.size(), INT_MAX), taken_by_(cur.size(), -1) {}

  /// Keyframe keypoint i (with a good map point) against the frame keypoints `js` without one.
  template <typename Indices>
  void offer(std::size_t i, const Indices& js) {
    const unsigned char* d_mp = desc_row(kff_.descriptors, i);
    BestTwo b;
    for (std::size_t j : js)
      if (!cur_.map_points[j]) b.offer(descriptor_distance(d_mp, desc_row(cur_.descriptors, j)), j);
    const std::size_t j = b.best_idx;
    if (b.best > max_distance_ || (b.second != INT_MAX && b.best >= ratio_ * b.second)) return;
    if (b.best >= taken_dist_[j]) return;
    if (taken_by_[j] >= 0) matches_[static_cast<std::size_t>(taken_by_[j])].i1 = SIZE_MAX;
    taken_dist_[j] = b.best;
    taken_by_[j] = static_cast<long>(matches_.size());
    matches_.push_back({i, j});
    diffs_.push_back(kff_.keys_un[i].angle - cur_.keys_un[j].angle);
  }

  /// Sets cur's map points of the kept matches; returns how many.
  int apply() {
    const std::vector<std::uint8_t> ok = orientation_consistent(diffs_);
    int n = 0;
    for (std::size_t k = 0; k < matches_.size(); ++k) {
      if (!ok[k] || matches_[k].i1 == SIZE_MAX) continue;
      cur_.map_points[matches_[k].i2] = kff_.map_points[matches_[k].i1];
      ++n;
    }
    return n;
  }

 private:
  const Frame& kff_;
  Frame& cur_;
  int max_distance_;
  double ratio_;
  std::vector<IndexMatch> matches_;
  std::vector<float> diffs_;
  std::vector<int> taken_dist_;
  std::vector<long> taken_by_;
};

/// 0, 1, ..., n - 1 without storing them.
struct AllIndices {
  std::size_t n;
  struct It {
    std::size_t v;
    std::size_t operator*() const { return v; }
    It& operator++() { return ++v, *this; }
    bool operator!=(const It& o) const { return v != o.v; }
  };
  It begin() const { return {0}; }
  It end() const { return {n}; }
};

}  // namespace

int search_keyframe_bruteforce(const KeyFrame& kf, Frame& cur, int max_distance, double ratio) {
  const Frame& kff = kf.frame();
  KeyFrameMatches m(kff, cur, max_distance, ratio);
  for (std::size_t i = 0; i < kff.size(); ++i)
    if (kff.map_points[i] && !kff.map_points[i]->bad()) m.offer(i, AllIndices{cur.size()});
  return m.apply();
}

int search_keyframe_by_bow(const KeyFrame& kf, Frame& cur, const place::FeatureVector& cur_features,
                           int max_distance, double ratio) {
  const Frame& kff = kf.frame();
  KeyFrameMatches m(kff, cur, max_distance, ratio);
  const place::FeatureVector& kf_features = kf.features_by_node();
  auto a = kf_features.begin();
  auto b = cur_features.begin();
  while (a != kf_features.end() && b != cur_features.end()) {
    if (a->first < b->first) {
      ++a;
    } else if (b->first < a->first) {
      ++b;
    } else {
      for (std::uint32_t i : a->second)
        if (kff.map_points[i] && !kff.map_points[i]->bad()) m.offer(i, b->second);
      ++a;
      ++b;
    }
  }
  return m.apply();
}

int fuse(Map& map, const std::shared_ptr<KeyFrame>& kf, const std::vector<std::shared_ptr<MapPoint>>& points, double th,
         FusePolicy policy) {
  const Frame& f = kf->frame();
  const CameraModel& cam = *f.cam;
  const Eigen::Vector3d center = f.camera_center_w();
  int fused = 0;
  std::vector<std::shared_ptr<MapPoint>> replaced;
  for (const auto& mp : points) {
    if (!mp || mp->bad() || mp->index_in(kf->id()) >= 0) continue;
    const Eigen::Vector3d p_c = f.T_c_w * mp->p_w();
    if (p_c.z() <= 0) continue;
    const Eigen::Vector2d uv = cam.project(p_c);
    if (!cam.in_bounds(uv.x(), uv.y())) continue;
    const double ur = uv.x() - cam.K.bf / p_c.z();
    const Eigen::Vector3d po = mp->p_w() - center;
    const double dist = po.norm();
    if (dist < mp->min_distance() || dist > mp->max_distance()) continue;
    if (po.dot(mp->normal()) < 0.5 * dist) continue;
    const int level = cam.predict_scale(dist, mp->max_distance());
    const double radius = th * cam.scale[level];
    const std::vector<std::size_t> cands = f.features_in_area(uv.x(), uv.y(), radius);
    const unsigned char* d_mp = mp->descriptor();
    int best = INT_MAX;
    std::size_t best_idx = 0;
    for (std::size_t j : cands) {
      const Keypoint& k = f.keys_un[j];
      if (k.octave < level - 1 || k.octave > level) continue;
      const double ex = uv.x() - k.pt.x, ey = uv.y() - k.pt.y;
      const double inv_s2 = cam.inv_level_sigma2[k.octave];
      if (f.u_right[j] >= 0) {
        const double er = ur - f.u_right[j];
        if ((ex * ex + ey * ey + er * er) * inv_s2 > 7.8) continue;
      } else if ((ex * ex + ey * ey) * inv_s2 > 5.99) {
        continue;
      }
      const int d = descriptor_distance(d_mp, desc_row(f.descriptors, j));
      if (d < best) {
        best = d;
        best_idx = j;
      }
    }
    if (best > kThLow) continue;
    const auto existing = f.map_points[best_idx];
    if (existing && !existing->bad()) {
      if (existing == mp) continue;
      // Both kept before the replacement: `points` may be a keyframe's own
      // list, whose slot `mp` refers to the replacement rewrites.
      replaced.push_back(existing);
      replaced.push_back(mp);
      if (policy == FusePolicy::kIncomingWins) existing->replace(mp, existing);
      else if (existing->num_observations() > mp->num_observations()) mp->replace(existing, mp);
      else existing->replace(mp, existing);
    } else {
      mp->add_observation(kf, best_idx);
      kf->set_map_point(best_idx, mp);
    }
    ++fused;
  }
  map.remove_bad_among(replaced);  // the only points fusing makes bad
  return fused;
}

std::vector<IndexMatch> search_for_triangulation(const KeyFrame& kf1, const KeyFrame& kf2) {
  const Frame& f1 = kf1.frame();
  const Frame& f2 = kf2.frame();
  const CameraModel& cam = *f1.cam;
  // F12 maps points of image 2 to epipolar lines in image 1: x1^T F12 x2 = 0.
  const geom::SE3d T_1_2 = f1.T_c_w * f2.T_c_w.inverse();
  const Eigen::Matrix3d K = (Eigen::Matrix3d() << cam.K.fx, 0, cam.K.cx, 0, cam.K.fy, cam.K.cy, 0, 0, 1).finished();
  const Eigen::Matrix3d Kinv = K.inverse();
  const Eigen::Matrix3d F12 = Kinv.transpose() * geom::skew(T_1_2.translation()) * T_1_2.linear() * Kinv;
  // epipole of camera 1 in image 2
  const Eigen::Vector3d c1_in_2 = f2.T_c_w * f1.camera_center_w();
  const Eigen::Vector2d ep2 = cam.project(c1_in_2);

  std::vector<IndexMatch> matches;
  std::vector<float> diffs;
  std::vector<int> taken_dist(f2.size(), INT_MAX);
  std::vector<long> taken_by(f2.size(), -1);
  for (std::size_t i = 0; i < f1.size(); ++i) {
    if (f1.map_points[i]) continue;
    const Keypoint& k1 = f1.keys_un[i];
    const Eigen::Vector3d x1(k1.pt.x, k1.pt.y, 1.0);
    const Eigen::RowVector3d l2 = x1.transpose() * F12;  // line in image 2
    const double den = l2(0) * l2(0) + l2(1) * l2(1);
    if (den < 1e-20) continue;
    int best = kThLow + 1;
    std::size_t best_idx = SIZE_MAX;
    for (std::size_t j = 0; j < f2.size(); ++j) {
      if (f2.map_points[j]) continue;
      const Keypoint& k2 = f2.keys_un[j];
      const double num = l2(0) * k2.pt.x + l2(1) * k2.pt.y + l2(2);
      if (num * num / den >= 3.84 * cam.level_sigma2[k2.octave]) continue;
      const int d = descriptor_distance(desc_row(f1.descriptors, i), desc_row(f2.descriptors, j));
      if (d >= best) continue;
      if (c1_in_2.z() > 0) {
        const double ex = ep2.x() - k2.pt.x, ey = ep2.y() - k2.pt.y;
        if (ex * ex + ey * ey < 100 * cam.scale[k2.octave]) continue;
      }
      best = d;
      best_idx = j;
    }
    if (best_idx == SIZE_MAX || best >= taken_dist[best_idx]) continue;
    if (taken_by[best_idx] >= 0) matches[static_cast<std::size_t>(taken_by[best_idx])].i1 = SIZE_MAX;
    taken_dist[best_idx] = best;
    taken_by[best_idx] = static_cast<long>(matches.size());
    matches.push_back({i, best_idx});
    diffs.push_back(k1.angle - f2.keys_un[best_idx].angle);
  }
  const std::vector<std::uint8_t> ok = orientation_consistent(diffs);
  std::vector<IndexMatch> kept;
  for (std::size_t k = 0; k < matches.size(); ++k)
    if (ok[k] && matches[k].i1 != SIZE_MAX) kept.push_back(matches[k]);
  return kept;
}

int pnp_ransac_on_matches(Frame& cur, int min_inliers) {
  std::vector<cv::Point3d> obj;
  std::vector<cv::Point2d> img;
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < cur.size(); ++i) {
    if (!cur.map_points[i]) continue;
    const Eigen::Vector3d& p = cur.map_points[i]->p_w();
    obj.emplace_back(p.x(), p.y(), p.z());
    img.emplace_back(cur.keys_un[i].pt.x, cur.keys_un[i].pt.y);
    idx.push_back(i);
  }
  if (obj.size() < 4) return 0;
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  cv::setRNGSeed(0);  // deterministic RANSAC
  const bool solved = cv::solvePnPRansac(obj, img, cur.cam->K_cv, cv::noArray(), rvec, tvec, false, 300, 4.0f, 0.99,
                                         inliers, cv::SOLVEPNP_EPNP);
  const int n = solved ? static_cast<int>(inliers.size()) : 0;
  if (n == 0 || n < min_inliers) return n;
  cv::Mat R_cv;
  cv::Rodrigues(rvec, R_cv);
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  cv::cv2eigen(R_cv, R);
  cv::cv2eigen(tvec, t);
  cur.T_c_w = geom::make_se3(R, t);
  std::vector<std::uint8_t> keep(idx.size(), 0);
  for (int i : inliers) keep[static_cast<std::size_t>(i)] = 1;
  for (std::size_t q = 0; q < idx.size(); ++q)
    if (!keep[q]) cur.map_points[idx[q]] = nullptr;
  return n;
}

}  // namespace pvb::slam
