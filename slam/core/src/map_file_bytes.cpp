// A map file's bytes, in memory or read from the file a piece at a time
// (MapFileBytes in map_file.hpp).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/slam/core/map_file.hpp"

namespace pvb::slam {

struct MapFileBytes::File {
  int fd = -1;
  ~File() {
    if (fd >= 0) ::close(fd);
  }
};

MapFileBytes MapFileBytes::open(const std::string& path, std::uint64_t piece_bytes) {
  require_regular_file(path);
  auto f = std::make_shared<File>();
  f->fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (f->fd < 0) throw IoError(path, std::string("cannot open for reading: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(f->fd, &st) != 0) throw IoError(path, "cannot tell its size");
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size > kMaxMapFileBytes)
    throw IoError(path, std::to_string(size) + " bytes, larger than a map file may be (" +
                            std::to_string(kMaxMapFileBytes) + " bytes, 4 GiB)");
  MapFileBytes m;
  m.name_ = path;
  m.size_ = size;
  m.piece_bytes_ = std::max<std::uint64_t>(piece_bytes, 1);
  m.file_ = std::move(f);
  return m;
}

MapFileBytes MapFileBytes::in_memory(const std::string& bytes, std::string name) {
  MapFileBytes m;
  m.name_ = std::move(name);
  m.size_ = bytes.size();
  m.data_ = bytes.data();
  return m;
}

void MapFileBytes::read(std::uint64_t offset, char* out, std::uint64_t n) const {
  if (offset > size_ || n > size_ - offset) throw std::logic_error("MapFileBytes::read: beyond the file");
  if (data_) {
    std::memcpy(out, data_ + offset, static_cast<std::size_t>(n));
    return;
  }
  for (std::uint64_t done = 0; done < n;) {
    const ssize_t r = ::pread(file_->fd, out + done, static_cast<std::size_t>(n - done),
                              static_cast<off_t>(offset + done));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0)
      throw IoError(name_, "cannot read " + std::to_string(n) + " bytes at file byte " + std::to_string(offset) +
                               (r < 0 ? std::string(": ") + std::strerror(errno) : " (the file shrank)"));
    done += static_cast<std::uint64_t>(r);
  }
}

}  // namespace pvb::slam
