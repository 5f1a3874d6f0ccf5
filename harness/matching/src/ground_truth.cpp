#include "pvb/harness/matching/ground_truth.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/image_file.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/slam/core/settings.hpp"

namespace pvb::harness {

Eigen::Matrix3d load_homography(const std::string& path) {
  const std::string text = read_file(path);
  std::istringstream in(text);
  Eigen::Matrix3d H;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (!(in >> H(r, c)) || !std::isfinite(H(r, c)))
        throw IoError(path, "expected a 3x3 homography (nine finite numbers)");
  // Scale-free test: |det H| against the cube of its size (H and kH are the same map).
  const double size = H.norm();
  if (!(std::abs(H.determinant()) > 1e-12 * size * size * size))
    throw IoError(
        path, "the homography is singular (determinant 0 at its scale); expected an invertible 3x3 matrix");
  return H;
}

std::vector<MatchLabel> label_by_homography(const std::vector<slam::PointMatch>& m, const Eigen::Matrix3d& H,
                                            double threshold_px) {
  std::vector<MatchLabel> out(m.size(), MatchLabel::kWrong);
  for (size_t i = 0; i < m.size(); ++i) {
    const Eigen::Vector3d h = H * m[i].p1.homogeneous();
    if (!(std::abs(h.z()) > 1e-12)) continue;
    if ((h.hnormalized() - m[i].p2).norm() <= threshold_px) out[i] = MatchLabel::kCorrect;
  }
  return out;
}

CameraSettings load_camera_settings(const std::string& path) {
  const slam::Settings settings = slam::read_settings(path);
  CameraSettings s;
  s.K = settings.K;
  if (settings.has_distortion())
    s.dist_coeffs = (cv::Mat_<double>(1, 5) << settings.k1, settings.k2, settings.p1, settings.p2, settings.k3);
  s.depth_map_factor = settings.depth_map_factor;
  return s;
}

cv::Mat load_depth_m(const std::string& path, double depth_map_factor) {
  const cv::Mat raw = dataset::read_image(path, cv::IMREAD_UNCHANGED, "depth image");
  if (raw.channels() != 1 || (raw.depth() != CV_16U && raw.depth() != CV_32F))
    throw IoError(path, "expected a single-channel 16-bit (or float) depth image");
  cv::Mat d;
  raw.convertTo(d, CV_32F, raw.depth() == CV_16U ? 1.0 / depth_map_factor : 1.0);
  cv::Mat valid = d > 0;  // false for NaN
  valid &= d < std::numeric_limits<float>::infinity();
  if (cv::countNonZero(valid) == 0)
    throw IoError(path,
                  "depth image holds no valid depth (every pixel is 0 or not finite); expected depths > 0");
  return d;
}

geom::SE3d parse_tum_pose(const std::string& text, const std::string& what) {
  const std::vector<std::string> f = split_ws(text);
  double v[7];
  bool ok = f.size() == 7;
  for (size_t i = 0; ok && i < 7; ++i) {
    char* end = nullptr;
    v[i] = std::strtod(f[i].c_str(), &end);
    ok = end && *end == '\0' && std::isfinite(v[i]);
  }
  if (!ok) throw ConfigError("<command line>", what, "\"tx ty tz qx qy qz qw\" or FILE@TIMESTAMP", text);
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (q.norm() < 1e-6) throw ConfigError("<command line>", what, "a non-zero quaternion", text);
  return geom::make_se3(q, Eigen::Vector3d(v[0], v[1], v[2]));
}

geom::SE3d tum_pose_at(const std::string& path, double t_s, double max_gap_s) {
  const std::optional<std::int64_t> t_checked_ns = geom::checked_seconds_to_ns(t_s);
  const std::optional<std::int64_t> gap_checked_ns = geom::checked_seconds_to_ns(max_gap_s);
  if (!t_checked_ns || !gap_checked_ns || *gap_checked_ns < 0)
    throw IoError(path, "pose wanted at t = " + std::to_string(t_s) + " s within " +
                            std::to_string(max_gap_s) + " s: expected times of at most 9e9 s");
  const eval::Trajectory gt = eval::read_tum(path);
  const std::int64_t t_ns = *t_checked_ns;
  const std::int64_t max_gap_ns = *gap_checked_ns;
  const auto& p = gt.poses;
  const auto after = std::lower_bound(p.begin(), p.end(), t_ns,
                                      [](const geom::StampedPose& a, std::int64_t t) { return a.t_ns < t; });
  if (after != p.end() && after->t_ns == t_ns) return after->T_w_c;
  if (after == p.begin()) {
    if (after->t_ns - t_ns <= max_gap_ns) return after->T_w_c;
  } else if (after == p.end()) {
    if (t_ns - p.back().t_ns <= max_gap_ns) return p.back().T_w_c;
  } else {
    const auto before = after - 1;
    if (std::min(after->t_ns - t_ns, t_ns - before->t_ns) <= max_gap_ns) {
      // linear in position, slerp in rotation
      const double a = static_cast<double>(t_ns - before->t_ns) / static_cast<double>(after->t_ns - before->t_ns);
      const Eigen::Quaterniond q0(before->T_w_c.linear()), q1(after->T_w_c.linear());
      return geom::make_se3(q0.slerp(a, q1),
                            (1 - a) * before->T_w_c.translation() + a * after->T_w_c.translation());
    }
  }
  std::ostringstream msg;
  msg.precision(17);
  msg << "no ground-truth pose within " << max_gap_s << " s of t = " << t_s;
  throw IoError(path, msg.str());
}

std::vector<slam::PointMatch> undistort_matches(const std::vector<slam::PointMatch>& raw,
                                                const geom::PinholeIntrinsics& K, const cv::Mat& dist) {
  if (dist.empty() || raw.empty()) return raw;
  std::vector<cv::Point2d> a, b, ua, ub;
  for (const auto& m : raw) {
    a.emplace_back(m.p1.x(), m.p1.y());
    b.emplace_back(m.p2.x(), m.p2.y());
  }
  cv::Mat Kcv = (cv::Mat_<double>(3, 3) << K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  cv::undistortPoints(a, ua, Kcv, dist, cv::noArray(), Kcv);
  cv::undistortPoints(b, ub, Kcv, dist, cv::noArray(), Kcv);
  std::vector<slam::PointMatch> out(raw.size());
  for (size_t i = 0; i < raw.size(); ++i) out[i] = {{ua[i].x, ua[i].y}, {ub[i].x, ub[i].y}};
  return out;
}

namespace {
/// Depth at the pixel nearest to p, 0 when outside or invalid.
float depth_at(const cv::Mat& d, const Eigen::Vector2d& p) {
  const int u = static_cast<int>(std::lround(p.x())), v = static_cast<int>(std::lround(p.y()));
  if (u < 0 || v < 0 || u >= d.cols || v >= d.rows) return 0.0f;
  const float z = d.at<float>(v, u);
  return std::isfinite(z) && z > 0 ? z : 0.0f;
}
}  // namespace

std::vector<MatchLabel> label_by_rgbd(const std::vector<slam::PointMatch>& raw,
                                      const std::vector<slam::PointMatch>& undist, const RgbdGroundTruth& gt) {
  std::vector<MatchLabel> out(raw.size(), MatchLabel::kUnknown);
  for (size_t i = 0; i < raw.size(); ++i) {
    const float z1 = depth_at(gt.depth1_m, raw[i].p1);
    if (z1 <= 0) continue;
    const Eigen::Vector3d P_c1 = gt.K.unproject(undist[i].p1.x(), undist[i].p1.y(), z1);
    const Eigen::Vector3d P_c2 = gt.T_c2_c1 * P_c1;
    out[i] = MatchLabel::kWrong;
    const auto uv = gt.K.project(P_c2);
    if (!uv || (*uv - undist[i].p2).norm() > gt.threshold_px) continue;
    const float z2 = depth_at(gt.depth2_m, raw[i].p2);
    if (z2 > 0 && std::abs(P_c2.z() - z2) > gt.depth_tol_rel * P_c2.z() + gt.depth_tol_abs_m) continue;
    out[i] = MatchLabel::kCorrect;
  }
  return out;
}

}  // namespace pvb::harness
