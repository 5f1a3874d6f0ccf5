#include "pvb/common/output_file.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <stdexcept>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/output_folder.hpp"

namespace pvb {

OutputFile::OutputFile(const std::string& path) : path_(path) {
  note_output(path);  // listed in its output folder's marker before it exists
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

void OutputFile::patch(long long offset, const char* data, std::size_t n_bytes) {
  if (fd_ < 0) throw IoError(path_.empty() ? "(no file)" : path_, "write to a closed file");
  if (offset < 0 || offset + static_cast<long long>(n_bytes) > size_)
    throw std::logic_error("OutputFile::patch: beyond what was appended");
  std::size_t done = 0;
  while (done < n_bytes) {
    const ssize_t n = ::pwrite(fd_, data + done, n_bytes - done, static_cast<off_t>(offset) + static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw IoError(path_, std::string("write failed: ") + std::strerror(n < 0 ? errno : EIO));
    done += static_cast<std::size_t>(n);
  }
}

void OutputFile::close() {
  if (fd_ < 0) return;
  const int rc = ::close(std::exchange(fd_, -1));
  if (rc != 0) throw IoError(path_, std::string("write failed on close: ") + std::strerror(errno));
}

namespace {

/// The descriptor named by /dev/stdout, /dev/stderr, /dev/fd/N or
/// /proc/self/fd/N, or -1.  Such a path is the process's own stream: it is
/// written through that descriptor, never opened again by name (a shell's
/// `> log` would otherwise be truncated or replaced).
int standard_stream_fd(const std::string& path) {
  if (path == "/dev/stdout") return STDOUT_FILENO;
  if (path == "/dev/stderr") return STDERR_FILENO;
  for (const char* prefix : {"/dev/fd/", "/proc/self/fd/"}) {
    const std::string p(prefix);
    if (path.size() <= p.size() || path.compare(0, p.size(), p) != 0) continue;
    const std::string digits = path.substr(p.size());
    if (digits.size() > 6 || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
    return std::stoi(digits);
  }
  return -1;
}

std::string parent_dir(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

/// Follows a chain of symbolic links to the path it ends at (which may not
/// exist yet).  Throws IoError naming `path` for a loop.
std::string follow_links(const std::string& path) {
  std::string at = path;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st {};
    if (::lstat(at.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return at;
    std::string target(static_cast<std::size_t>(st.st_size > 0 ? st.st_size : 4096) + 1, '\0');
    const ssize_t n = ::readlink(at.c_str(), target.data(), target.size());
    if (n < 0) throw IoError(path, std::string("cannot read the symbolic link: ") + std::strerror(errno));
    target.resize(static_cast<std::size_t>(n));
    at = !target.empty() && target[0] == '/' ? target : parent_dir(at) + "/" + target;
  }
  throw IoError(path, "too many levels of symbolic links");
}

std::string kind_name(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISBLK(mode)) return "a block device";
  return "not a regular file";
}

}  // namespace

OutputTarget resolve_output_target(const std::string& path) {
  OutputTarget t;
  t.path = path;
  if (path.empty()) throw IoError("(empty path)", "expected a file name");
  if ((t.fd = standard_stream_fd(path)) >= 0) {
    t.kind = OutputTarget::Kind::kStream;
    return t;
  }
  t.path = follow_links(path);
  if ((t.fd = standard_stream_fd(t.path)) >= 0) {
    t.kind = OutputTarget::Kind::kStream;
    return t;
  }
  struct stat st {};
  if (::lstat(t.path.c_str(), &st) != 0) {
    if (errno != ENOENT) throw IoError(path, std::string("cannot examine: ") + std::strerror(errno));
    t.kind = OutputTarget::Kind::kNewFile;
    return t;
  }
  if (S_ISREG(st.st_mode)) {
    t.kind = OutputTarget::Kind::kRegularFile;
  } else if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode)) {
    t.kind = OutputTarget::Kind::kStream;
  } else {
    throw IoError(path, "is " + kind_name(st.st_mode) +
                            "; expected a regular file, a new file, a character device or a FIFO");
  }
  return t;
}

std::optional<OutputFile> OutputFile::create_new(const std::string& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0 && errno == EEXIST) return std::nullopt;
  if (fd < 0) throw IoError(path, std::string("cannot create: ") + std::strerror(errno));
  return OutputFile(path, fd);
}

OutputFile OutputFile::open_stream(const std::string& path, const OutputTarget& target) {
  const int fd = target.fd >= 0 ? ::fcntl(target.fd, F_DUPFD_CLOEXEC, 0)
                                : ::open(target.path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) throw IoError(path, std::string("cannot open for writing: ") + std::strerror(errno));
  return OutputFile(path, fd);
}

namespace {

/// A temporary file beside `final_path`, created exclusively (an existing
/// file of that name, whatever it is, is never opened), with the mode of
/// the file it replaces.
OutputFile create_temporary(const std::string& final_path, std::string* tmp_path) {
  static std::atomic<unsigned> counter{0};
  struct stat old {};
  const bool replaces = ::stat(final_path.c_str(), &old) == 0;
  for (int attempt = 0; attempt < 100; ++attempt) {
    *tmp_path = final_path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
    std::optional<OutputFile> f = OutputFile::create_new(*tmp_path);
    if (!f) continue;
    if (replaces) (void)::fchmod(f->fd(), old.st_mode & 07777);
    return std::move(*f);
  }
  tmp_path->clear();
  throw IoError(final_path, "cannot create a temporary file beside it: too many exist");
}

/// True for "NAME.tmp.PID.N" (digits only after the name), giving PID.
bool temporary_of(const std::string& entry, const std::string& name, long* pid) {
  const std::string head = name + ".tmp.";
  if (entry.size() <= head.size() || entry.compare(0, head.size(), head) != 0) return false;
  const std::string rest = entry.substr(head.size());
  const std::size_t dot = rest.find('.');
  if (dot == 0 || dot == std::string::npos || dot + 1 == rest.size() || dot > 9) return false;
  for (std::size_t i = 0; i < rest.size(); ++i)
    if (i != dot && !std::isdigit(static_cast<unsigned char>(rest[i]))) return false;
  *pid = std::stol(rest.substr(0, dot));
  return true;
}

/// Removes the temporary files of earlier writes of `final_path` whose
/// process no longer exists (one killed during a write leaves its
/// temporary file behind); a live process's temporary file is kept.
void remove_stale_temporaries(const std::string& final_path) {
  const std::size_t slash = final_path.rfind('/');
  const std::string dir = slash == std::string::npos ? "." : final_path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? final_path : final_path.substr(slash + 1);
  DIR* d = ::opendir(dir.c_str());
  if (!d) return;
  std::vector<std::string> stale;
  while (const dirent* e = ::readdir(d)) {
    long pid = 0;
    if (temporary_of(e->d_name, name, &pid) && pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 &&
        errno == ESRCH)
      stale.push_back(e->d_name);
  }
  ::closedir(d);
  for (const std::string& f : stale) ::unlink((slash == std::string::npos ? f : dir + f).c_str());
}

void write_through(const std::string& path, const OutputTarget& target,
                   const std::function<void(OutputFile&)>& write) {
  try {
    OutputFile out = OutputFile::open_stream(path, target);
    write(out);
    out.close();
  } catch (const IoError& e) {
    throw IoError(path, e.message());
  }
}

}  // namespace

void write_file_via_temp(const std::string& path, const std::function<void(OutputFile&)>& write) {
  const OutputTarget target = resolve_output_target(path);
  if (target.kind == OutputTarget::Kind::kStream) return write_through(path, target, write);
  note_output(path);  // the name in its folder (a link stays a link), before its temporary file exists
  remove_stale_temporaries(target.path);
  std::string tmp;
  try {
    OutputFile out = create_temporary(target.path, &tmp);
    write(out);
    out.close();
  } catch (const IoError& e) {
    if (!tmp.empty()) std::remove(tmp.c_str());
    // The final name is what the user asked for; the reason is the system's.
    const std::string why = e.message();
    throw IoError(path, why);
  } catch (...) {
    if (!tmp.empty()) std::remove(tmp.c_str());
    throw;
  }
  if (std::rename(tmp.c_str(), target.path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw IoError(path, std::string("cannot rename the temporary file over it: ") + std::strerror(err));
  }
}

}  // namespace pvb
