#include "pvb/run/map_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/eval/associate.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/slam/optim/optimizer.hpp"

namespace pvb::run {
namespace {

using slam::BaOptions;
using slam::BaProblem;
using slam::MapSnapshot;

eval::Trajectory keyframe_trajectory(const std::vector<geom::SE3d>& T_c_w, const MapSnapshot& map) {
  eval::Trajectory t;
  t.source = "keyframes";
  for (std::size_t i = 0; i < T_c_w.size(); ++i) t.poses.push_back({map.keyframes[i].t_ns, T_c_w[i].inverse()});
  std::sort(t.poses.begin(), t.poses.end(), [](const auto& a, const auto& b) { return a.t_ns < b.t_ns; });
  return t;
}

MapCheckFit fit_of(const std::vector<geom::SE3d>& T_c_w, const MapSnapshot& map, const eval::Trajectory& gt,
                   const eval::EvalOptions& eo) {
  const eval::EvalResult r = eval::evaluate(gt, keyframe_trajectory(T_c_w, map), eo);
  MapCheckFit f;
  f.ate_rmse_m = r.ate.rmse;
  const auto& ax = r.rpe_rot_axes_deg;
  f.rot_mean_deg = ax.mean;
  for (int k = 0; k < 3; ++k) {
    const double se = ax.count > 1 ? ax.std[k] / std::sqrt(double(ax.count)) : 0.0;
    f.rot_t[k] = se > 0 ? ax.mean[k] / se : 0.0;
  }
  return f;
}

BaProblem make_problem(const MapSnapshot& map, const std::vector<geom::SE3d>& T_c_w, bool fix_all) {
  BaProblem p;
  for (std::size_t i = 0; i < map.keyframes.size(); ++i)
    p.keyframes.push_back({map.keyframes[i].id, T_c_w[i], fix_all || i == 0});
  for (const auto& pt : map.points) p.points.push_back({pt.id, pt.p_w});
  for (const auto& m : map.measurements) {
    slam::Observation o;
    o.uv = m.uv;
    o.u_right = m.u_right;
    o.inv_sigma2 = std::pow(map.scale_factor, -2.0 * m.octave);
    p.edges.push_back({m.keyframe, m.point, o});
  }
  return p;
}

std::vector<geom::SE3d> poses_of(const BaProblem& p) {
  std::vector<geom::SE3d> out;
  for (const auto& k : p.keyframes) out.push_back(k.T_c_w);
  return out;
}

std::string fit_line(const char* name, const MapCheckFit& f) {
  char buf[200];
  std::snprintf(buf, sizeof(buf), "%-38s %8.2f   %+.4f (%+.1f)  %+.4f (%+.1f)  %+.4f (%+.1f)\n", name,
                f.ate_rmse_m * 1000, f.rot_mean_deg.x(), f.rot_t.x(), f.rot_mean_deg.y(), f.rot_t.y(),
                f.rot_mean_deg.z(), f.rot_t.z());
  return buf;
}

std::string draws_line(const char* name, const std::vector<MapCheckFit>& fits) {
  if (fits.empty()) return {};
  std::vector<double> a;
  for (const auto& f : fits) a.push_back(f.ate_rmse_m * 1000);
  std::sort(a.begin(), a.end());
  double mean = 0;
  for (double x : a) mean += x;
  mean /= a.size();
  char buf[200];
  std::snprintf(buf, sizeof(buf), "%-38s %8.2f   (%zu draws: min %.2f, median %.2f, max %.2f mm)\n", name, mean,
                a.size(), a.front(), a[a.size() / 2], a.back());
  return buf;
}

/// What every fit from the truth shares.
struct FitContext {
  const MapSnapshot& map;
  const eval::Trajectory& gt;
  eval::EvalOptions eo;
  BaOptions ba;
  std::vector<geom::SE3d> truth;  ///< T_c_w of every keyframe at its ground truth, in the map's world frame
};

/// Ground truth T_w_c of every keyframe; throws when one has none within options.max_time_diff_s.
std::vector<geom::SE3d> keyframe_ground_truth(const MapSnapshot& map, const eval::Trajectory& gt,
                                              const MapCheckOptions& options,
                                              const eval::AssociationOptions& ao) {
  std::vector<geom::SE3d> gt_T_w_c(map.keyframes.size());
  // eval::associate wants both trajectories sorted by time; `order` maps back.
  std::vector<std::size_t> order(map.keyframes.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return map.keyframes[a].t_ns < map.keyframes[b].t_ns; });
  eval::Trajectory sorted;
  for (std::size_t i : order) sorted.poses.push_back({map.keyframes[i].t_ns, geom::SE3d::Identity()});
  std::vector<bool> have(map.keyframes.size(), false);
  for (const auto& pr : eval::associate(gt, sorted, ao)) {
    gt_T_w_c[order[pr.est]] = gt.poses[pr.gt].T_w_c;
    have[order[pr.est]] = true;
  }
  for (std::size_t i = 0; i < have.size(); ++i)
    if (!have[i])
      throw Error("map-check: keyframe " + std::to_string(map.keyframes[i].id) + " (t " +
                  std::to_string(map.keyframes[i].t_ns * 1e-9) + " s) has no ground truth within " +
                  std::to_string(options.max_time_diff_s) + " s in " + gt.source);
  return gt_T_w_c;
}

/// The truth in the map's world frame (anchored at keyframe 0), the
/// evaluation and the bundle-adjustment options.
FitContext make_context(const MapSnapshot& map, const eval::Trajectory& gt, const MapCheckOptions& options) {
  FitContext c{map, gt, {}, {}, {}};
  c.eo.association.max_diff_s = options.max_time_diff_s;
  c.eo.rpe.pairs = eval::PairMode::kConsecutive;
  const std::vector<geom::SE3d> gt_T_w_c = keyframe_ground_truth(map, gt, options, c.eo.association);
  const geom::SE3d T_gtw_w = gt_T_w_c[0] * map.keyframes[0].T_c_w;
  c.truth.resize(map.keyframes.size());
  for (std::size_t i = 0; i < c.truth.size(); ++i) c.truth[i] = gt_T_w_c[i].inverse() * T_gtw_w;
  c.ba.sparse_schur = true;
  c.ba.iterations_first = 10;
  c.ba.iterations_second = 20;
  return c;
}

/// Points fitted to their measurements with every keyframe at the truth.
struct AtTruth {
  BaProblem problem;
  /// Per measurement: (u, v, u_right) of the fitted point.
  std::vector<Eigen::Vector3d> exact;
  /// Per measurement: the whitened residual (u_right's 0 without depth).
  std::vector<Eigen::Vector3d> residual;
};

AtTruth fit_points_at_truth(const FitContext& c) {
  AtTruth at{make_problem(c.map, c.truth, true), {}, {}};
  slam::local_bundle_adjustment(&at.problem, c.map.K, c.ba);
  const std::size_t n = at.problem.edges.size();
  at.exact.resize(n);
  at.residual.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto& e = at.problem.edges[k];
    const Eigen::Vector3d p_c = at.problem.keyframes[e.keyframe].T_c_w * at.problem.points[e.point].p_w;
    const Eigen::Vector2d uv = slam::project(c.map.K, p_c);
    const double w = std::sqrt(e.obs.inv_sigma2);
    at.exact[k] = Eigen::Vector3d(uv.x(), uv.y(), uv.x() - c.map.K.bf / p_c.z());
    const bool depth = e.obs.u_right >= 0;
    at.residual[k] = Eigen::Vector3d(e.obs.uv.x() - uv.x(), e.obs.uv.y() - uv.y(),
                                     depth ? e.obs.u_right - at.exact[k].z() : 0.0) *
                     w;
  }
  return at;
}

