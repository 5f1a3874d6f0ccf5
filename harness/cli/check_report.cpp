#include "check_report.hpp"

#include <cstdio>
#include <vector>

#include "pvb/scenes/scenario.hpp"
#include "pvb/suite/check.hpp"
#include "pvb/suite/metrics_file.hpp"

namespace pvb::cli {

int check_and_print(const std::string& scenario_file, const std::string& metrics_path,
                    std::optional<std::uint64_t> seed, int no_expect_code) {
  const scenes::Scenario s = scenes::load_scenario(scenario_file);
  if (!s.expect.any()) {
    std::printf("%s: no expect: section, nothing to check\n", scenario_file.c_str());
    return no_expect_code;
  }
  // The run must be one of this scenario and seed: another's metrics would
  // be judged by the wrong bounds, or stand for a run that was not made.
  const suite::MetricsFile metrics = suite::read_metrics_file(metrics_path);
  const std::string seed_source =
      seed ? std::string("--seed")
           : "the scenario's seed" +
                 (metrics.seed ? "; give --seed " + std::to_string(*metrics.seed) + " for a run of that seed"
                               : std::string());
  suite::expect_run_identity(metrics, s.name, scenario_file, seed.value_or(s.seed), seed_source);
  std::vector<std::string> notes;
  const std::vector<suite::Violation> violations = suite::check_expectations(s.expect, metrics, &notes);
  if (s.expect.sweep.any())
    notes.push_back("expect.sweep is judged over seeds: pvbench sweep --scenario " + scenario_file +
                    " --compare --check");
  for (const auto& n : notes) std::printf("%s: note: %s\n", metrics_path.c_str(), n.c_str());
  for (const auto& v : violations) std::printf("%s: %s\n", metrics_path.c_str(), v.line().c_str());
  if (violations.empty()) std::printf("%s: ok (%s)\n", metrics_path.c_str(), s.name.c_str());
  std::fflush(stdout);
  return violations.empty() ? 0 : kViolationExit;
}

}  // namespace pvb::cli
