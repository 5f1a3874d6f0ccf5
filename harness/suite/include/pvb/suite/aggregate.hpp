#pragma once
// Aggregation of a seed sweep: per-seed rows read from DIR/seed_S/metrics.json
// and mean ± sd over the seeds that produced metrics.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pvb/eval/plot.hpp"
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

struct RunSummary {
  Summary ate_rmse_m;
  Summary lost_frames;
  Summary tracking_ms_median;
  Summary realtime_factor;
};

struct SweepAggregate {
  std::string scenario;
  std::vector<SeedRun> runs;  ///< in seed-list order
  RunSummary primary;
  bool has_baseline = false;  ///< any seed ran with --compare
  RunSummary baseline;
  int failed = 0;  ///< seeds without metrics or with a non-zero exit
};

/// Reads DIR/seed_S/metrics.json for one seed into a SeedRun; a missing or
/// malformed file is recorded in `error`, not thrown.
SeedRun read_seed_run(std::uint64_t seed, const std::string& metrics_path, int exit_code = 0);

/// Summaries over the runs that have metrics (ATE over runs with an ATE).
SweepAggregate aggregate(const std::string& scenario, std::vector<SeedRun> runs);

/// aggregate.md: a summary table (mean ± sd) and the per-seed rows.
std::string format_markdown(const SweepAggregate& a);
/// aggregate.csv: one row per seed.
std::string format_csv(const SweepAggregate& a);
/// aggregate.json: the summaries and per-seed rows.
std::string format_json(const SweepAggregate& a);

/// The sweep figure: ATE RMSE (mm) per seed, PE-SLAM as filled dots and the
/// baseline as hollow squares when present, with the means as dashed lines.
eval::Figure make_sweep_figure(const SweepAggregate& a);

}  // namespace pvb::suite
