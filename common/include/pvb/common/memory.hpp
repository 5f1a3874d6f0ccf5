#pragma once
// Memory accounting: what a heap block costs, and the process's resident
// set.  Per-structure figures built from heap_block_bytes() (keyframes, map
// points, dense clouds; docs/slam.md, "Keyframe memory") add up to what the
// process holds, which resident_bytes() confirms from outside.
#include <cstddef>
#include <map>
#include <unordered_map>
#include <utility>
#include <vector>

namespace pvb {

/// Bytes that a heap block of n requested bytes occupies under glibc's
/// malloc: an 8-byte header, 16-byte granularity, at least 32 bytes; 0 for
/// n = 0.  Blocks large enough to be mapped on their own round to pages
/// instead, which this ignores (under 0.1 % for them).
std::size_t heap_block_bytes(std::size_t n);

/// Heap bytes of a vector's buffer (its capacity, not its size).
template <typename T>
std::size_t vector_heap_bytes(const std::vector<T>& v) {
  return heap_block_bytes(v.capacity() * sizeof(T));
}

/// Heap bytes of a std::map's nodes (libstdc++: four words of tree links,
/// then the value), not counting what the values own.
template <typename K, typename V>
std::size_t map_node_bytes(const std::map<K, V>& m) {
  return m.size() * heap_block_bytes(4 * sizeof(void*) + sizeof(std::pair<const K, V>));
}

/// Heap bytes of a std::unordered_map's nodes and bucket array (libstdc++:
/// a link word, then the value; hash codes not stored, as for integer keys),
/// not counting what the values own.
template <typename K, typename V, typename H, typename E, typename A>
std::size_t unordered_map_bytes(const std::unordered_map<K, V, H, E, A>& m) {
  const std::size_t buckets = m.bucket_count() > 1 ? heap_block_bytes(m.bucket_count() * sizeof(void*)) : 0;
  return m.size() * heap_block_bytes(sizeof(void*) + sizeof(std::pair<const K, V>)) + buckets;
}

/// The process's resident set (VmRSS of /proc/self/status), bytes; 0 where
/// it cannot be read.
std::size_t resident_bytes();

/// Hands the pages that the allocator holds free back to the system
/// (glibc's malloc_trim: free pages inside every arena, not only at the
/// heap's top).  A long run whose threads free and allocate in turn keeps
/// hundreds of megabytes free in its arenas otherwise.  Returns the
/// resident bytes it gave back (0 where nothing was, or the set cannot be
/// read).
std::size_t return_free_heap();

}  // namespace pvb
