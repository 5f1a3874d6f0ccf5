// pvbench check: compares a run's metrics.json with the `expect:` section of
// its scenario.  Prints one line per violated bound and exits 3, or prints
// "ok" and exits 0.
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "check_report.hpp"
#include "command.hpp"
#include "count_option.hpp"

namespace pvb::cli {
namespace {

struct CheckArgs {
  std::string scenario;
  std::string metrics;
  std::optional<std::uint64_t> seed;
};

int run_check(const CheckArgs& a) { return check_and_print(a.scenario, a.metrics, a.seed, 0); }

}  // namespace

Command add_check_command(CLI::App& app) {
  auto args = std::make_shared<CheckArgs>();
  CLI::App* sub = app.add_subcommand(
      "check",
      "Compare a run's metrics.json with its scenario's expect: bounds (exit 3 when one is violated)");
  sub->add_option("--scenario", args->scenario, "scenario YAML file with an expect: section")
      ->required()
      ->check(path_check("check", "--scenario"));
  sub->add_option("--metrics", args->metrics, "metrics.json written by pvbench run")
      ->required()
      ->check(path_check("check", "--metrics"));
  sub->add_option("--seed", args->seed, "the seed the run used, when it overrode the scenario's")
      ->check(seed_check("check", "--seed", std::numeric_limits<std::uint64_t>::max()));
  return {sub, [args] { return run_check(*args); }};
}

}  // namespace pvb::cli
