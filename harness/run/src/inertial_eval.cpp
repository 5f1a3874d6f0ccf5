#include "pvb/run/inertial_eval.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include <yaml-cpp/yaml.h>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

namespace pvb::run {
namespace {

constexpr double kInertialDegPerRad = 57.29577951308232;
constexpr std::size_t kTruthColumns = 13;

/// One number of a CSV field; false when it is not one whole number.
bool parse_field(const std::string& s, double* v) {
  char* end = nullptr;
  *v = std::strtod(s.c_str(), &end);
  return !s.empty() && end == s.c_str() + s.size() && std::isfinite(*v);
}

BiasTruth parse_truth_line(const std::vector<std::string>& f, const std::string& path, int line) {
  if (f.size() != kTruthColumns)
    throw IoError(path, std::to_string(f.size()) + " columns, expected " + std::to_string(kTruthColumns),
                  line);
  double v[kTruthColumns];
  for (std::size_t i = 0; i < kTruthColumns; ++i)
    if (!parse_field(f[i], &v[i])) throw IoError(path, "not a number: '" + f[i] + "'", line);
  BiasTruth t;
  t.t_ns = std::strtoll(f[0].c_str(), nullptr, 10);
  t.gyro_radps = Eigen::Vector3d(v[7], v[8], v[9]);
  t.accel_mps2 = Eigen::Vector3d(v[10], v[11], v[12]);
  return t;
}

double seconds_since_ns(std::int64_t t0_ns, std::int64_t t_ns) {
  return static_cast<double>(t_ns - t0_ns) * 1e-9;
}

void push_axes(Axes* a, const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k) (*a)[k].push_back(v[k]);
}

double rms_of(double sum_sq, std::size_t n) { return n ? std::sqrt(sum_sq / static_cast<double>(n)) : 0.0; }

}  // namespace

std::vector<BiasTruth> read_bias_truth(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw IoError(path, "cannot read the IMU truth");
  std::vector<BiasTruth> out;
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (text.empty() || text[0] == '#') continue;
    out.push_back(parse_truth_line(split_ws(text, ","), path, line));
    if (out.size() > 1 && out.back().t_ns < out[out.size() - 2].t_ns)
      throw IoError(path, "readings out of time order", line);
  }
  return out;
}

BiasTruth bias_truth_at(const std::vector<BiasTruth>& truth, std::int64_t t_ns) {
  const auto after = std::lower_bound(truth.begin(), truth.end(), t_ns,
                                      [](const BiasTruth& b, std::int64_t t) { return b.t_ns < t; });
  if (after == truth.begin()) return {t_ns, truth.front().gyro_radps, truth.front().accel_mps2};
  if (after == truth.end()) return {t_ns, truth.back().gyro_radps, truth.back().accel_mps2};
  if (after->t_ns == t_ns) return *after;  // a reading at that time: its own biases, not a blend
  const BiasTruth& a = *(after - 1);
  const BiasTruth& b = *after;
  const double s =
      b.t_ns > a.t_ns ? static_cast<double>(t_ns - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns) : 0.0;
  return {t_ns, a.gyro_radps + s * (b.gyro_radps - a.gyro_radps),
          a.accel_mps2 + s * (b.accel_mps2 - a.accel_mps2)};
}

void keep_frame_ends(const std::vector<BiasTruth>& frame_readings, std::vector<BiasTruth>* kept) {
  if (frame_readings.empty()) return;
  kept->push_back(frame_readings.front());
  if (frame_readings.size() > 1) kept->push_back(frame_readings.back());
}

BiasComparison compare_biases(std::vector<KeyframeBias> keyframes, const std::vector<BiasTruth>& truth,
                              std::int64_t t0_ns, bool has_gyro) {
  std::sort(keyframes.begin(), keyframes.end(),
            [](const KeyframeBias& a, const KeyframeBias& b) { return a.t_ns < b.t_ns; });
  BiasComparison c;
  c.has_gyro = has_gyro;
  double gyro_sq = 0, accel_sq = 0;
  for (const KeyframeBias& k : keyframes) {
    const BiasTruth t = bias_truth_at(truth, k.t_ns);
    c.keyframe_id.push_back(k.id);
    c.t_s.push_back(seconds_since_ns(t0_ns, k.t_ns));
    push_axes(&c.gyro_est_radps, k.bias.gyro_radps);
    push_axes(&c.gyro_true_radps, t.gyro_radps);
    push_axes(&c.accel_est_mps2, k.bias.accel_mps2);
    push_axes(&c.accel_true_mps2, t.accel_mps2);
    c.gyro_final_radps = (k.bias.gyro_radps - t.gyro_radps).norm();
    c.accel_final_mps2 = (k.bias.accel_mps2 - t.accel_mps2).norm();
    gyro_sq += c.gyro_final_radps * c.gyro_final_radps;
    accel_sq += c.accel_final_mps2 * c.accel_final_mps2;
  }
  c.gyro_rms_radps = rms_of(gyro_sq, keyframes.size());
  c.accel_rms_mps2 = rms_of(accel_sq, keyframes.size());
  return c;
}

