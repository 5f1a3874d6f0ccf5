#pragma once
// Keyframe features on disk: a file-backed arena for the arrays a keyframe
// far from the robot keeps for matching (keypoints, descriptors, depths,
// the grid).  The arrays stay where code reads them (a shared mapping of
// an unlinked file in the temporary folder), so every reader works
// unchanged; release_resident() writes the pages out and drops them from
// the process and from the page cache, and a later read brings back the
// pages it touches.  Blocks are handed out in order and never reused; a
// freed block's whole pages are punched out of the file.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

#include "pvb/common/memory.hpp"

namespace cv {
class MatAllocator;
}

namespace pvb::slam {

struct FeatureSpillStats {
  std::uint64_t allocated_bytes = 0;  ///< handed out, all time
  std::uint64_t freed_bytes = 0;      ///< given back (culled keyframes)
  std::uint64_t file_bytes = 0;       ///< the file's length (mapped)
  std::uint64_t releases = 0;         ///< release_resident() calls
  std::uint64_t live_bytes() const { return allocated_bytes - freed_bytes; }
};

class FeatureSpill {
 public:
  /// Makes an unlinked file in `dir` (empty: $TMPDIR, else /tmp); throws
  /// IoError when it cannot.  The file grows in chunks of chunk_bytes.
  explicit FeatureSpill(std::string dir = {}, std::size_t chunk_bytes = std::size_t(64) << 20);
  ~FeatureSpill();
  FeatureSpill(const FeatureSpill&) = delete;
  FeatureSpill& operator=(const FeatureSpill&) = delete;

  /// n bytes, 64-byte aligned, inside the mapping (n ≤ chunk_bytes).
  void* allocate(std::size_t n);
  /// Gives back a block from allocate(): its whole pages leave the file.
  void deallocate(void* p, std::size_t n);
  /// Writes dirty pages to the file and drops every page from the
  /// process's resident set and from the page cache.  Safe while other
  /// threads read or write blocks: a page touched afterwards is read back.
  void release_resident();
  /// Pages of the mapping resident in this process now (mincore).
  std::size_t resident_bytes() const;
  FeatureSpillStats stats() const;
  /// OpenCV's hook for a cv::Mat whose data lies in this spill: set it as
  /// the matrix's allocator before create(); copies share the block, the
  /// last one frees it.
  cv::MatAllocator* mat_allocator() const { return mat_allocator_.get(); }

 private:
  struct Chunk {
    char* base = nullptr;
    std::uint64_t offset = 0;  ///< in the file
  };
  void add_chunk();

  std::string dir_;
  std::size_t chunk_bytes_;
  int fd_ = -1;
  mutable std::mutex mutex_;
  std::vector<Chunk> chunks_;
  std::size_t used_in_last_ = 0;  ///< bytes handed out of the newest chunk
  FeatureSpillStats stats_;
  std::unique_ptr<cv::MatAllocator> mat_allocator_;
};

/// A std::allocator that allocates in a FeatureSpill, or on the heap when
/// it has none.  Moves and swaps carry it along; a copy of a container goes
/// to the heap, so a copied frame never refers to a spill it does not keep.
template <typename T>
class SpillAllocator {
 public:
  using value_type = T;
  using propagate_on_container_move_assignment = std::true_type;
  using propagate_on_container_swap = std::true_type;
  using propagate_on_container_copy_assignment = std::false_type;
  using is_always_equal = std::false_type;

  SpillAllocator() noexcept = default;
  explicit SpillAllocator(FeatureSpill* spill) noexcept : spill_(spill) {}
  template <typename U>
  SpillAllocator(const SpillAllocator<U>& o) noexcept : spill_(o.spill()) {}  // NOLINT: rebinding

  T* allocate(std::size_t n) {
    if (!spill_) return std::allocator<T>().allocate(n);
    return static_cast<T*>(spill_->allocate(n * sizeof(T)));
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (!spill_) return std::allocator<T>().deallocate(p, n);
    spill_->deallocate(p, n * sizeof(T));
  }
  SpillAllocator select_on_container_copy_construction() const noexcept { return SpillAllocator(); }
  FeatureSpill* spill() const noexcept { return spill_; }

 private:
  FeatureSpill* spill_ = nullptr;
};

template <typename T, typename U>
bool operator==(const SpillAllocator<T>& a, const SpillAllocator<U>& b) noexcept {
  return a.spill() == b.spill();
}
template <typename T, typename U>
bool operator!=(const SpillAllocator<T>& a, const SpillAllocator<U>& b) noexcept {
  return !(a == b);
}

/// A per-keypoint array of a frame: on the heap, or in a FeatureSpill.
template <typename T>
using FeatureArray = std::vector<T, SpillAllocator<T>>;

/// Heap bytes of an array (0 when it lies in a spill).
template <typename T>
std::size_t feature_heap_bytes(const FeatureArray<T>& v) {
  return v.get_allocator().spill() ? 0 : heap_block_bytes(v.capacity() * sizeof(T));
}
/// Bytes of an array that lie in a spill (0 on the heap).
template <typename T>
std::size_t feature_spilled_bytes(const FeatureArray<T>& v) {
  return v.get_allocator().spill() ? v.capacity() * sizeof(T) : 0;
}

/// A copy of v inside `spill` (capacity = size).
template <typename T>
FeatureArray<T> spilled_copy(const FeatureArray<T>& v, FeatureSpill* spill) {
  FeatureArray<T> out{SpillAllocator<T>(spill)};
  out.reserve(v.size());
  out.assign(v.begin(), v.end());
  return out;
}

}  // namespace pvb::slam
