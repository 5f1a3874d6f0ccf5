#include "pvb/slam/core/feature_spill.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>

#include "pvb/common/error.hpp"

namespace pvb::slam {
namespace {

constexpr std::size_t kAlign = 64;

std::size_t page_bytes() {
  static const std::size_t n = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  return n;
}

std::string temp_dir(const std::string& dir) {
  if (!dir.empty()) return dir;
  std::error_code ec;
  const std::string t = std::filesystem::temp_directory_path(ec).string();
  return ec ? std::string("/tmp") : t;
}

/// cv::Mat data in a FeatureSpill, as OpenCV's own allocator lays it out.
class SpillMatAllocator : public cv::MatAllocator {
 public:
  explicit SpillMatAllocator(FeatureSpill* spill) : spill_(spill) {}
  cv::UMatData* allocate(int dims, const int* sizes, int type, void* data0, size_t* step, cv::AccessFlag,
                         cv::UMatUsageFlags) const override {
    std::size_t total = CV_ELEM_SIZE(type);
    for (int i = dims - 1; i >= 0; --i) {
      if (step) {
        if (data0 && step[i] != cv::Mat::AUTO_STEP)
          total = step[i];
        else
          step[i] = total;
      }
      total *= static_cast<std::size_t>(sizes[i]);
    }
    auto* data = static_cast<uchar*>(data0 ? data0 : spill_->allocate(total));
    auto* u = new cv::UMatData(this);
    u->data = u->origdata = data;
    u->size = total;
    if (data0) u->flags |= cv::UMatData::USER_ALLOCATED;
    return u;
  }
  bool allocate(cv::UMatData* u, cv::AccessFlag, cv::UMatUsageFlags) const override { return u != nullptr; }
  void deallocate(cv::UMatData* u) const override {
    if (!u) return;
    if (!(u->flags & cv::UMatData::USER_ALLOCATED)) spill_->deallocate(u->origdata, u->size);
    delete u;
  }

 private:
  FeatureSpill* spill_;
};

}  // namespace

FeatureSpill::FeatureSpill(std::string dir, std::size_t chunk_bytes)
    : dir_(temp_dir(dir)), chunk_bytes_((chunk_bytes + page_bytes() - 1) / page_bytes() * page_bytes()) {
  std::string path = dir_ + "/pvb-features-XXXXXX";
  std::vector<char> name(path.begin(), path.end());
  name.push_back('\0');
  fd_ = ::mkstemp(name.data());
  if (fd_ < 0) throw IoError(dir_, std::string("cannot make a keyframe feature file: ") + std::strerror(errno));
  ::unlink(name.data());  // gone from the folder; the space goes back when the descriptor closes
  mat_allocator_ = std::make_unique<SpillMatAllocator>(this);
}

FeatureSpill::~FeatureSpill() {
  for (const Chunk& c : chunks_) ::munmap(c.base, chunk_bytes_);
  if (fd_ >= 0) ::close(fd_);
}

void FeatureSpill::add_chunk() {
  const std::uint64_t offset = stats_.file_bytes;
  // Reserved on disk now, so a full disk is this one error and never a
  // fault when a page of the mapping is first written.
  if (const int err = ::posix_fallocate(fd_, static_cast<off_t>(offset), static_cast<off_t>(chunk_bytes_)); err != 0)
    throw IoError(dir_, "cannot grow the keyframe feature file by " + std::to_string(chunk_bytes_ >> 20) +
                            " MB: " + std::strerror(err));
  void* p = ::mmap(nullptr, chunk_bytes_, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, static_cast<off_t>(offset));
  if (p == MAP_FAILED)
    throw IoError(dir_, std::string("cannot map the keyframe feature file: ") + std::strerror(errno));
  // Reads come back a keyframe at a time: no read-ahead of the neighbours.
  ::madvise(p, chunk_bytes_, MADV_RANDOM);
  chunks_.push_back({static_cast<char*>(p), offset});
  stats_.file_bytes = offset + chunk_bytes_;
  used_in_last_ = 0;
}

void* FeatureSpill::allocate(std::size_t n) {
  if (n == 0) n = 1;
  const std::size_t size = (n + kAlign - 1) / kAlign * kAlign;
  if (size > chunk_bytes_) throw Error("FeatureSpill: a block larger than a chunk");
  std::lock_guard<std::mutex> lock(mutex_);
  if (chunks_.empty() || used_in_last_ + size > chunk_bytes_) add_chunk();
  char* p = chunks_.back().base + used_in_last_;
  used_in_last_ += size;
  stats_.allocated_bytes += size;
  return p;
}

void FeatureSpill::store(void* block, const void* src, std::size_t n) {
  std::uint64_t at = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const char* c = static_cast<const char*>(block);
    const auto k = std::find_if(chunks_.begin(), chunks_.end(),
                                [&](const Chunk& x) { return c >= x.base && c + n <= x.base + chunk_bytes_; });
    if (k == chunks_.end()) throw Error("FeatureSpill::store: not a block of this spill");
    at = k->offset + static_cast<std::uint64_t>(c - k->base);
  }
  const char* from = static_cast<const char*>(src);
  while (n > 0) {
    const ssize_t w = ::pwrite(fd_, from, n, static_cast<off_t>(at));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) throw IoError(dir_, std::string("cannot write the keyframe feature file: ") + std::strerror(errno));
    from += w;
    at += static_cast<std::uint64_t>(w);
    n -= static_cast<std::size_t>(w);
  }
}

