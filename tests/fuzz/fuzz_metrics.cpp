// Fuzz target: the metrics.json reader of `pvbench check` and `pvbench
// sweep` (suite::read_metrics_file).  Any input must give metrics or a
// pvb::Error.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "pvb/common/error.hpp"
#include "pvb/suite/metrics_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = pvb::fuzz::write_input("metrics.json", data, size);
  try {
    pvb::suite::read_metrics_file(path);
  } catch (const pvb::Error&) {
  }
  return 0;
}
