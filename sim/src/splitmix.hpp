#pragma once
// splitmix64: a fast generator whose output is fully specified, so noise is
// identical on every platform.  One stream per (seed, stream) pair.
#include <cstdint>

namespace pvb::sim {

struct SplitMix {
  explicit SplitMix(std::uint64_t seed, std::uint64_t stream)
      : s(seed * 0x9E3779B97F4A7C15ull ^ (stream + 0x2545F4914F6CDD1Dull) * 0xBF58476D1CE4E5B9ull) {}
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in (0, 1): 53 random bits, never 0.
  double uniform() { return (static_cast<double>(next() >> 11) + 0.5) * (1.0 / 9007199254740992.0); }
  std::uint64_t s;
};

}  // namespace pvb::sim
