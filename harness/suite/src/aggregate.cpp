#include "pvb/suite/aggregate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/eval/slam_mode.hpp"
#include "seed_failed.hpp"

namespace pvb::suite {
namespace {

std::string opt(const std::optional<double>& v, const char* f, double scale = 1.0) {
  return v ? format_number(f, *v * scale) : "";
}
std::string json_num(double v) { return json_number(v, 9); }
std::string json_opt(const std::optional<double>& v) { return v ? json_num(*v) : "null"; }

RunSummary summarize_runs(const std::vector<const RunMetrics*>& runs) {
  std::vector<double> ate, lost, ms, rtf, refined, map_acc, map_comp, ghost, ghost_live;
  for (const RunMetrics* r : runs) {
    if (const MapMetrics* m = r->map("corrected")) {
      if (m->accuracy_median_m) map_acc.push_back(*m->accuracy_median_m);
      map_comp.push_back(m->completeness_5cm);
      ghost.push_back(m->ghosting);
    }
    if (const MapMetrics* m = r->map("live")) ghost_live.push_back(m->ghosting);
    if (r->ate_rmse_m) ate.push_back(*r->ate_rmse_m);
    if (r->refined_ate_rmse_m) refined.push_back(*r->refined_ate_rmse_m);
    lost.push_back(r->lost_frames);
    if (r->tracking_ms_median) ms.push_back(*r->tracking_ms_median);
    if (r->realtime_factor) rtf.push_back(*r->realtime_factor);
  }
  return {summarize(ate),     summarize(lost),     summarize(ms),    summarize(rtf),
          summarize(refined), summarize(map_acc), summarize(map_comp), summarize(ghost),
          summarize(ghost_live)};
}

std::string place_totals_json(const PlaceTotals& p) {
  return "{\"seeds\": " + std::to_string(p.seeds) + ", \"loops_proposed\": " + std::to_string(p.loops_proposed) +
         ", \"loops_accepted\": " + std::to_string(p.loops_accepted) +
         ", \"loops_true\": " + std::to_string(p.loops_true) + ", \"loops_false\": " + std::to_string(p.loops_false) +
         ", \"loops_missed\": " + std::to_string(p.loops_missed) + ", \"revisits\": " + std::to_string(p.revisits) +
         ", \"relocalisations_true\": " + std::to_string(p.relocalisations_true) +
         ", \"relocalisations_false\": " + std::to_string(p.relocalisations_false) +
         ", \"seeds_with_true_loop\": " + std::to_string(p.seeds_with_true_loop) +
         ", \"seeds_with_false_match\": " + std::to_string(p.seeds_with_false_match) + "}";
}

std::string place_totals_line(const PlaceTotals& p) {
  return "Place recognition over " + std::to_string(p.seeds) + " seeds with ground-truth labels: loops " +
         std::to_string(p.loops_proposed) + " proposed, " + std::to_string(p.loops_accepted) + " accepted, " +
         std::to_string(p.loops_true) + " true, " + std::to_string(p.loops_false) + " false, " +
         std::to_string(p.loops_missed) + " missed of " + std::to_string(p.revisits) +
         " true revisits (a true loop on " + std::to_string(p.seeds_with_true_loop) + " seeds); relocalisations " +
         std::to_string(p.relocalisations_true) + " true, " + std::to_string(p.relocalisations_false) +
         " false; seeds with a false match: " + std::to_string(p.seeds_with_false_match) + ".\n";
}

std::string pm(const Summary& s, const char* f, double scale = 1.0) {
  if (s.count == 0) return "n/a";
  return format_number(f, s.mean * scale) + " ± " + format_number(f, s.sd * scale);
}

/// The dense-map line of one run kind (empty when no seed scored its map).
std::string map_line(const std::string& name, const RunSummary& s) {
  if (s.map_accuracy_median_m.count == 0) return {};
  return "\n" + name + " dense map over " + std::to_string(s.map_accuracy_median_m.count) +
         " seeds: median accuracy " + pm(s.map_accuracy_median_m, "%.1f", 1000.0) + " mm, complete within 5 cm " +
         pm(s.map_completeness_5cm, "%.1f", 100.0) + " %, ghosting " + pm(s.map_ghosting, "%.2f", 100.0) +
         " % (live map " + pm(s.map_ghosting_live, "%.2f", 100.0) + " %).\n";
}

std::string summary_json(const Summary& s) {
  if (s.count == 0) return "{\"count\": 0}";
  return "{\"count\": " + std::to_string(s.count) + ", \"mean\": " + json_num(s.mean) +
         ", \"sd\": " + json_num(s.sd) + ", \"min\": " + json_num(s.min) + ", \"max\": " + json_num(s.max) +
         "}";
}

std::string run_summary_json(const RunSummary& r) {
  return "{\"ate_rmse_m\": " + summary_json(r.ate_rmse_m) +
         ", \"refined_ate_rmse_m\": " + summary_json(r.refined_ate_rmse_m) +
         ", \"lost_frames\": " + summary_json(r.lost_frames) +
         ", \"tracking_ms_median\": " + summary_json(r.tracking_ms_median) +
         ", \"realtime_factor\": " + summary_json(r.realtime_factor) +
         ", \"map_accuracy_median_m\": " + summary_json(r.map_accuracy_median_m) +
         ", \"map_completeness_5cm\": " + summary_json(r.map_completeness_5cm) +
         ", \"map_ghosting\": " + summary_json(r.map_ghosting) +
         ", \"map_ghosting_live\": " + summary_json(r.map_ghosting_live) + "}";
}

std::string paired_json(const PairedComparison& p) {
  const auto ci = [&](double v) { return p.has_ci ? json_num(v) : std::string("null"); };
  return "{\"count\": " + std::to_string(p.count) + ", \"mean_m\": " + json_num(p.mean_m) +
         ", \"sd_m\": " + json_num(p.sd_m) + ", \"se_m\": " + json_num(p.se_m) +
         ", \"t_quantile\": " + ci(p.t_quantile) + ", \"ci95_low_m\": " + ci(p.ci_low_m) +
         ", \"ci95_high_m\": " + ci(p.ci_high_m) + ", \"effect_size_dz\": " + json_num(p.effect_size_dz) +
         ", \"pe_not_worse\": " + std::to_string(p.pe_not_worse) +
         ", \"pe_better\": " + std::to_string(p.pe_better) + ", \"pe_worse\": " + std::to_string(p.pe_worse) +
         ", \"sign_test_p\": " + json_num(p.sign_test_p) +
         ", \"baseline_mean_m\": " + json_num(p.baseline_mean_m) + ", \"margin_m\": " + json_num(p.margin_m) +
         ", \"not_significantly_worse\": " + (p.has_ci ? (p.not_worse ? "true" : "false") : "null") +
         ", \"verdict\": \"" + json_escape(verdict_text(p)) + "\", \"primary\": " + json_string(p.primary_label) +
         ", \"reference\": " + json_string(p.reference_label) + "}";
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return out + "\"";
}

constexpr double kPi = 3.14159265358979323846;

/// P(|T| < t) for t >= 0 and Student's t with `dof` >= 1 degrees of freedom,
/// the closed forms for integer dof (Abramowitz & Stegun 26.7.3 and 26.7.4)
/// with theta = atan(t / sqrt(dof)):
///   dof = 1:     2 theta / pi
///   dof odd:     2/pi (theta + sin theta (cos theta + 2/3 cos^3 theta + ...
///                      + (2·4···(dof−3)) / (1·3···(dof−2)) cos^(dof−2) theta))
///   dof even:    sin theta (1 + 1/2 cos^2 theta + 1·3/(2·4) cos^4 theta + ...
///                      + (1·3···(dof−3)) / (2·4···(dof−2)) cos^(dof−2) theta)
double t_central_mass(double t, int dof) {
  const double theta = std::atan(t / std::sqrt(static_cast<double>(dof)));
  const double s = std::sin(theta), c = std::cos(theta), c2 = c * c;
  if (dof % 2 == 0) {
    double term = 1.0, sum = 1.0;
    for (int j = 1; j <= (dof - 2) / 2; ++j) {
      term *= c2 * (2.0 * j - 1.0) / (2.0 * j);
      sum += term;
    }
    return s * sum;
  }
  if (dof == 1) return 2.0 * theta / kPi;
  double term = c, sum = c;
  for (int j = 1; j <= (dof - 3) / 2; ++j) {
    term *= c2 * (2.0 * j) / (2.0 * j + 1.0);
    sum += term;
  }
  return 2.0 / kPi * (theta + s * sum);
}

std::string mm2(double v_m) { return format_number("%.2f", v_m * 1000.0); }

}  // namespace

double student_t_quantile(double p, int dof) {
  if (!(p > 0.0 && p < 1.0) || dof < 1) return std::nan("");
  if (p == 0.5) return 0.0;
  // Solve P(|T| < t) = |2p − 1| for t >= 0; the mass rises monotonically in t.
  const double target = std::abs(2.0 * p - 1.0);
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 1100 && t_central_mass(hi, dof) < target; ++i) {
    lo = hi;
    hi *= 2.0;
  }
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (t_central_mass(mid, dof) < target ? lo : hi) = mid;
  }
  const double t = 0.5 * (lo + hi);
  return p > 0.5 ? t : -t;
}

