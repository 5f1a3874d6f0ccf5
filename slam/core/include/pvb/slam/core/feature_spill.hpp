#pragma once
// Keyframe features on disk: a file-backed arena for the arrays a keyframe
// far from the robot keeps for matching (keypoints, descriptors, depths,
// the grid).  The arrays stay where code reads them (a shared mapping of
// an unlinked file in the temporary folder), so every reader works
// unchanged; release_resident() writes the pages out and drops them from
// the process and from the page cache, and a later read brings back the
// pages it touches.  Blocks are handed out in order and never reused; a
// freed block's whole pages are punched out of the file.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <type_traits>
#include <utility>
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
  /// Writes n bytes into a block from allocate() through the file, not the
  /// mapping (which then reads them): no page of the block is faulted in,
  /// which costs a trap per page.  Throws IoError when the write fails.
  void store(void* block, const void* src, std::size_t n);
  /// Gives back a block from allocate(): its whole pages leave the file.
  void deallocate(void* p, std::size_t n);
  /// The file's owner is going away: blocks freed from now on are counted
  /// but not punched out of the file (the whole file goes with the last
  /// user), so tearing down a map of 10,000 keyframes costs no syscalls.
  void discard() { discarding_ = true; }
  /// Writes dirty pages to the file and drops every page from the
  /// process's resident set and from the page cache.  Safe while other
  /// threads read or write blocks: a page touched afterwards is read back.
  void release_resident();
  /// Drops every page from the process's resident set only: dirty pages
  /// stay in the page cache and go to the file with the kernel's writeback,
  /// and a later read takes them from the cache without a disk read while
  /// they are still there.  For passes that touch many keyframes at once
  /// (a map's load and save).
  void drop_from_process();
  /// Reads the whole file into the page cache in large sequential reads,
  /// ahead of a pass that reads every block (a map's save), so that the
  /// pass does not fault its pages in from the disk one by one; until
  /// end_read_ahead() a fault maps the cached pages around it too.  The
  /// cache is the kernel's to reclaim: nothing is added to the process.
  void read_ahead();
  /// Back to faulting single pages (keyframes are read one at a time).
  void end_read_ahead();
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
  std::atomic<bool> discarding_{false};
  FeatureSpillStats stats_;
  std::unique_ptr<cv::MatAllocator> mat_allocator_;
};

/// Elements whose bytes may be written straight into a spill's file.
template <typename T>
inline constexpr bool kPlainBytes = std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>;

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
  /// In a spill, resize() leaves plain-bytes elements (trivially copyable
  /// and destructible) as they are, for spilled_copy to fill through the
  /// file; on the heap they are value-initialised as usual.
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) == 0 && kPlainBytes<U>) {
      if (spill_) {
        (void)p;
        return;
      }
    }
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
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

/// A copy of v inside `spill` (capacity = size), written through the file.
template <typename T>
FeatureArray<T> spilled_copy(const FeatureArray<T>& v, FeatureSpill* spill) {
  FeatureArray<T> out{SpillAllocator<T>(spill)};
  out.reserve(v.size());
  if constexpr (kPlainBytes<T>) {
    out.resize(v.size());  // not touched (SpillAllocator::construct)
    if (!v.empty()) spill->store(out.data(), v.data(), v.size() * sizeof(T));
  } else {
    out.assign(v.begin(), v.end());
  }
  return out;
}

}  // namespace pvb::slam
