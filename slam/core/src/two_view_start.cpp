#include "pvb/slam/core/two_view_start.hpp"

#include <algorithm>
#include <climits>
#include <cmath>

#include <opencv2/calib3d.hpp>

namespace pvb::slam {

namespace {

double median_of(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// Squared reprojection error of p_c (camera frame) against keypoint k, px^2.
double reprojection_px2(const CameraModel& cam, const Eigen::Vector3d& p_c, const Keypoint& k) {
  const Eigen::Vector2d uv = cam.project(p_c);
  return (uv - Eigen::Vector2d(k.pt.x, k.pt.y)).squaredNorm();
}

/// The essential matrix's inlier matches, triangulated in the first view's
/// frame at unit baseline, and the motion R, t (|t| = 1).
struct UnitTwoView {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  std::vector<IndexMatch> matches;
  std::vector<Eigen::Vector3d> p_ref;
};

UnitTwoView essential_inliers(const Frame& ref, const Frame& cur, const std::vector<IndexMatch>& m) {
  std::vector<cv::Point2d> p1, p2;
  for (const IndexMatch& k : m) {
    p1.emplace_back(ref.keys_un[k.i1].pt.x, ref.keys_un[k.i1].pt.y);
    p2.emplace_back(cur.keys_un[k.i2].pt.x, cur.keys_un[k.i2].pt.y);
  }
  cv::Mat mask;
  cv::setRNGSeed(0);  // deterministic RANSAC
  const cv::Mat E = cv::findEssentialMat(p1, p2, cur.cam->K_cv, cv::RANSAC, 0.999, 1.0, mask);
  UnitTwoView out;
  if (E.rows != 3 || E.cols != 3) return out;
  cv::Mat R, t, points;
  cv::recoverPose(E, p1, p2, cur.cam->K_cv, R, t, 50.0, mask, points);
  for (int r = 0; r < 3; ++r) {
    out.t(r) = t.at<double>(r);
    for (int c = 0; c < 3; ++c) out.R(r, c) = R.at<double>(r, c);
  }
  points.convertTo(points, CV_64F);
  for (int k = 0; k < mask.rows; ++k) {
    const double w = points.at<double>(3, k);
    if (!mask.at<std::uint8_t>(k) || std::abs(w) < 1e-12) continue;
    out.matches.push_back(m[static_cast<std::size_t>(k)]);
    out.p_ref.emplace_back(points.at<double>(0, k) / w, points.at<double>(1, k) / w, points.at<double>(2, k) / w);
  }
  return out;
}

/// Keeps the points in front of both views, within max_px of both
/// keypoints (at their octave); their parallax angles go to `parallax`.
void keep_good_points(const Frame& ref, const Frame& cur, double max_px, UnitTwoView* v, std::vector<double>* parallax) {
  const CameraModel& cam = *cur.cam;
  const Eigen::Vector3d c_cur_in_ref = -v->R.transpose() * v->t;
  std::vector<IndexMatch> kept;
  std::vector<Eigen::Vector3d> pts;
  for (std::size_t k = 0; k < v->matches.size(); ++k) {
    const Eigen::Vector3d& p = v->p_ref[k];
    const Eigen::Vector3d q = v->R * p + v->t;
    if (!(p.z() > 0) || !(q.z() > 0)) continue;
    const Keypoint& k1 = ref.keys_un[v->matches[k].i1];
    const Keypoint& k2 = cur.keys_un[v->matches[k].i2];
    if (reprojection_px2(cam, p, k1) > max_px * max_px * cam.level_sigma2[k1.octave] ||
        reprojection_px2(cam, q, k2) > max_px * max_px * cam.level_sigma2[k2.octave])
      continue;
    const Eigen::Vector3d a = p.normalized(), b = (p - c_cur_in_ref).normalized();
    parallax->push_back(std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180.0 / M_PI);
    kept.push_back(v->matches[k]);
    pts.push_back(p);
  }
  v->matches = std::move(kept);
  v->p_ref = std::move(pts);
}

}  // namespace

std::vector<IndexMatch> search_for_start(const Frame& ref, const Frame& cur, double radius_px) {
  std::vector<IndexMatch> matches;
  std::vector<float> diffs;
  std::vector<int> taken_dist(cur.size(), INT_MAX);
  std::vector<long> taken_by(cur.size(), -1);
  std::vector<std::size_t> around;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const Keypoint& k1 = ref.keys_un[i];
    cur.features_in_area(k1.pt.x, k1.pt.y, radius_px, k1.octave, k1.octave, &around);
    int best = INT_MAX, second = INT_MAX;
    std::size_t best_idx = SIZE_MAX;
    for (const std::size_t j : around) {
      const int d = descriptor_distance(ref.descriptors.ptr<unsigned char>(static_cast<int>(i)),
                                        cur.descriptors.ptr<unsigned char>(static_cast<int>(j)));
      if (d < best) {
        second = best;
        best = d;
        best_idx = j;
      } else if (d < second) {
        second = d;
      }
    }
    if (best_idx == SIZE_MAX || best > kThLow || best >= 0.9 * second || best >= taken_dist[best_idx]) continue;
    if (taken_by[best_idx] >= 0) matches[static_cast<std::size_t>(taken_by[best_idx])].i1 = SIZE_MAX;
    taken_dist[best_idx] = best;
    taken_by[best_idx] = static_cast<long>(matches.size());
    matches.push_back({i, best_idx});
    diffs.push_back(k1.angle - cur.keys_un[best_idx].angle);
  }
  const std::vector<std::uint8_t> ok = orientation_consistent(diffs);
  std::vector<IndexMatch> kept;
  for (std::size_t k = 0; k < matches.size(); ++k)
    if (ok[k] && matches[k].i1 != SIZE_MAX) kept.push_back(matches[k]);
  return kept;
}

std::optional<TwoViewStart> two_view_start(const Frame& ref, const Frame& cur, const TwoViewOptions& o,
                                           std::string* why, TwoViewFailure* failure) {
  const auto fail = [&](TwoViewFailure kind, const std::string& text) {
    *failure = kind;
    *why = text;
    return std::nullopt;
  };
  const std::vector<IndexMatch> m = search_for_start(ref, cur, o.search_radius_px);
  if (static_cast<int>(m.size()) < o.min_points)
    return fail(TwoViewFailure::kFewMatches,
                std::to_string(m.size()) + " matches (need " + std::to_string(o.min_points) + ")");
  UnitTwoView v = essential_inliers(ref, cur, m);
  std::vector<double> parallax;
  keep_good_points(ref, cur, o.max_reprojection_px, &v, &parallax);
  if (static_cast<int>(v.matches.size()) < o.min_points)
    return fail(TwoViewFailure::kNotYet, std::to_string(v.matches.size()) + " of " + std::to_string(m.size()) +
                                             " matches triangulated (need " + std::to_string(o.min_points) + ")");
  TwoViewStart s;
  s.median_parallax_deg = median_of(parallax);
  if (s.median_parallax_deg < o.min_parallax_deg)
    return fail(TwoViewFailure::kNotYet, "median parallax " + std::to_string(s.median_parallax_deg) +
                                             " deg (need " + std::to_string(o.min_parallax_deg) + ")");
  // The scale: measured over triangulated depth, in either view.
  std::vector<double> ratios;
  for (std::size_t k = 0; k < v.matches.size(); ++k) {
    const float d1 = ref.depth_m[v.matches[k].i1], d2 = cur.depth_m[v.matches[k].i2];
    if (d1 > 0) ratios.push_back(d1 / v.p_ref[k].z());
    if (d2 > 0) ratios.push_back(d2 / (v.R * v.p_ref[k] + v.t).z());
  }
  s.scale_points = static_cast<int>(ratios.size());
  if (s.scale_points < o.min_scale_points)
    return fail(TwoViewFailure::kNotYet, std::to_string(s.scale_points) + " measured depths among the points (need " +
                                             std::to_string(o.min_scale_points) + ")");
  const double scale = median_of(ratios);
  std::vector<double> deviation;
  for (const double r : ratios) deviation.push_back(std::abs(r - scale));
  s.scale_spread = median_of(deviation) / scale;
  if (s.scale_spread > o.max_scale_spread)
    return fail(TwoViewFailure::kNotYet, "the measured depths disagree on the scale (spread " +
                                             std::to_string(s.scale_spread) + ")");
  s.T_cur_ref = geom::make_se3(v.R, scale * v.t);
  s.matches = std::move(v.matches);
  for (Eigen::Vector3d& p : v.p_ref) s.p_ref_m.push_back(scale * p);
  return s;
}

}  // namespace pvb::slam