const char* verdict_text(PairedVerdict v) {
  switch (v) {
    case PairedVerdict::kPeBetter:
      return "PE-SLAM better";
    case PairedVerdict::kBaselineBetter:
      return "baseline better";
    case PairedVerdict::kNoSignificantDifference:
      return "no significant difference at 95 %";
    case PairedVerdict::kTooFewSeeds:
      break;
  }
  return "too few seeds";
}

std::string verdict_text(const PairedComparison& p) {
  if (p.verdict == PairedVerdict::kPeBetter) return p.primary_label + " better";
  if (p.verdict == PairedVerdict::kBaselineBetter) return p.reference_label + " better";
  return verdict_text(p.verdict);
}

std::optional<double> paired_ate_difference_m(const SeedRun& r) {
  if (!r.metrics || !r.metrics->baseline || !r.metrics->primary.ate_rmse_m ||
      !r.metrics->baseline->ate_rmse_m)
    return std::nullopt;
  return *r.metrics->primary.ate_rmse_m - *r.metrics->baseline->ate_rmse_m;
}

double not_worse_margin_m(double baseline_mean_ate_m) {
  return std::max(kNotWorseFloorM, kNotWorseShare * baseline_mean_ate_m);
}

double sign_test_p(int negative, int n) {
  if (n <= 0) return 1.0;
  // P(X <= k) for X ~ Binomial(n, 1/2), summed in log space (n may be large).
  const auto cdf = [n](int k) {
    double sum = 0.0;
    for (int i = 0; i <= k; ++i)
      sum += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) -
                      n * std::log(2.0));
    return sum;
  };
  const int k = std::min(negative, n - negative);  // the rarer sign
  return std::min(1.0, 2.0 * cdf(k));
}

