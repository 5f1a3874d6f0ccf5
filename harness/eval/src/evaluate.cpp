#include "pvb/eval/evaluate.hpp"

#include <cmath>
#include <cstdio>

#include "pvb/common/text.hpp"
#include "pvb/geometry/time.hpp"

namespace pvb::eval {
namespace {

/// JSON number: finite values with full precision, null otherwise.
std::string num(double v) { return json_number(v, 17); }

}  // namespace

std::string stats_json(const Stats& s) {
  return "{\"rmse\": " + num(s.rmse) + ", \"mean\": " + num(s.mean) + ", \"median\": " + num(s.median) +
         ", \"std\": " + num(s.std) + ", \"min\": " + num(s.min) + ", \"max\": " + num(s.max) +
         ", \"count\": " + std::to_string(s.count) + "}";
}

namespace {

std::string vec_json(const geom::Vec3d& v) {
  return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]";
}

std::string axes_json(const EvalResult& r) {
  auto one = [](const AxisStats& a) {
    return "{\"mean\": " + vec_json(a.mean) + ", \"std\": " + vec_json(a.std) + "}";
  };
  return "{\"rot_deg\": " + one(r.rpe_rot_axes_deg) + ", \"trans_m\": " + one(r.rpe_trans_axes_m) + "}";
}

}  // namespace

std::string rpe_json(const EvalResult& r) {
  return "{\"delta\": " + num(r.rpe_options.delta) + ", \"unit\": \"" + delta_unit_name(r.rpe_options.unit) +
         "\", \"pairs\": \"" + (r.rpe_options.pairs == PairMode::kAll ? "all" : "consecutive") +
         "\", \"trans\": " + stats_json(r.rpe_trans_m) + ", \"rot_deg\": " + stats_json(r.rpe_rot_deg) +
         ", \"axes\": " + axes_json(r) + "}";
}

namespace {

std::string result_fields_json(const EvalResult& r, const std::string& indent) {
  std::string R = "[";
  for (int i = 0; i < 3; ++i) {
    R += (i ? ", [" : "[");
    for (int j = 0; j < 3; ++j) R += (j ? ", " : "") + num(r.alignment.R(i, j));
    R += "]";
  }
  R += "]";
  const geom::Vec3d& t = r.alignment.t;
  std::string out;
  out += indent + "\"est\": \"" + json_escape(r.est_source) + "\",\n";
  out += indent + "\"pairs\": " + std::to_string(r.pairs.size()) + ",\n";
  out += indent + "\"ate\": " + stats_json(r.ate) + ",\n";
  out += indent + "\"rpe\": {\"delta\": " + num(r.rpe_options.delta) + ", \"unit\": \"" +
         delta_unit_name(r.rpe_options.unit) + "\", \"pairs\": \"" +
         (r.rpe_options.pairs == PairMode::kAll ? "all" : "consecutive") + "\",\n";
  out += indent + "        \"trans\": " + stats_json(r.rpe_trans_m) + ",\n";
  out += indent + "        \"rot_deg\": " + stats_json(r.rpe_rot_deg) + ",\n";
  out += indent + "        \"axes\": " + axes_json(r) + "},\n";
  out += indent + "\"alignment\": {\"kind\": \"" + alignment_name(r.alignment_kind) + "\", \"R\": " + R +
         ", \"t\": [" + num(t.x()) + ", " + num(t.y()) + ", " + num(t.z()) +
         "], \"s\": " + num(r.alignment.s) + "}";
  return out;
}

struct Metric {
  const char* name;
  const char* unit;
  double (*get)(const EvalResult&);
};
const Metric kMetrics[] = {
    {"ATE rmse", "m", [](const EvalResult& r) { return r.ate.rmse; }},
    {"ATE mean", "m", [](const EvalResult& r) { return r.ate.mean; }},
    {"ATE median", "m", [](const EvalResult& r) { return r.ate.median; }},
    {"ATE std", "m", [](const EvalResult& r) { return r.ate.std; }},
    {"ATE max", "m", [](const EvalResult& r) { return r.ate.max; }},
    {"RPE trans rmse", "m", [](const EvalResult& r) { return r.rpe_trans_m.rmse; }},
    {"RPE trans mean", "m", [](const EvalResult& r) { return r.rpe_trans_m.mean; }},
    {"RPE trans median", "m", [](const EvalResult& r) { return r.rpe_trans_m.median; }},
    {"RPE rot rmse", "deg", [](const EvalResult& r) { return r.rpe_rot_deg.rmse; }},
    {"RPE rot mean", "deg", [](const EvalResult& r) { return r.rpe_rot_deg.mean; }},
    {"RPE rot median", "deg", [](const EvalResult& r) { return r.rpe_rot_deg.median; }},
};

std::string base_name(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// Column label of an estimate: its file name, or "folder/file" when several
// estimates share a file name (runs writing CameraTrajectory.txt each).
std::string column_label(const std::vector<EvalResult>& results, std::size_t k) {
  const std::string& path = results[k].est_source;
  const std::string name = base_name(path);
  bool shared = false;
  for (std::size_t j = 0; j < results.size(); ++j)
    shared = shared || (j != k && base_name(results[j].est_source) == name);
  if (!shared) return name;
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos || slash == 0) return name;
  return base_name(path.substr(0, slash)) + "/" + name;
}

/// Throws EvalError for a pose that is not finite or lies beyond
/// kMaxAbsCoordinateM (trajectories built in memory; the readers check files
/// line by line).
void check_poses(const Trajectory& traj, const char* which) {
  for (const geom::StampedPose& p : traj.poses) {
    if (plausible_position(p.T_w_c.translation()) && p.T_w_c.linear().allFinite()) continue;
    throw EvalError(std::string(which) + " '" + traj.source +
                    "': the pose at t = " + geom::format_tum_time(p.t_ns) +
                    " s is not finite or lies beyond " + format_number("%g", kMaxAbsCoordinateM) + " m");
  }
}

}  // namespace

