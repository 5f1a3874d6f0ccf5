// Fuzz target: the scenario reader (scenes::parse_scenario).  Any input
// must give a Scenario or a pvb::Error.
#include <cstddef>
#include <cstdint>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/scenes/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const pvb::scenes::Scenario s = pvb::scenes::parse_scenario(text, "fuzz.yaml");
    (void)pvb::scenes::frame_count(s);
  } catch (const pvb::Error&) {
  }
  return 0;
}
