#include "pvb/common/output_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

#include "pvb/common/error.hpp"

namespace pvb {

OutputFile::OutputFile(const std::string& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw IoError(path, std::string("cannot open for writing: ") + std::strerror(errno));
}

OutputFile::~OutputFile() {
  if (fd_ >= 0) ::close(fd_);
}

OutputFile::OutputFile(OutputFile&& other) noexcept
    : path_(std::move(other.path_)), fd_(std::exchange(other.fd_, -1)), size_(other.size_) {}

OutputFile& OutputFile::operator=(OutputFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
    size_ = other.size_;
  }
  return *this;
}

void OutputFile::append(const char* data, std::size_t n_bytes) {
  if (fd_ < 0) throw IoError(path_.empty() ? "(no file)" : path_, "write to a closed file");
  std::size_t done = 0;
  while (done < n_bytes) {
    const ssize_t n = ::write(fd_, data + done, n_bytes - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : ENOSPC;
      // Cut back to the last whole append: a reader never sees half a line.
      if (::ftruncate(fd_, static_cast<off_t>(size_)) == 0) ::lseek(fd_, static_cast<off_t>(size_), SEEK_SET);
      throw IoError(path_, std::string("write failed: ") + std::strerror(err));
    }
    done += static_cast<std::size_t>(n);
  }
  size_ += static_cast<long long>(n_bytes);
}

void OutputFile::close() {
  if (fd_ < 0) return;
  const int rc = ::close(std::exchange(fd_, -1));
  if (rc != 0) throw IoError(path_, std::string("write failed on close: ") + std::strerror(errno));
}

void write_file_via_temp(const std::string& path, const std::function<void(OutputFile&)>& write) {
  const std::string tmp = path + ".tmp";
  try {
    OutputFile out(tmp);
    write(out);
    out.close();
  } catch (const IoError& e) {
    std::remove(tmp.c_str());
    // The final name is what the user asked for; the reason is the system's.
    const std::string why = e.message();
    throw IoError(path, why);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw IoError(path, std::string("cannot rename the temporary file over it: ") + std::strerror(err));
  }
}

}  // namespace pvb
