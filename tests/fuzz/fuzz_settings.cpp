// Fuzz target: the ORB-SLAM2 settings reader (slam::read_settings).  Any
// input must give a Settings or a pvb::Error; a crash, a sanitizer report,
// another exception or a hang is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "pvb/common/error.hpp"
#include "pvb/slam/core/settings.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = pvb::fuzz::write_input("settings.yaml", data, size);
  try {
    pvb::slam::read_settings(path);
  } catch (const pvb::Error&) {
  }
  return 0;
}