PairedComparison compare_paired(const std::vector<SeedRun>& runs) {
  PairedComparison p;
  std::vector<double> d, baseline;
  for (const SeedRun& r : runs) {
    const std::optional<double> diff = paired_ate_difference_m(r);
    if (!diff) continue;
    d.push_back(*diff);
    baseline.push_back(*r.metrics->baseline->ate_rmse_m);
    if (*diff <= 0.0) ++p.pe_not_worse;
    if (*diff < 0.0) ++p.pe_better;
    if (*diff > 0.0) ++p.pe_worse;
    if (r.metrics->primary.sensors != r.metrics->baseline->sensors) {  // --compare-sensors
      p.primary_label = r.metrics->primary.sensors;
      p.reference_label = r.metrics->baseline->sensors;
    }
  }
  const Summary s = summarize(d);
  p.count = s.count;
  p.mean_m = s.mean;
  p.sd_m = s.sd;
  if (p.count > 0) p.se_m = s.sd / std::sqrt(static_cast<double>(p.count));
  if (p.sd_m > 0.0) p.effect_size_dz = p.mean_m / p.sd_m;
  p.sign_test_p = sign_test_p(p.pe_better, p.pe_better + p.pe_worse);
  p.baseline_mean_m = summarize(baseline).mean;
  p.margin_m = not_worse_margin_m(p.baseline_mean_m);
  if (p.count < 2) return p;  // verdict stays kTooFewSeeds
  p.has_ci = true;
  p.t_quantile = student_t_quantile(0.975, p.count - 1);
  p.ci_low_m = p.mean_m - p.t_quantile * p.se_m;
  p.ci_high_m = p.mean_m + p.t_quantile * p.se_m;
  p.verdict = p.ci_high_m < 0.0  ? PairedVerdict::kPeBetter
              : p.ci_low_m > 0.0 ? PairedVerdict::kBaselineBetter
                                 : PairedVerdict::kNoSignificantDifference;
  p.not_worse = p.ci_high_m <= p.margin_m;
  return p;
}

