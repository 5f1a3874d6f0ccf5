#pragma once
// What the checker's tests share (test_check.cpp, test_check_sections.cpp):
// a sweep's seed from a fixture with its ATEs replaced, and whether a
// violation names a key.
#include <cstdint>
#include <string>
#include <vector>

#include "pvb/suite/aggregate.hpp"
#include "pvb/suite/check.hpp"
#include "suite_fixtures.hpp"

namespace pvb::test {

/// A seed of a sweep from a fixture, with its two ATEs (millimetres) replaced.
inline suite::SeedRun seed_run(std::uint64_t seed, double pe_mm, double baseline_mm) {
  suite::SeedRun r = suite::read_seed_run(seed, suite_fixture("good_compare.json"));
  r.metrics->primary.ate_rmse_m = pe_mm / 1000.0;
  r.metrics->baseline->ate_rmse_m = baseline_mm / 1000.0;
  return r;
}

inline bool has_key(const std::vector<suite::Violation>& v, const std::string& key) {
  for (const auto& x : v)
    if (x.key == key) return true;
  return false;
}

}  // namespace pvb::test
