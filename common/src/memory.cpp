#include "pvb/common/memory.hpp"

#include <fstream>
#include <string>

namespace pvb {

std::size_t heap_block_bytes(std::size_t n) {
  if (n == 0) return 0;
  constexpr std::size_t kHeader = 8, kAlign = 16, kMinBlock = 32;
  const std::size_t block = (n + kHeader + kAlign - 1) / kAlign * kAlign;
  return block < kMinBlock ? kMinBlock : block;
}

std::size_t resident_bytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      std::size_t kib = 0;
      status >> kib;
      return kib * 1024;
    }
    status.ignore(4096, '\n');
  }
  return 0;
}

}  // namespace pvb