std::string format_paired_line(const PairedComparison& p) {
  // "PE ≤ baseline" in a --compare sweep; the setups' names in a --compare-sensors one.
  const bool pe = p.primary_label == "PE-SLAM";
  const std::string le = (pe ? std::string("PE") : p.primary_label) + " ≤ " + p.reference_label;
  std::string out = p.primary_label + " − " + p.reference_label + " ATE: ";
  if (p.count == 0) return out + "no seed with both ATEs; " + verdict_text(p);
  out += "mean " + mm2(p.mean_m) + " mm";
  if (p.has_ci) out += ", 95 % CI [" + mm2(p.ci_low_m) + ", " + mm2(p.ci_high_m) + "] mm";
  out += " over " + std::to_string(p.count) + (p.count == 1 ? " seed" : " seeds");
  if (!p.has_ci)
    return out + " (" + le + " on " + std::to_string(p.pe_not_worse) + "); " + verdict_text(p);
  out += " (effect size d_z " + format_number("%.2f", p.effect_size_dz) + "; " + le + " on " +
         std::to_string(p.pe_not_worse) + ", sign test p = " + format_number("%.2f", p.sign_test_p) + "); " +
         verdict_text(p);
  return out + "; not significantly worse: " + (p.not_worse ? "yes (upper end " : "no (upper end ") +
         mm2(p.ci_high_m) + (p.not_worse ? " mm ≤ margin " : " mm > margin ") + mm2(p.margin_m) + " mm)";
}

Summary summarize(const std::vector<double>& values) {
  Summary s;
  s.count = static_cast<int>(values.size());
  if (values.empty()) return s;
  double sum = 0;
  for (double v : values) sum += v;
  s.mean = sum / s.count;
  double ss = 0;
  for (double v : values) ss += (v - s.mean) * (v - s.mean);
  s.sd = s.count > 1 ? std::sqrt(ss / (s.count - 1)) : 0.0;
  s.min = *std::min_element(values.begin(), values.end());
  s.max = *std::max_element(values.begin(), values.end());
  return s;
}

SeedRun read_seed_run(std::uint64_t seed, const std::string& metrics_path, int exit_code) {
  SeedRun r;
  r.seed = seed;
  r.exit_code = exit_code;
  try {
    r.metrics = read_metrics_file(metrics_path);
  } catch (const Error& e) {
    r.error = e.what();
  }
  return r;
}

