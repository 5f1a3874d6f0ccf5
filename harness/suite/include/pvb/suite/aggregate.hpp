#pragma once
// Aggregation of a seed sweep: per-seed rows read from DIR/seed_S/metrics.json,
// mean ± sd over the seeds that produced metrics and, with --compare, the
// paired PE-SLAM − baseline ATE difference with its 95 % confidence interval.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pvb/eval/charts.hpp"
#include "pvb/suite/metrics_file.hpp"

namespace pvb::suite {

/// One seed of a sweep.
struct SeedRun {
  std::uint64_t seed = 0;
  int exit_code = 0;  ///< of the child process; 0 when only aggregated
  std::string error;  ///< why there are no metrics ("" when there are)
  std::optional<MetricsFile> metrics;
};

/// Mean and sample standard deviation (n - 1; 0 for n = 1) of the values present.
struct Summary {
  int count = 0;
  double mean = 0.0;
  double sd = 0.0;
  double min = 0.0;
  double max = 0.0;
};
Summary summarize(const std::vector<double>& values);

/// Quantile of Student's t distribution with `dof` degrees of freedom: the
/// t with P(T <= t) = p, for 0 < p < 1 and dof >= 1.  Exact up to the
/// bisection's double precision: P(|T| < t) is the closed-form finite sum for
/// integer degrees of freedom (Abramowitz & Stegun 26.7.3 and 26.7.4),
/// inverted by bisection.  E.g. student_t_quantile(0.975, 4) = 2.776.
double student_t_quantile(double p, int dof);

/// What the paired comparison says about PE-SLAM against the baseline.
enum class PairedVerdict {
  kTooFewSeeds,              ///< fewer than 2 pairs: no interval
  kPeBetter,                 ///< the whole 95 % CI of PE − baseline is below 0
  kBaselineBetter,           ///< the whole 95 % CI is above 0
  kNoSignificantDifference,  ///< the CI contains 0
};
/// "PE-SLAM better", "baseline better", "no significant difference at 95 %", "too few seeds".
const char* verdict_text(PairedVerdict v);

/// "Not significantly worse" (the sweep-level expectation, docs/scenarios.md):
/// the upper end of the paired 95 % interval of PE − baseline ATE RMSE is at
/// most max(kNotWorseFloorM, kNotWorseShare × the baseline's mean ATE RMSE).
/// The floor keeps a scene where both track to a few millimetres from asking
/// for sub-millimetre agreement; the share scales the margin with the error.
constexpr double kNotWorseFloorM = 0.0005;
constexpr double kNotWorseShare = 0.10;
/// max(kNotWorseFloorM, kNotWorseShare × baseline_mean_ate_m).
double not_worse_margin_m(double baseline_mean_ate_m);

/// Two-sided exact sign test: the probability, under "each sign is a fair
/// coin", of a split at least as uneven as `negative` of `n` signs (ties are
/// left out of n).  1 for n = 0.
double sign_test_p(int negative, int n);

/// PE-SLAM − baseline ATE RMSE per seed (d_i, metres) over the seeds where
/// both runs of a --compare run have an ATE.  Both runs of one seed track
/// the same rendered frames, so the scene, the noise and the route cancel
/// in d_i and what is left is the effect of PE-match plus run-to-run noise.
struct PairedComparison {
  int count = 0;            ///< n: seeds with both ATEs
  double mean_m = 0.0;      ///< mean of d_i
  double sd_m = 0.0;        ///< sample SD of d_i (n − 1; 0 for n = 1)
  double se_m = 0.0;        ///< standard error sd / sqrt(n)
  bool has_ci = false;      ///< n >= 2
  double t_quantile = 0.0;  ///< t(0.975, n − 1) when has_ci
  double ci_low_m = 0.0;    ///< mean − t · se
  double ci_high_m = 0.0;   ///< mean + t · se
  /// Effect size d_z = mean / sd of d_i (Cohen's paired d; 0 when sd = 0).
  double effect_size_dz = 0.0;
  int pe_not_worse = 0;     ///< seeds with PE ATE <= baseline ATE (d_i <= 0)
  int pe_better = 0;        ///< seeds with d_i < 0
  int pe_worse = 0;         ///< seeds with d_i > 0
  double sign_test_p = 1.0;      ///< sign_test_p(pe_better, pe_better + pe_worse)
  double baseline_mean_m = 0.0;  ///< the baseline's mean ATE RMSE over these seeds
  double margin_m = 0.0;         ///< not_worse_margin_m(baseline_mean_m)
  bool not_worse = false;        ///< has_ci and ci_high_m <= margin_m
  PairedVerdict verdict = PairedVerdict::kTooFewSeeds;
  /// Who is compared: "PE-SLAM" against "baseline" (--compare), or with
  /// --compare-sensors the primary run's sensor setup against the
  /// reference's (e.g. "camera+imu+wheels" against "camera").
  std::string primary_label = "PE-SLAM";
  std::string reference_label = "baseline";
};

/// The verdict in the comparison's own names, e.g. "camera better".
std::string verdict_text(const PairedComparison& p);

/// PE-SLAM − baseline ATE of one seed, when both are present.
std::optional<double> paired_ate_difference_m(const SeedRun& r);
/// The paired comparison over the runs (seeds without both ATEs left out).
PairedComparison compare_paired(const std::vector<SeedRun>& runs);
/// One line in millimetres, e.g. "PE-SLAM − baseline ATE: mean -0.42 mm,
/// 95 % CI [-1.10, 0.26] mm over 8 seeds (effect size d_z -0.52; PE ≤
/// baseline on 5, sign test p = 0.73); no significant difference at 95 %;
/// not significantly worse: yes (upper end 0.26 mm ≤ margin 0.50 mm)".
std::string format_paired_line(const PairedComparison& p);

struct RunSummary {
  Summary ate_rmse_m;
  Summary lost_frames;
  Summary tracking_ms_median;
  Summary realtime_factor;
  Summary refined_ate_rmse_m;  ///< seeds with a refined evaluation
  // The dense maps, over the seeds where they were scored (docs/map_accuracy.md).
  Summary map_accuracy_median_m;  ///< corrected map
  Summary map_completeness_5cm;   ///< corrected map
  Summary map_ghosting;           ///< corrected map
  Summary map_ghosting_live;      ///< the live map (keyframes at the poses they were made with)
};

/// Place recognition summed over the seeds whose metrics carry
/// ground-truth labels (docs/place_recognition.md).
struct PlaceTotals {
  int seeds = 0;  ///< seeds with labels
  int loops_proposed = 0, loops_accepted = 0, loops_true = 0, loops_false = 0, loops_missed = 0, revisits = 0;
  int relocalisations_true = 0, relocalisations_false = 0;
  int seeds_with_true_loop = 0;   ///< seeds where at least one true loop was closed
  int seeds_with_false_match = 0; ///< seeds with a false loop or a false relocalisation
};
PlaceTotals total_place(const std::vector<const RunMetrics*>& runs);

struct SweepAggregate {
  std::string scenario;
  std::vector<SeedRun> runs;  ///< in seed-list order
  RunSummary primary;
  PlaceTotals primary_place;
  bool has_baseline = false;  ///< any seed ran with --compare
  RunSummary baseline;
  PairedComparison paired;  ///< meaningful when has_baseline
  int failed = 0;           ///< seeds without metrics or with a non-zero exit
};

/// Reads DIR/seed_S/metrics.json for one seed into a SeedRun; a missing or
/// malformed file is recorded in `error`, not thrown.
SeedRun read_seed_run(std::uint64_t seed, const std::string& metrics_path, int exit_code = 0);

/// Summaries over the runs that have metrics (ATE over runs with an ATE).
SweepAggregate aggregate(const std::string& scenario, std::vector<SeedRun> runs);

/// aggregate.md: a summary table (mean ± sd), the paired line when there is a
/// baseline, and the per-seed rows.
std::string format_markdown(const SweepAggregate& a);
/// aggregate.csv: one row per seed.
std::string format_csv(const SweepAggregate& a);
/// aggregate.json: the summaries and per-seed rows.
std::string format_json(const SweepAggregate& a);

/// The sweep figure: ATE RMSE (mm) per seed, PE-SLAM as filled dots and the
/// baseline as hollow squares when present, with the means as dashed lines.
eval::Figure make_sweep_figure(const SweepAggregate& a);

}  // namespace pvb::suite
