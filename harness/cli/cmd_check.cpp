// pvbench check: compares a run's metrics.json with the `expect:` section of
// its scenario.  Prints one line per violated bound and exits 3, or prints
// "ok" and exits 0.
#include <cstdio>
#include <memory>
#include <string>

#include "command.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/suite/check.hpp"

namespace pvb::cli {
namespace {

/// Exit status when a bound is violated (1 and 2 are errors, see main.cpp).
constexpr int kViolationExit = 3;

struct CheckArgs {
  std::string scenario;
  std::string metrics;
};

int run_check(const CheckArgs& a) {
  const scenes::Scenario s = scenes::load_scenario(a.scenario);
  if (!s.expect.any()) {
    std::printf("%s: no expect: section, nothing to check\n", a.scenario.c_str());
    return 0;
  }
  const std::vector<suite::Violation> violations = suite::check_expectations(s.expect, a.metrics);
  for (const auto& v : violations) std::printf("%s: %s\n", a.metrics.c_str(), v.line().c_str());
  if (violations.empty()) std::printf("%s: ok (%s)\n", a.metrics.c_str(), s.name.c_str());
  std::fflush(stdout);
  return violations.empty() ? 0 : kViolationExit;
}

}  // namespace

Command add_check_command(CLI::App& app) {
  auto args = std::make_shared<CheckArgs>();
  CLI::App* sub = app.add_subcommand(
      "check",
      "Compare a run's metrics.json with its scenario's expect: bounds (exit 3 when one is violated)");
  sub->add_option("--scenario", args->scenario, "scenario YAML file with an expect: section")->required();
  sub->add_option("--metrics", args->metrics, "metrics.json written by pvbench run")->required();
  return {sub, [args] { return run_check(*args); }};
}

}  // namespace pvb::cli