PlaceTotals total_place(const std::vector<const RunMetrics*>& runs) {
  PlaceTotals t;
  for (const RunMetrics* r : runs) {
    if (!r->place || !r->place->loops_false || !r->place->relocalisations_false) continue;
    const PlaceMetrics& p = *r->place;
    ++t.seeds;
    t.loops_proposed += p.loops_proposed;
    t.loops_accepted += p.loops_accepted;
    t.loops_true += p.loops_true.value_or(0);
    t.loops_false += *p.loops_false;
    t.loops_missed += p.loops_missed.value_or(0);
    t.revisits += p.revisits.value_or(0);
    t.relocalisations_true += p.relocalisations_true.value_or(0);
    t.relocalisations_false += *p.relocalisations_false;
    t.seeds_with_true_loop += p.loops_true.value_or(0) > 0 ? 1 : 0;
    t.seeds_with_false_match += (*p.loops_false + *p.relocalisations_false) > 0 ? 1 : 0;
  }
  return t;
}

SweepAggregate aggregate(const std::string& scenario, std::vector<SeedRun> runs) {
  SweepAggregate a;
  a.scenario = scenario;
  a.runs = std::move(runs);
  std::vector<const RunMetrics*> primary, baseline;
  for (const SeedRun& r : a.runs) {
    if (seed_failed(r)) ++a.failed;
    if (!r.metrics) continue;
    primary.push_back(&r.metrics->primary);
    if (r.metrics->baseline) baseline.push_back(&*r.metrics->baseline);
  }
  a.primary = summarize_runs(primary);
  a.primary_place = total_place(primary);
  a.has_baseline = !baseline.empty();
  if (a.has_baseline) a.baseline = summarize_runs(baseline);
  a.paired = compare_paired(a.runs);
  return a;
}

namespace {

/// The per-seed table; the reference run's columns by its name (the
/// baseline, or with --compare-sensors its sensor setup) and the paired
/// difference's as `difference`.
std::string per_seed_section(const SweepAggregate& a, const std::string& reference_name,
                             const std::string& difference) {
  std::string out =
      "\n## Per seed\n\n| seed | exit | status | frames | lost | ATE RMSE (mm) | tracking ms | realtime "
      "factor |";
  if (a.has_baseline)
    out += " " + reference_name + " lost | " + reference_name + " ATE RMSE (mm) | " + difference + " (mm) |";
  out += " note |\n|---|---|---|---|---|---|---|---|";
  if (a.has_baseline) out += "---|---|---|";
  out += "---|\n";
  for (const SeedRun& r : a.runs) {
    out += "| " + std::to_string(r.seed) + " | " + std::to_string(r.exit_code) + " | ";
    if (r.metrics) {
      const RunMetrics& m = r.metrics->primary;
      out += m.status + " | " + std::to_string(m.frames) + " | " + std::to_string(m.lost_frames) + " | " +
             opt(m.ate_rmse_m, "%.2f", 1000.0) + " | " + opt(m.tracking_ms_median, "%.2f") + " | " +
             opt(m.realtime_factor, "%.3f") + " |";
      if (a.has_baseline) {
        if (r.metrics->baseline)
          out += " " + std::to_string(r.metrics->baseline->lost_frames) + " | " +
                 opt(r.metrics->baseline->ate_rmse_m, "%.2f", 1000.0) + " | " +
                 opt(paired_ate_difference_m(r), "%.2f", 1000.0) + " |";
        else
          out += " | | |";
      }
      std::string note;
      if (!m.loss_events.empty())
        note = "first loss at frame " + std::to_string(m.loss_events.front().frame) + ": " +
               m.loss_events.front().reason;
      for (char& c : note) c = c == '|' ? '/' : c;
      out += " " + note + " |\n";
    } else {
      std::string note = "no metrics: " + r.error;
      for (char& c : note) c = c == '|' ? '/' : c;
      out += " | | | | | |" + std::string(a.has_baseline ? " | | |" : "") + " " + note + " |\n";
    }
  }
  return out;
}

}  // namespace