/// RMS of the residuals under 3 (u_right over those with depth).
geom::Vec3d residual_rms(const AtTruth& at) {
  Eigen::Vector3d sum2 = Eigen::Vector3d::Zero();
  double count = 0, count_depth = 0;
  for (std::size_t k = 0; k < at.residual.size(); ++k) {
    const Eigen::Vector3d& r = at.residual[k];
    if (r.norm() < 3) {
      sum2 += r.cwiseProduct(r);
      count += 1;
      count_depth += at.problem.edges[k].obs.u_right >= 0 ? 1 : 0;
    }
  }
  if (count == 0) return geom::Vec3d::Zero();
  return Eigen::Vector3d(std::sqrt(sum2.x() / count), std::sqrt(sum2.y() / count),
                         count_depth > 0 ? std::sqrt(sum2.z() / count_depth) : 0.0);
}

/// Global BA with the poses free, from the truth and the fitted points;
/// r == nullptr: the measurements as they are, else the exact ones plus r
/// (whitened, per measurement).
MapCheckFit fit_from_truth(const FitContext& c, const AtTruth& at, const std::vector<Eigen::Vector3d>* r) {
  BaProblem p = make_problem(c.map, c.truth, false);
  for (std::size_t i = 0; i < p.points.size(); ++i) p.points[i].p_w = at.problem.points[i].p_w;
  if (r)
    for (std::size_t k = 0; k < at.exact.size(); ++k) {
      auto& o = p.edges[k].obs;
      const double w = std::sqrt(o.inv_sigma2);
      o.uv = Eigen::Vector2d(at.exact[k].x() + (*r)[k].x() / w, at.exact[k].y() + (*r)[k].y() / w);
      if (o.u_right >= 0) o.u_right = at.exact[k].z() + (*r)[k].z() / w;
    }
  slam::local_bundle_adjustment(&p, c.map.K, c.ba);
  return fit_of(poses_of(p), c.map, c.gt, c.eo);
}

