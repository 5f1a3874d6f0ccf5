// Fuzz target: the .oni record scanner (openni::scan_oni_file and
// check_oni_complete), which sees every recording before libOpenNI2 does.
// Any input must give a summary or a pvb::Error.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "pvb/common/error.hpp"
#include "pvb/openni/oni_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = pvb::fuzz::write_input("input.oni", data, size);
  try {
    const pvb::openni::OniFileSummary s = pvb::openni::scan_oni_file(path);
    pvb::openni::check_oni_complete(path, s);
  } catch (const pvb::Error&) {
  }
  return 0;
}