std::string format_markdown(const SweepAggregate& a) {
  int with_metrics = 0;
  for (const SeedRun& r : a.runs) with_metrics += r.metrics ? 1 : 0;
  std::string out = "# Sweep: " + a.scenario + "\n\n" + std::to_string(a.runs.size()) + " seeds, " +
                    std::to_string(with_metrics) + " with metrics, " + std::to_string(a.failed) +
                    " failed. Mean ± sample SD over the seeds with metrics.\n\n";
  out += "| run | seeds | ATE RMSE (mm) | lost frames | tracking ms (median) | realtime factor |\n";
  out += "|---|---|---|---|---|---|\n";
  auto row = [&](const char* name, const RunSummary& s) {
    out += std::string("| ") + name + " | " + std::to_string(s.lost_frames.count) + " | " +
           pm(s.ate_rmse_m, "%.2f", 1000.0) + " | " + pm(s.lost_frames, "%.1f") + " | " +
           pm(s.tracking_ms_median, "%.2f") + " | " + pm(s.realtime_factor, "%.3f") + " |\n";
  };
  // The primary run's name: PE-SLAM unless the seeds ran --baseline alone.
  std::string primary_name = "PE-SLAM";
  for (const SeedRun& r : a.runs)
    if (r.metrics && !r.metrics->primary.mode.empty()) {
      if (r.metrics->primary.mode == eval::kBaselineMode) primary_name = eval::kBaselineLabel;
      break;
    }
  // --compare-sensors: the rows are named by the setups.
  const bool by_sensors = a.has_baseline && a.paired.primary_label != "PE-SLAM";
  if (by_sensors) primary_name = a.paired.primary_label;
  const std::string reference_name = by_sensors ? a.paired.reference_label : std::string(eval::kBaselineLabel);
  // The table's rows first, together, then the lines about them: a line
  // between two rows would end the table in a Markdown viewer.
  row(primary_name.c_str(), a.primary);
  if (a.has_baseline) row(reference_name.c_str(), a.baseline);
  if (a.primary.refined_ate_rmse_m.count > 0)
    out += "\nRefined trajectory (frames re-anchored on the final keyframe poses, after loop closing): ATE RMSE " +
           pm(a.primary.refined_ate_rmse_m, "%.2f", 1000.0) + " mm, max " +
           format_number("%.2f", a.primary.refined_ate_rmse_m.max * 1000.0) + " mm.\n";
  if (a.primary_place.seeds > 0) out += "\n" + place_totals_line(a.primary_place);
  out += map_line(primary_name, a.primary);
  if (a.has_baseline) {
    out += map_line(reference_name, a.baseline);
    // The paired figure (docs/sweeps.md): per seed d = PE − baseline on the same frames.
    out += "\n" + format_paired_line(a.paired) + "\n";
    if (a.paired.count > 0)
      out += "\nPaired per seed (both runs track the same frames): d = " + a.paired.primary_label + " − " +
             a.paired.reference_label + " ATE RMSE, SD " +
             mm2(a.paired.sd_m) + " mm, standard error " + mm2(a.paired.se_m) +
             " mm; the interval is mean ± t(0.975, n − 1) · SE. Not significantly worse: the upper end is at "
             "most max(0.5 mm, 10 % of the " + (by_sensors ? reference_name : std::string("baseline")) +
             "'s mean " +
             mm2(a.paired.baseline_mean_m) + " mm).\n";
  }
  if (!by_sensors) return out + per_seed_section(a, "baseline", "PE − baseline");
  return out + per_seed_section(a, reference_name, primary_name + " − " + reference_name);
}

