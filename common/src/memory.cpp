#include "pvb/common/memory.hpp"

#include <malloc.h>

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

std::size_t return_free_heap() {
  const std::size_t before = resident_bytes();
  malloc_trim(0);
  const std::size_t after = resident_bytes();
  return before > after ? before - after : 0;
}

}  // namespace pvb