EvalResult evaluate(const Trajectory& gt, const Trajectory& est, const EvalOptions& options) {
  check_poses(gt, "ground truth");
  check_poses(est, "estimate");
  EvalResult r;
  r.est_source = est.source;
  r.alignment_kind = options.alignment;
  r.rpe_options = options.rpe;
  r.pairs = associate_or_throw(gt, est, options.association);
  std::vector<geom::SE3d> est_raw;
  est_raw.reserve(r.pairs.size());
  for (const IndexPair& p : r.pairs) {
    r.t_ns.push_back(est.poses[p.est].t_ns);
    r.T_w_c_gt.push_back(gt.poses[p.gt].T_w_c);
    est_raw.push_back(est.poses[p.est].T_w_c);
  }
  r.alignment = compute_alignment(est_raw, r.T_w_c_gt, options.alignment);
  r.T_w_c_est = apply_alignment(r.alignment, est_raw);
  r.ate_m = ate_errors_m(r.T_w_c_est, r.T_w_c_gt);
  r.ate = compute_stats(r.ate_m);
  r.rpe_pairs = rpe(r.T_w_c_est, r.T_w_c_gt, r.t_ns, options.rpe);
  std::vector<double> trans, rot;
  std::vector<geom::Vec3d> trans_axes, rot_axes;
  for (const RpePair& p : r.rpe_pairs) {
    trans.push_back(p.trans_m);
    rot.push_back(p.rot_deg);
    trans_axes.push_back(p.trans_err_m);
    rot_axes.push_back(p.rot_err_deg);
  }
  r.rpe_trans_m = compute_stats(trans);
  r.rpe_rot_deg = compute_stats(rot);
  r.rpe_trans_axes_m = compute_axis_stats(trans_axes);
  r.rpe_rot_axes_deg = compute_axis_stats(rot_axes);
  return r;
}

std::string format_report(const EvalResult& r) {
  std::string out;
  out += "estimate     " + r.est_source + "\n";
  out += "pairs        " + std::to_string(r.pairs.size()) + " associated poses";
  if (!r.t_ns.empty())
    out += ", " + format_number("%.3f", geom::ns_to_seconds(r.t_ns.back() - r.t_ns.front())) + " s";
  out += "\n";
  out += std::string("alignment    ") + alignment_name(r.alignment_kind) +
         format_number(" (scale %.6f", r.alignment.s) + format_number(", |t| %.4f m", r.alignment.t.norm()) +
         format_number(", rotation %.3f deg)", geom::rotation_angle_rad(r.alignment.R) * 180.0 / M_PI) + "\n";
  out += "RPE delta    " + format_number("%g", r.rpe_options.delta) + " " +
         delta_unit_name(r.rpe_options.unit) +
         (r.rpe_options.pairs == PairMode::kAll ? ", all pairs" : ", consecutive pairs") + "\n\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-18s %10s %10s %10s %10s %10s %10s %7s\n", "metric", "rmse", "mean",
                "median", "std", "min", "max", "count");
  out += line;
  auto row = [&](const char* name, const Stats& s) {
    std::snprintf(line, sizeof line, "%-18s %10.6f %10.6f %10.6f %10.6f %10.6f %10.6f %7zu\n", name, s.rmse,
                  s.mean, s.median, s.std, s.min, s.max, s.count);
    out += line;
  };
  row("ATE [m]", r.ate);
  row("RPE trans [m]", r.rpe_trans_m);
  row("RPE rot [deg]", r.rpe_rot_deg);
  out += format_rpe_axes(r);
  return out;
}

