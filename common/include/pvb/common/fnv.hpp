#pragma once
// FNV-1a (64-bit): the checksum of our binary files (vocabulary, map) and
// the fingerprint of what they depend on.  Not a cryptographic hash: it
// finds damaged files and mix-ups, not forgeries.
#include <cstddef>
#include <cstdint>

namespace pvb {

constexpr std::uint64_t kFnv1a64Offset = 14695981039346656037ULL;

/// FNV-1a of n bytes, continuing from `h` (the offset basis for a new hash).
inline std::uint64_t fnv1a64(const void* data, std::size_t n, std::uint64_t h = kFnv1a64Offset) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ULL;
  }
  return h;
}

}  // namespace pvb
