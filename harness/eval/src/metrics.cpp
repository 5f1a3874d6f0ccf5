#include "pvb/eval/metrics.hpp"

#include <algorithm>
#include <cmath>

#include "pvb/common/error.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/geometry/angles.hpp"
#include "pvb/geometry/time.hpp"

namespace pvb::eval {
namespace {
using geom::kRadToDeg;

/// Index of the element of sorted `v` closest to x; the lower one on a tie.
std::size_t closest_index(const std::vector<double>& v, double x) {
  const auto it = std::lower_bound(v.begin(), v.end(), x);
  if (it == v.begin()) return 0;
  if (it == v.end()) return v.size() - 1;
  const std::size_t hi = static_cast<std::size_t>(it - v.begin());
  return (x - v[hi - 1] <= v[hi] - x) ? hi - 1 : hi;
}
}  // namespace

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = std::clamp(p, 0.0, 1.0) * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

double mean_of(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

Stats compute_stats(const std::vector<double>& values) {
  Stats s;
  s.count = values.size();
  if (values.empty()) return s;
  const double n = static_cast<double>(values.size());
  double sum = 0.0, sum_sq = 0.0;
  for (double v : values) {
    sum += v;
    sum_sq += v * v;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  double var = 0.0;
  for (double v : values) var += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(var / n);
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  s.min = sorted.front();
  s.max = sorted.back();
  const std::size_t mid = sorted.size() / 2;
  s.median = sorted.size() % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
  return s;
}

AxisStats compute_axis_stats(const std::vector<geom::Vec3d>& values) {
  AxisStats s;
  s.count = values.size();
  if (values.empty()) return s;
  for (const geom::Vec3d& v : values) s.mean += v;
  s.mean /= static_cast<double>(values.size());
  geom::Vec3d var = geom::Vec3d::Zero();
  for (const geom::Vec3d& v : values) var += (v - s.mean).cwiseAbs2();
  s.std = (var / static_cast<double>(values.size())).cwiseSqrt();
  return s;
}

std::vector<double> ate_errors_m(const std::vector<geom::SE3d>& est, const std::vector<geom::SE3d>& gt) {
  if (est.size() != gt.size()) throw EvalError("ATE: pose lists differ in size");
  std::vector<double> out;
  out.reserve(est.size());
  for (std::size_t i = 0; i < est.size(); ++i) out.push_back((gt[i].translation() - est[i].translation()).norm());
  return out;
}

DeltaUnit parse_delta_unit(const std::string& name) {
  if (name == "f") return DeltaUnit::kFrames;
  if (name == "s") return DeltaUnit::kSeconds;
  if (name == "m") return DeltaUnit::kMetres;
  throw ConfigError("command line", "--delta-unit", "one of f (frames), s (seconds), m (metres)", name);
}

const char* delta_unit_name(DeltaUnit u) {
  switch (u) {
    case DeltaUnit::kFrames: return "f";
    case DeltaUnit::kSeconds: return "s";
    case DeltaUnit::kMetres: return "m";
  }
  return "?";
}

PairMode parse_pair_mode(const std::string& name) {
  if (name == "all") return PairMode::kAll;
  if (name == "consecutive") return PairMode::kConsecutive;
  throw ConfigError("command line", "--rpe-pairs", "one of all, consecutive", name);
}

std::vector<std::pair<std::size_t, std::size_t>> select_rpe_pairs(const std::vector<double>& index,
                                                                  double delta, PairMode mode) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  const std::size_t n = index.size();
  if (n < 2) return out;
  if (mode == PairMode::kAll) {
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = closest_index(index, index[i] + delta);
      if (j != n - 1) out.emplace_back(i, j);
    }
    return out;
  }
  // Consecutive: tolerate rounding when the last segment ends exactly at the end.
  const double tol = 1e-9 * std::max(1.0, std::fabs(index.back()));
  std::size_t i = 0;
  while (i + 1 < n && index[i] + delta <= index.back() + tol) {
    std::size_t j = closest_index(index, index[i] + delta);
    if (j <= i) j = i + 1;
    out.emplace_back(i, j);
    i = j;
  }
  return out;
}

std::vector<RpePair> rpe(const std::vector<geom::SE3d>& est, const std::vector<geom::SE3d>& gt,
                         const std::vector<std::int64_t>& t_ns, const RpeOptions& options) {
  const std::size_t n = est.size();
  if (gt.size() != n || t_ns.size() != n) throw EvalError("RPE: pose lists differ in size");
  if (n < 2) throw EvalError("RPE: need at least 2 associated poses, got " + std::to_string(n));
  if (!(options.delta > 0.0)) throw EvalError("RPE: delta must be positive");
  std::vector<double> index(n);
  double travelled_m = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    switch (options.unit) {
      case DeltaUnit::kFrames: index[k] = static_cast<double>(k); break;
      case DeltaUnit::kSeconds: index[k] = geom::ns_to_seconds(t_ns[k] - t_ns[0]); break;
      case DeltaUnit::kMetres:
        if (k > 0) travelled_m += (est[k].translation() - est[k - 1].translation()).norm();
        index[k] = travelled_m;
        break;
    }
  }
  std::vector<RpePair> out;
  for (const auto& [i, j] : select_rpe_pairs(index, options.delta, options.pairs)) {
    const geom::SE3d A = est[i].inverse() * est[j];
    const geom::SE3d B = gt[i].inverse() * gt[j];
    const geom::SE3d E = A * B.inverse();
    RpePair p;
    p.i = i;
    p.j = j;
    p.trans_m = E.translation().norm();
    p.rot_deg = geom::rotation_angle_rad(E.linear()) * kRadToDeg;
    p.rot_err_deg = geom::so3_log(E.linear()) * kRadToDeg;
    p.trans_err_m = E.translation();
    out.push_back(p);
  }
  if (out.empty())
    throw EvalError("RPE: no pose pair is " + std::to_string(options.delta) + " " +
                    delta_unit_name(options.unit) + " apart within the " + std::to_string(n) +
                    " associated poses; use a smaller --delta");
  return out;
}

}  // namespace pvb::eval