/// The synthetic draws: Gaussian noise of the measured RMS, and the
/// measured residuals with random signs.
void add_draws(const FitContext& c, const AtTruth& at, const MapCheckOptions& options, MapCheckResult* out) {
  const std::size_t n = at.residual.size();
  for (int d = 0; d < options.draws; ++d) {
    std::mt19937 rng(options.seed + static_cast<std::uint32_t>(d));
    std::normal_distribution<double> normal(0.0, 1.0);
    std::vector<Eigen::Vector3d> r(n);
    for (auto& x : r) {
      x.x() = normal(rng) * out->residual_rms.x();
      x.y() = normal(rng) * out->residual_rms.y();
      x.z() = normal(rng) * out->residual_rms.z();
    }
    out->gaussian.push_back(fit_from_truth(c, at, &r));
    for (std::size_t k = 0; k < n; ++k)
      r[k] = (rng() & 1u) ? at.residual[k] : Eigen::Vector3d(-at.residual[k]);
    out->sign_flipped.push_back(fit_from_truth(c, at, &r));
  }
}

}  // namespace

MapCheckResult check_map(const MapSnapshot& map, const eval::Trajectory& gt, const MapCheckOptions& options) {
  MapCheckResult out;
  out.keyframes = map.keyframes.size();
  out.points = map.points.size();
  out.measurements = map.measurements.size();
  if (map.keyframes.size() < 3) throw Error("map-check: the map has fewer than 3 keyframes");
  const FitContext c = make_context(map, gt, options);
  std::vector<geom::SE3d> mapped;
  for (const auto& k : map.keyframes) mapped.push_back(k.T_c_w);
  out.estimate = fit_of(mapped, map, gt, c.eo);
  const AtTruth at = fit_points_at_truth(c);
  out.residual_rms = residual_rms(at);
  out.measured = fit_from_truth(c, at, nullptr);
  add_draws(c, at, options, &out);
  return out;
}

std::string format_map_check(const MapCheckResult& r) {
  std::ostringstream os;
  char buf[200];
  std::snprintf(buf, sizeof(buf), "map: %zu keyframes, %zu points, %zu measurements\n", r.keyframes, r.points,
                r.measurements);
  os << buf;
  std::snprintf(buf, sizeof(buf),
                "residual RMS at ground truth (px / 1.2^octave, under 3): u %.3f  v %.3f  u_right %.3f\n",
                r.residual_rms.x(), r.residual_rms.y(), r.residual_rms.z());
  os << buf;
  os << "                                       KF ATE mm   rotation error per keyframe pair, deg (t)\n"
        "                                                  pitch (x)        yaw (y)          roll (z)\n";
  os << fit_line("estimate (as mapped)", r.estimate);
  os << fit_line("measured, global BA from ground truth", r.measured);
  os << draws_line("Gaussian noise of that RMS, mean", r.gaussian);
  os << draws_line("measured sizes, random signs, mean", r.sign_flipped);
  if (!r.sign_flipped.empty()) {
    std::size_t better = 0;
    for (const auto& f : r.sign_flipped) better += f.ate_rmse_m < r.measured.ate_rmse_m ? 1 : 0;
    std::string biased;
    static const char* kAxis[] = {"pitch", "yaw", "roll"};
    for (int k = 0; k < 3; ++k)
      if (std::abs(r.measured.rot_t[k]) > 3) {
        std::snprintf(buf, sizeof(buf), "%s%s t %+.1f", biased.empty() ? "" : ", ", kAxis[k], r.measured.rot_t[k]);
        biased += buf;
      }
    std::snprintf(buf, sizeof(buf), "reading: the measured fit is worse than %zu of %zu sign-flipped draws", better,
                  r.sign_flipped.size());
    os << buf;
    if (better == r.sign_flipped.size() || !biased.empty())
      os << "; systematic error in the measurements" << (biased.empty() ? "" : " (rotation bias: " + biased + ")")
         << "\n";
    else
      os << ", no rotation bias with |t| > 3: noise-limited\n";
  }
  return os.str();
}

}  // namespace pvb::run
