#pragma once
// Scratch storage for what a bounded map moves out of memory.  Records are
// compressed (zstd, level 1) into one temporary file that is unlinked as
// soon as it is made, so nothing is left behind whatever way the process
// ends.  A record is read back by the extent its write returned; a released
// extent's bytes are reused by later writes that fit in them.
//
// Not thread-safe: the owner serialises calls (the dense mapper holds its
// mutex).  Reads are pread(2), so const readers never move a shared offset.
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

namespace pvb::slam::dense {

class SpillFile {
 public:
  /// Where a record lies and how long it is, stored and uncompressed.
  struct Extent {
    std::uint64_t offset = 0;
    std::uint32_t stored_bytes = 0;
    std::uint32_t raw_bytes = 0;
  };

  /// The file is made in `dir` (empty: the system's temporary directory) at
  /// the first write, so a map that never spills makes none.
  explicit SpillFile(std::string dir = {});
  ~SpillFile();
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  /// Compresses and stores `raw` (under 4 GiB); throws pvb::IoError naming
  /// the directory when the file cannot be made or written (disk full).
  Extent write(const std::string& raw);
  /// The record as it was written; throws pvb::IoError on a short read or
  /// bytes that do not decompress to the length written.
  std::string read(const Extent& e) const;
  /// The record is no longer needed: its bytes may be reused.
  void release(const Extent& e);

  /// Bytes the file spans on disk, and those its live records hold.
  std::uint64_t file_bytes() const { return end_; }
  std::uint64_t live_bytes() const { return live_; }
  /// Uncompressed bytes of the live records.
  std::uint64_t live_raw_bytes() const { return live_raw_; }
  std::uint64_t writes() const { return writes_; }
  std::uint64_t reads() const { return reads_; }

 private:
  void open();
  std::string label() const;  ///< the name errors give: the folder, or "spill file"
  std::string dir_;
  int fd_ = -1;
  std::uint64_t end_ = 0, live_ = 0, live_raw_ = 0, writes_ = 0;
  mutable std::uint64_t reads_ = 0;
  std::multimap<std::uint32_t, std::uint64_t> free_;  ///< size -> offset of reusable holes
};

}  // namespace pvb::slam::dense
