// Fuzz target: the TUM trajectory reader (eval::parse_tum), then what every
// command does with a trajectory it read: association with itself and
// writing it back.  Any input must give a trajectory or a pvb::Error.
#include <cstddef>
#include <cstdint>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/eval/associate.hpp"
#include "pvb/eval/trajectory.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const pvb::eval::Trajectory t = pvb::eval::parse_tum(text, "fuzz.txt");
    (void)pvb::eval::associate(t, t);
    (void)pvb::eval::format_tum(t);
  } catch (const pvb::Error&) {
  }
  return 0;
}