std::string format_rpe_axes(const EvalResult& r) {
  const bool consecutive = r.rpe_options.pairs == PairMode::kConsecutive;
  const std::size_t n = r.rpe_rot_axes_deg.count;
  std::string out = "\nRPE per axis of the start camera (signed: mean +- std over " + std::to_string(n) +
                    " pairs" + (consecutive && n > 1 ? "; t = mean / (std / sqrt(n - 1))" : "") + ")\n";
  auto row = [&](const char* name, const AxisStats& a, double scale, const char* unit) {
    char cell[96];
    std::snprintf(cell, sizeof cell, "%-6s", name);
    out += cell;
    for (int k = 0; k < 3; ++k) {
      std::snprintf(cell, sizeof cell, "  %c %+9.5f +- %8.5f", "xyz"[k], a.mean(k) * scale, a.std(k) * scale);
      out += cell;
      // Non-overlapping pairs only: overlapping ones are not independent.
      if (consecutive && n > 1) {
        const double se = a.std(k) / std::sqrt(static_cast<double>(n - 1));
        if (se > 0)
          std::snprintf(cell, sizeof cell, " (t %+5.1f)", a.mean(k) / se);
        else
          std::snprintf(cell, sizeof cell, " (t   n/a)");
        out += cell;
      }
    }
    out += std::string("  ") + unit + "\n";
  };
  row("rot", r.rpe_rot_axes_deg, 1.0, "deg");
  row("trans", r.rpe_trans_axes_m, 1000.0, "mm");
  return out;
}

double reduction_percent(double reference, double value) {
  if (reference == 0.0) return 0.0;
  return 100.0 * (reference - value) / reference;
}

std::string format_comparison(const std::vector<EvalResult>& results) {
  std::string out;
  if (results.empty()) return out;
  constexpr int kCol = 24;
  char cell[128];
  std::snprintf(cell, sizeof cell, "%-22s", "metric");
  out += cell;
  for (std::size_t k = 0; k < results.size(); ++k) {
    std::string name = "[" + std::to_string(k + 1) + "] " + column_label(results, k);
    if (name.size() > kCol - 1) name = name.substr(0, kCol - 2) + "~";
    std::snprintf(cell, sizeof cell, "%*s", kCol, name.c_str());
    out += cell;
  }
  out += "\n";
  for (const Metric& m : kMetrics) {
    std::snprintf(cell, sizeof cell, "%-22s", (std::string(m.name) + " [" + m.unit + "]").c_str());
    out += cell;
    const double ref = m.get(results.front());
    for (std::size_t k = 0; k < results.size(); ++k) {
      const double v = m.get(results[k]);
      std::string text = format_number("%.4f", v);
      if (k > 0) text += format_number(" (%+6.1f%%)", reduction_percent(ref, v));
      std::snprintf(cell, sizeof cell, "%*s", kCol, text.c_str());
      out += cell;
    }
    out += "\n";
  }
  std::snprintf(cell, sizeof cell, "%-22s", "pairs");
  out += cell;
  for (const EvalResult& r : results) {
    std::snprintf(cell, sizeof cell, "%*zu", kCol, r.pairs.size());
    out += cell;
  }
  out += "\n(percentages: reduction against [1]; positive means a smaller error than [1])\n";
  return out;
}

std::string format_json(const EvalResult& result) {
  return "{\n" + result_fields_json(result, "  ") + "\n}\n";
}

std::string format_json_document(const std::string& gt_source, const std::vector<EvalResult>& results) {
  if (results.empty()) return "{}\n";
  std::string out = "{\n  \"gt\": \"" + json_escape(gt_source) + "\",\n";
  out += result_fields_json(results.front(), "  ");
  if (results.size() > 1) {
    out += ",\n  \"runs\": [\n";
    for (std::size_t k = 0; k < results.size(); ++k) {
      out += "    {\n" + result_fields_json(results[k], "      ") + ",\n      \"reduction_percent\": {";
      for (std::size_t m = 0; m < std::size(kMetrics); ++m) {
        std::string key = kMetrics[m].name;
        for (char& c : key)
          c = c == ' ' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        out += (m ? ", \"" : "\"") + key +
               "\": " + num(reduction_percent(kMetrics[m].get(results.front()), kMetrics[m].get(results[k])));
      }
      out += "}\n    }";
      out += k + 1 < results.size() ? ",\n" : "\n";
    }
    out += "  ]";
  }
  out += "\n}\n";
  return out;
}

}  // namespace pvb::eval