std::string format_csv(const SweepAggregate& a) {
  std::string out =
      "seed,exit_code,status,frames,lost_frames,ate_rmse_m,rpe_trans_rmse_m,tracking_ms_median,realtime_"
      "factor,"
      "baseline_lost_frames,baseline_ate_rmse_m,baseline_tracking_ms_median,pe_minus_baseline_ate_m,error\n";
  for (const SeedRun& r : a.runs) {
    out += std::to_string(r.seed) + "," + std::to_string(r.exit_code) + ",";
    if (r.metrics) {
      const RunMetrics& m = r.metrics->primary;
      out += m.status + "," + std::to_string(m.frames) + "," + std::to_string(m.lost_frames) + "," +
             opt(m.ate_rmse_m, "%.9g") + "," + opt(m.rpe_trans_rmse_m, "%.9g") + "," +
             opt(m.tracking_ms_median, "%.9g") + "," + opt(m.realtime_factor, "%.9g") + ",";
      if (r.metrics->baseline) {
        const RunMetrics& b = *r.metrics->baseline;
        out += std::to_string(b.lost_frames) + "," + opt(b.ate_rmse_m, "%.9g") + "," +
               opt(b.tracking_ms_median, "%.9g") + "," + opt(paired_ate_difference_m(r), "%.9g") + ",";
      } else {
        out += ",,,,";
      }
      out += "\n";
    } else {
      out += ",,,,,,,,,,," + csv_field(r.error) + "\n";
    }
  }
  return out;
}

std::string format_json(const SweepAggregate& a) {
  std::string out = "{\n  \"scenario\": \"" + json_escape(a.scenario) +
                    "\",\n  \"seeds\": " + std::to_string(a.runs.size()) +
                    ",\n  \"failed\": " + std::to_string(a.failed) + ",\n";
  out += "  \"primary\": " + run_summary_json(a.primary) + ",\n";
  out += "  \"place_recognition\": " + place_totals_json(a.primary_place) + ",\n";
  out += "  \"baseline\": " + (a.has_baseline ? run_summary_json(a.baseline) : std::string("null")) + ",\n";
  out += "  \"paired\": " + (a.has_baseline ? paired_json(a.paired) : std::string("null")) + ",\n";
  out += "  \"runs\": [\n";
  for (std::size_t i = 0; i < a.runs.size(); ++i) {
    const SeedRun& r = a.runs[i];
    out += "    {\"seed\": " + std::to_string(r.seed) + ", \"exit_code\": " + std::to_string(r.exit_code);
    if (r.metrics) {
      const RunMetrics& m = r.metrics->primary;
      out += ", \"status\": \"" + json_escape(m.status) + "\", \"frames\": " + std::to_string(m.frames) +
             ", \"lost_frames\": " + std::to_string(m.lost_frames) +
             ", \"ate_rmse_m\": " + json_opt(m.ate_rmse_m) +
             ", \"rpe_trans_rmse_m\": " + json_opt(m.rpe_trans_rmse_m) +
             ", \"tracking_ms_median\": " + json_opt(m.tracking_ms_median) +
             ", \"realtime_factor\": " + json_opt(m.realtime_factor);
      if (r.metrics->baseline) {
        const RunMetrics& b = *r.metrics->baseline;
        out += ", \"baseline\": {\"lost_frames\": " + std::to_string(b.lost_frames) +
               ", \"ate_rmse_m\": " + json_opt(b.ate_rmse_m) +
               ", \"tracking_ms_median\": " + json_opt(b.tracking_ms_median) +
               "}, \"pe_minus_baseline_ate_m\": " + json_opt(paired_ate_difference_m(r));
      }
    } else {
      out += ", \"error\": \"" + json_escape(r.error) + "\"";
    }
    out += i + 1 < a.runs.size() ? "},\n" : "}\n";
  }
  out += "  ]\n}\n";
  return out;
}

}  // namespace pvb::suite
