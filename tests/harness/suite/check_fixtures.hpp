#pragma once
// What the checker's tests share (test_check.cpp, test_check_sections.cpp):
// a sweep's seed from a fixture with its ATEs replaced, whether a
// violation names a key, and the reader's error on an edited fixture.
#include <cstdint>
#include <string>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
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

/// The fixture `fixture_name` with its first `from` replaced by `to`,
/// written to `path` and read as a metrics file: the reader's error
/// message, "(no error)", or a note when `from` is not in the fixture.
inline std::string metrics_error_after_edit(const std::string& path, const std::string& fixture_name,
                                            const std::string& from, const std::string& to) {
  std::string text = read_file(suite_fixture(fixture_name));
  const std::size_t at = text.find(from);
  if (at == std::string::npos) return "(" + from + " not in " + fixture_name + ")";
  write_file(path, text.replace(at, from.size(), to));
  try {
    suite::read_metrics_file(path);
  } catch (const IoError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace pvb::test
