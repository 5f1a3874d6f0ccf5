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

// Blocks freed below one still in use stay in the heap: free() returns
// only the heap's top to the system, so the pages stay resident until
// return_free_heap() gives them back.
TEST(Memory, FreePagesInsideTheHeapAreGivenBack) {
#if PVB_ADDRESS_SANITIZER
  GTEST_SKIP() << "AddressSanitizer's allocator keeps freed blocks in quarantine";
#else
  constexpr std::size_t kBlock = 64u << 10, kBlocks = 1024;  // 64 MB below malloc's mmap threshold
  std::vector<char*> blocks(kBlocks);
  for (char*& b : blocks) {
    b = static_cast<char*>(std::malloc(kBlock));
    ASSERT_NE(b, nullptr);
    std::memset(b, 1, kBlock);
  }
  char* pin = blocks.back();  // the newest block keeps the heap's top in use
  blocks.pop_back();
  for (char* b : blocks) std::free(b);
  const std::size_t held = pvb::resident_bytes();
  const std::size_t given = pvb::return_free_heap();
  EXPECT_GE(given, kBlock * kBlocks / 2);
  EXPECT_LE(pvb::resident_bytes() + given / 2, held);
  std::free(pin);
#endif
}
