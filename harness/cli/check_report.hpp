#pragma once
// Shared by `pvbench check` and `pvbench run --check`: judge a metrics.json
// by its scenario's expect: bounds and print the verdict.
#include <cstdint>
#include <optional>
#include <string>

namespace pvb::cli {

/// Exit status when a bound is violated (1 and 2 are errors, see main.cpp).
constexpr int kViolationExit = 3;

/// Prints one line per violated bound (or one "ok" line) and returns 0 or
/// kViolationExit.  A scenario without an expect: section prints so and
/// returns `no_expect_code`.  The metrics must be of the scenario and of
/// `seed` (nullopt: the scenario's own seed).  Throws pvb::Error for a bad
/// scenario or file, or metrics of another run.
int check_and_print(const std::string& scenario_file, const std::string& metrics_path,
                    std::optional<std::uint64_t> seed, int no_expect_code);

}  // namespace pvb::cli
