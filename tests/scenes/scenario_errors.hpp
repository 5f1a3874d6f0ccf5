#pragma once
// What the scenario reader's tests share (test_scenario.cpp,
// test_scenario_events.cpp): the smallest scenario and the error a text gives.
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/scenes/scenario.hpp"

namespace pvb::test {

/// A route and nothing else: every other key at its default.
inline constexpr const char* kMinimal = "route: {waypoints_m: [[0, 0], [5, 0]]}\n";

/// The error message parse_scenario gives for `yaml`, or "" if it parses.
inline std::string error_of(const std::string& yaml) {
  try {
    scenes::parse_scenario(yaml, "bad.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace pvb::test
