#pragma once
#include <cstdint>

namespace pvb {

/// Set bits of a 64-bit word: the POPCNT instruction where the build
/// targets it, else the parallel bit count inline (without -mpopcnt GCC
/// makes __builtin_popcountll a call into libgcc, three times slower for
/// descriptor distances).
inline int popcount64(std::uint64_t x) {
#if defined(__POPCNT__)
  return __builtin_popcountll(x);
#else
  x -= (x >> 1) & 0x5555555555555555ULL;
  x = (x & 0x3333333333333333ULL) + ((x >> 2) & 0x3333333333333333ULL);
  x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0FULL;
  return static_cast<int>((x * 0x0101010101010101ULL) >> 56);
#endif
}

}  // namespace pvb
