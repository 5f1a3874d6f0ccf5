#pragma once
// The hand-written metrics.json and campaign files under fixtures/.
#include <string>

namespace pvb::test {

inline std::string suite_fixture(const std::string& name) {
  return std::string(PVB_SOURCE_DIR) + "/tests/harness/suite/fixtures/" + name;
}

}  // namespace pvb::test
