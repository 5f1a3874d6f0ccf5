#include "pvb/eval/gravity.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <iterator>

#include "pvb/common/text.hpp"
#include "pvb/eval/associate.hpp"
#include "pvb/eval/metrics.hpp"
#include "pvb/geometry/time.hpp"

namespace pvb::eval {
namespace {

constexpr double kDegPerRad = 57.29577951308232;

double seconds_between(std::int64_t from_ns, std::int64_t to_ns) {
  return static_cast<double>(to_ns - from_ns) * 1e-9;
}

/// The estimate held at t_ns: the last entry made at or before it, less
/// a millisecond (trajectory files keep microseconds).
const geom::Vec3d* held_at(const GravityEstimates& estimates, std::int64_t t_ns) {
  constexpr std::int64_t kTolNs = 1000000;
  auto it = estimates.upper_bound(t_ns + kTolNs);
  if (it == estimates.begin()) return nullptr;
  return &std::prev(it)->second;
}

geom::Vec3d estimated_down(const GravityEstimates& estimates, std::int64_t t_ns) {
  const geom::Vec3d* g = held_at(estimates, t_ns);
  if (g != nullptr && g->norm() > 0) return g->normalized();
  return geom::Vec3d(0, 0, -1);
}

int sign_of(double v) { return v > 0 ? 1 : v < 0 ? -1 : 0; }

std::string json_list(const std::vector<double>& v) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + json_number(v[i], 6);
  return out + "]";
}

}  // namespace

void record_gravity(GravityEstimates* estimates, std::int64_t t_ns, const std::optional<geom::Vec3d>& g_w) {
  const geom::Vec3d g = g_w.value_or(geom::Vec3d::Zero());
  const geom::Vec3d* held = held_at(*estimates, t_ns);
  const geom::Vec3d none = geom::Vec3d::Zero();
  if (g != (held != nullptr ? *held : none)) (*estimates)[t_ns] = g;
}

GravityError gravity_error(const Trajectory& gt, const Trajectory& est, const geom::Vec3d& down_w,
                           const std::string& map_frame, const GravityEstimates& estimates) {
  GravityError g;
  g.map_frame = map_frame;
  const geom::Vec3d down = down_w.normalized();
  const std::vector<IndexPair> pairs = associate(gt, est);
  for (const IndexPair& p : pairs) {
    const geom::Mat3d R_c_w = gt.poses[p.gt].T_w_c.linear().transpose();
    const geom::Mat3d R_c_map = est.poses[p.est].T_w_c.linear().transpose();
    const geom::Vec3d true_c = R_c_w * down, est_c = R_c_map * estimated_down(estimates, est.poses[p.est].t_ns);
    const double angle = std::atan2(true_c.cross(est_c).norm(), true_c.dot(est_c));
    g.t_s.push_back(seconds_between(est.poses[pairs.front().est].t_ns, est.poses[p.est].t_ns));
    g.angle_deg.push_back(angle * kDegPerRad);
  }
  g.median_deg = percentile(g.angle_deg, 0.5);
  g.p95_deg = percentile(g.angle_deg, 0.95);
  g.final_deg = g.angle_deg.empty() ? 0.0 : g.angle_deg.back();
  return g;
}

std::pair<double, double> pitch_roll_error_deg(const geom::Mat3d& R_w_c_true, const geom::Mat3d& R_w_c_est) {
  const Eigen::AngleAxisd err(geom::Mat3d(R_w_c_true.transpose() * R_w_c_est));
  const geom::Vec3d w = err.angle() * err.axis();
  return {w.x() * kDegPerRad, w.z() * kDegPerRad};
}

double slope_per_index(const std::vector<double>& v) {
  const std::size_t n = v.size();
  if (n < 2) return 0.0;
  const double mean_i = 0.5 * static_cast<double>(n - 1);
  const double mean_v = mean_of(v);
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double di = static_cast<double>(i) - mean_i;
    sxy += di * (v[i] - mean_v);
    sxx += di * di;
  }
  return sxy / sxx;
}

TiltDrift tilt_drift(const Trajectory& gt, const Trajectory& keyframes, const Sim3Transform& alignment) {
  TiltDrift t;
  const std::vector<IndexPair> pairs = associate(gt, keyframes);
  for (const IndexPair& p : pairs) {
    const geom::SE3d T_w_c_est = alignment.apply(keyframes.poses[p.est].T_w_c);
    const auto [pitch, roll] = pitch_roll_error_deg(gt.poses[p.gt].T_w_c.linear(), T_w_c_est.linear());
    t.t_s.push_back(seconds_between(keyframes.poses[pairs.front().est].t_ns, keyframes.poses[p.est].t_ns));
    t.pitch_deg.push_back(pitch);
    t.roll_deg.push_back(roll);
  }
  t.pitch_mean_deg = mean_of(t.pitch_deg);
  t.roll_mean_deg = mean_of(t.roll_deg);
  t.pitch_slope_deg_per_kf = slope_per_index(t.pitch_deg);
  t.roll_slope_deg_per_kf = slope_per_index(t.roll_deg);
  t.pitch_slope_sign = sign_of(t.pitch_slope_deg_per_kf);
  t.roll_slope_sign = sign_of(t.roll_slope_deg_per_kf);
  return t;
}

std::string gravity_json(const GravityError& g) {
  return "{\"map_frame\": " + json_string(g.map_frame) + ", \"frames\": " + std::to_string(g.angle_deg.size()) +
         ", \"median_deg\": " + json_number(g.median_deg, 6) + ", \"p95_deg\": " + json_number(g.p95_deg, 6) +
         ", \"final_deg\": " + json_number(g.final_deg, 6) + ", \"t_s\": " + json_list(g.t_s) +
         ", \"angle_deg\": " + json_list(g.angle_deg) + "}";
}

std::string tilt_json(const TiltDrift& t) {
  return "{\"keyframes\": " + std::to_string(t.pitch_deg.size()) +
         ", \"pitch_mean_deg\": " + json_number(t.pitch_mean_deg, 6) +
         ", \"pitch_slope_deg_per_keyframe\": " + json_number(t.pitch_slope_deg_per_kf, 6) +
         ", \"pitch_slope_sign\": " + std::to_string(t.pitch_slope_sign) +
         ", \"roll_mean_deg\": " + json_number(t.roll_mean_deg, 6) +
         ", \"roll_slope_deg_per_keyframe\": " + json_number(t.roll_slope_deg_per_kf, 6) +
         ", \"roll_slope_sign\": " + std::to_string(t.roll_slope_sign) + ", \"t_s\": " + json_list(t.t_s) +
         ", \"pitch_deg\": " + json_list(t.pitch_deg) + ", \"roll_deg\": " + json_list(t.roll_deg) + "}";
}

}  // namespace pvb::eval
