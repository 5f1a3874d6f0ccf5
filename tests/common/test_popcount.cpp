// popcount64 against counting the bits one by one, on words from a seeded
// generator and on the edge words.
#include "pvb/common/popcount.hpp"

#include <gtest/gtest.h>

#include <random>

namespace {

int bits_one_by_one(std::uint64_t x) {
  int n = 0;
  for (; x; x >>= 1) n += static_cast<int>(x & 1);
  return n;
}

}  // namespace

TEST(Popcount, CountsTheSetBitsOfAnyWord) {
  for (std::uint64_t x : {0ULL, 1ULL, ~0ULL, 0x8000000000000000ULL, 0x5555555555555555ULL, 0xF0F0F0F0F0F0F0F0ULL})
    EXPECT_EQ(pvb::popcount64(x), bits_one_by_one(x)) << x;
  std::mt19937_64 rng(7);
  for (int i = 0; i < 10000; ++i) {
    const std::uint64_t x = rng();
    ASSERT_EQ(pvb::popcount64(x), bits_one_by_one(x)) << x;
  }
}
