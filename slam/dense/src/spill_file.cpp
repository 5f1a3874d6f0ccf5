#include "pvb/slam/dense/spill_file.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <utility>
#include <vector>

#include "pvb/common/error.hpp"

namespace pvb::slam::dense {
namespace {
constexpr std::uint32_t kMinHole = 64;  // smaller remainders are not worth keeping
}

std::string SpillFile::label() const { return dir_.empty() ? "spill file" : dir_; }

SpillFile::SpillFile(std::string dir) : dir_(std::move(dir)) {}

SpillFile::~SpillFile() {
  if (fd_ >= 0) ::close(fd_);
}

void SpillFile::open() {
  std::string dir = dir_;
  if (dir.empty()) {
    std::error_code ec;
    dir = std::filesystem::temp_directory_path(ec).string();
    if (ec) dir = "/tmp";
  }
  std::string path = dir + "/pvb-spill-XXXXXX";
  std::vector<char> name(path.begin(), path.end());
  name.push_back('\0');
  fd_ = ::mkstemp(name.data());
  if (fd_ < 0) throw IoError(dir, std::string("cannot make a spill file: ") + std::strerror(errno));
  ::unlink(name.data());  // gone from the folder now; the space goes back when the descriptor closes
}

SpillFile::Extent SpillFile::write(const std::string& raw) {
  if (raw.size() >= (std::uint64_t(1) << 32)) throw Error("SpillFile: a record of 4 GiB or more");
  if (fd_ < 0) open();
  std::vector<char> packed(ZSTD_compressBound(raw.size()));
  const std::size_t n = ZSTD_compress(packed.data(), packed.size(), raw.data(), raw.size(), 1);
  if (ZSTD_isError(n)) throw Error(std::string("SpillFile: zstd could not compress a record: ") + ZSTD_getErrorName(n));
  Extent e;
  e.stored_bytes = static_cast<std::uint32_t>(n);
  e.raw_bytes = static_cast<std::uint32_t>(raw.size());
  auto hole = free_.lower_bound(e.stored_bytes);
  if (hole != free_.end()) {
    e.offset = hole->second;
    const std::uint32_t rest = hole->first - e.stored_bytes;
    free_.erase(hole);
    if (rest >= kMinHole) free_.emplace(rest, e.offset + e.stored_bytes);
  } else {
    e.offset = end_;
    end_ += e.stored_bytes;
  }
  std::size_t done = 0;
  while (done < n) {
    const ssize_t w = ::pwrite(fd_, packed.data() + done, n - done, static_cast<off_t>(e.offset + done));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) throw IoError(label(), std::string("cannot write: ") + std::strerror(errno));
    done += static_cast<std::size_t>(w);
  }
  live_ += e.stored_bytes;
  live_raw_ += e.raw_bytes;
  ++writes_;
  return e;
}

std::string SpillFile::read(const Extent& e) const {
  std::vector<char> packed(e.stored_bytes);
  std::size_t done = 0;
  while (done < packed.size()) {
    const ssize_t r = ::pread(fd_, packed.data() + done, packed.size() - done, static_cast<off_t>(e.offset + done));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) throw IoError(label(), "short read at offset " + std::to_string(e.offset));
    done += static_cast<std::size_t>(r);
  }
  std::string raw(e.raw_bytes, '\0');
  const std::size_t n = ZSTD_decompress(raw.data(), raw.size(), packed.data(), packed.size());
  if (ZSTD_isError(n) || n != e.raw_bytes)
    throw IoError(label(), "a record at offset " + std::to_string(e.offset) + " does not decompress");
  ++reads_;
  return raw;
}

void SpillFile::release(const Extent& e) {
  if (e.stored_bytes == 0) return;
  live_ -= e.stored_bytes;
  live_raw_ -= e.raw_bytes;
  if (e.offset + e.stored_bytes == end_) end_ = e.offset;  // the tail: the file shrinks back
  else free_.emplace(e.stored_bytes, e.offset);
}

}  // namespace pvb::slam::dense