double gravity_tilt_deg(const Eigen::Vector3d& g_w) {
  if (!(g_w.norm() > 0)) return 0.0;
  return std::acos(std::clamp(-g_w.normalized().z(), -1.0, 1.0)) * kInertialDegPerRad;
}

std::optional<double> gravity_error_at_deg(const eval::Trajectory& gt, const eval::Trajectory& est,
                                           const geom::Vec3d& down_w, const eval::GravityEstimates& estimates,
                                           std::int64_t t_ns) {
  eval::Trajectory one;
  for (const geom::StampedPose& p : est.poses)
    if (p.t_ns >= t_ns) {
      one.poses.push_back(p);
      break;
    }
  if (one.empty() || gt.empty()) return std::nullopt;
  const eval::GravityError g = eval::gravity_error(gt, one, down_w, "", estimates);
  if (g.angle_deg.empty()) return std::nullopt;
  return g.angle_deg.front();
}

slam::WheelCalibration wheels_true(double effective_radius_m, double effective_track_m, double described_radius_m,
                                   double described_track_m, double radius_difference) {
  const double radius = effective_radius_m / described_radius_m, half = 0.5 * radius_difference;
  return {radius * (1 - half), radius * (1 + half), effective_track_m / described_track_m};
}

slam::WheelCalibration read_wheels_true(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw IoError(path, e.what());
  }
  const auto number = [&](const char* key) {
    const YAML::Node n = root[key];
    double v = 0;
    if (!n || !n.IsScalar() || !parse_field(n.as<std::string>(), &v) || !(v > 0))
      throw IoError(path, std::string(key) + ": expected a positive number");
    return v;
  };
  // Radius before track, so that the first bad key is the one named.
  const double effective_radius_m = number("effective_wheel_radius_m");
  const double described_radius_m = number("nominal_wheel_radius_m");
  const double effective_track_m = number("effective_track_m");
  const double described_track_m = number("nominal_track_m");
  double difference = 0;  // written only when the wheels differ
  if (const YAML::Node d = root["radius_difference"]) {
    if (!d.IsScalar() || !parse_field(d.as<std::string>(), &difference) || std::abs(difference) > 1)
      throw IoError(path, "radius_difference: expected a number in [-1, 1]");
  }
  return wheels_true(effective_radius_m, effective_track_m, described_radius_m, described_track_m, difference);
}

std::string wheels_text(const slam::WheelFit& w, const std::optional<slam::WheelCalibration>& truth) {
  const auto x = [](double v, int digits) { return "x" + format_fixed(v, digits); };
  std::string out = "wheel calibration over " + std::to_string(w.intervals) + " keyframe intervals (" +
                    format_fixed(w.rolled_m, 1) + " m rolled, " + format_fixed(w.turned_rad, 1) + " rad turned, " +
                    std::to_string(w.refused) + " refused): left " + x(w.calibration.left_scale, 5) + ", right " +
                    x(w.calibration.right_scale, 5) + (w.radii_known ? "" : " (not yet observed)") + ", track " +
                    x(w.calibration.track_scale, 4) + (w.track_known ? "" : " (not yet observed)");
  if (truth)
    out += "; the robot: " + x(truth->left_scale, 5) + ", " + x(truth->right_scale, 5) + ", track " +
           x(truth->track_scale, 4);
  return out + "\n";
}

InertialReport inertial_report(const slam::MapGravity& g, std::int64_t t0_ns) {
  InertialReport r;
  r.trusted = g.ready;
  if (!g.ready) return r;
  r.trusted_t_s = seconds_since_ns(t0_ns, g.ready_t_ns);
  r.trusted_keyframe = g.ready_keyframe_id;
  r.gravity_tilt_deg = gravity_tilt_deg(g.g_w);
  r.init_rms = g.init_rms;
  return r;
}

}  // namespace pvb::run
