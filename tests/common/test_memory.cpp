// Heap block sizes against glibc's own, and the resident set.
#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdlib>
#include <cstring>
#include <vector>

#include "pvb/common/memory.hpp"
#include "sanitizers.hpp"

TEST(Memory, HeapBlockBytesIsWhatMallocReserves) {
#if PVB_ADDRESS_SANITIZER
  GTEST_SKIP() << "heap_block_bytes models glibc's malloc; AddressSanitizer's allocator sizes blocks its own way";
#endif
  // malloc_usable_size is the block less its 8-byte header.
  for (std::size_t n : {1u, 8u, 24u, 25u, 40u, 41u, 100u, 1000u, 4096u, 30000u, 100000u}) {
    void* p = std::malloc(n);
    ASSERT_NE(p, nullptr);
    EXPECT_EQ(pvb::heap_block_bytes(n), malloc_usable_size(p) + 8) << n;
    std::free(p);
  }
  EXPECT_EQ(pvb::heap_block_bytes(0), 0u);
}

TEST(Memory, ContainersCountTheirCapacity) {
  std::vector<double> v;
  v.reserve(100);
  EXPECT_EQ(pvb::vector_heap_bytes(v), pvb::heap_block_bytes(800));
  std::map<int, double> m = {{1, 1.0}, {2, 2.0}};
  EXPECT_EQ(pvb::map_node_bytes(m), 2 * pvb::heap_block_bytes(32 + 16));
}

TEST(Memory, ResidentSetGrowsWithTouchedMemory) {
  const std::size_t before = pvb::resident_bytes();
  ASSERT_GT(before, 0u);
  constexpr std::size_t kBytes = 64u << 20;
  std::vector<char> big(kBytes);
  std::memset(big.data(), 1, big.size());
  const std::size_t after = pvb::resident_bytes();
  EXPECT_GE(after, before + kBytes * 9 / 10);
  EXPECT_EQ(big[kBytes - 1], 1);
}