void FeatureSpill::deallocate(void* p, std::size_t n) {
  if (p == nullptr) return;
  const std::size_t size = (std::max<std::size_t>(n, 1) + kAlign - 1) / kAlign * kAlign;
  std::lock_guard<std::mutex> lock(mutex_);
  stats_.freed_bytes += size;
  if (discarding_) return;
  const char* c = static_cast<const char*>(p);
  for (const Chunk& k : chunks_) {
    if (c < k.base || c >= k.base + chunk_bytes_) continue;
    // Whole pages inside the block go: dropped from memory and punched out
    // of the file (a neighbour's part of a page stays).
    const std::size_t page = page_bytes();
    const std::size_t begin = (static_cast<std::size_t>(c - k.base) + page - 1) / page * page;
    const std::size_t end = (static_cast<std::size_t>(c - k.base) + size) / page * page;
    if (end > begin) {
      ::madvise(k.base + begin, end - begin, MADV_DONTNEED);
      ::fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, static_cast<off_t>(k.offset + begin),
                  static_cast<off_t>(end - begin));
    }
    return;
  }
}

void FeatureSpill::release_resident() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Chunk& c : chunks_) {
    ::msync(c.base, chunk_bytes_, MS_SYNC);
    ::madvise(c.base, chunk_bytes_, MADV_DONTNEED);
  }
  if (fd_ >= 0) ::posix_fadvise(fd_, 0, 0, POSIX_FADV_DONTNEED);
  ++stats_.releases;
}

void FeatureSpill::drop_from_process() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Chunk& c : chunks_) ::madvise(c.base, chunk_bytes_, MADV_DONTNEED);
}

void FeatureSpill::read_ahead() {
  std::lock_guard<std::mutex> lock(mutex_);
  // posix_fadvise(WILLNEED) reads only one read-ahead window of a range
  // this long, so the file is read through a small buffer instead.
  std::vector<char> buffer(std::size_t(4) << 20);
  for (std::uint64_t at = 0; at < stats_.file_bytes;) {
    const ssize_t n = ::pread(fd_, buffer.data(), buffer.size(), static_cast<off_t>(at));
    if (n <= 0) break;  // a read error only costs the read-ahead
    at += static_cast<std::uint64_t>(n);
  }
  for (const Chunk& c : chunks_) ::madvise(c.base, chunk_bytes_, MADV_SEQUENTIAL);
}

void FeatureSpill::end_read_ahead() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Chunk& c : chunks_) ::madvise(c.base, chunk_bytes_, MADV_RANDOM);
}

std::size_t FeatureSpill::resident_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::size_t page = page_bytes();
  std::vector<unsigned char> in_core(chunk_bytes_ / page);
  std::size_t n = 0;
  for (const Chunk& c : chunks_) {
    if (::mincore(c.base, chunk_bytes_, in_core.data()) != 0) continue;
    for (unsigned char b : in_core) n += (b & 1) ? page : 0;
  }
  return n;
}

FeatureSpillStats FeatureSpill::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace pvb::slam
