#include "pvb/common/output_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

#include "pvb/common/error.hpp"
#include "output_manifest.hpp"
#include "pvb/common/text.hpp"

namespace pvb {
namespace {

namespace fs = std::filesystem;

/// True when `p` is the file open as this process's standard output or error.
bool is_own_stream(const fs::path& p) {
  struct stat file {};
  if (::lstat(p.c_str(), &file) != 0 || !S_ISREG(file.st_mode)) return false;
  for (const int fd : {STDOUT_FILENO, STDERR_FILENO}) {
    struct stat open_file {};
    if (::fstat(fd, &open_file) == 0 && open_file.st_dev == file.st_dev && open_file.st_ino == file.st_ino)
      return true;
  }
  return false;
}

/// The entries of `dir` that count (all but the marker and own streams).
std::vector<fs::path> entries_of(const std::string& dir, bool* has_marker) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    if (e.path().filename() == kOutputFolderMarker) {
      *has_marker = true;
      continue;
    }
    if (!is_own_stream(e.path())) out.push_back(e.path());
  }
  if (ec) throw IoError(dir, "cannot list the folder: " + ec.message());
  return out;
}

void create_folder(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError(dir, "cannot create folder: " + ec.message());
  if (::access(dir.c_str(), W_OK) != 0)
    throw IoError(dir, std::string("the folder is not writable: ") + std::strerror(errno));
}

std::string listing(const std::vector<fs::path>& entries) {
  std::string names;
  for (std::size_t i = 0; i < entries.size() && i < 3; ++i)
    names += (i ? ", " : "") + entries[i].filename().string();
  if (entries.size() > 3) names += ", ...";
  return std::to_string(entries.size()) + (entries.size() == 1 ? " entry: " : " entries: ") + names;
}

[[noreturn]] void throw_busy(const std::string& dir) {
  throw IoError(dir,
                "another pvbench process is writing this output folder now; wait for it to end, or give "
                "another folder");
}

/// Opens `dir` and takes its lock without blocking: the descriptor, or -1
/// when another process holds it.  Throws IoError when it cannot open it.
int try_lock(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) throw IoError(dir, std::string("cannot open the output folder: ") + std::strerror(errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return fd;
  const int err = errno;
  ::close(fd);
  if (err == EWOULDBLOCK) return -1;
  throw IoError(dir, std::string("cannot lock the output folder: ") + std::strerror(err));
}

/// Locks `dir` for the rest of this process's life (the lock goes with the
/// process, also when it is killed); a folder this process locked before
/// stays locked.  Throws IoError when another process holds it.
/// The folders this process locked: (device, inode) -> the locked descriptor.
struct HeldLocks {
  std::mutex mutex;
  std::map<std::pair<dev_t, ino_t>, int> fds;
};
HeldLocks& held_locks() {
  static HeldLocks held;
  return held;
}

std::pair<dev_t, ino_t> folder_key(const std::string& dir) {
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0)
    throw IoError(dir, std::string("cannot examine: ") + std::strerror(errno));
  return {st.st_dev, st.st_ino};
}

void lock_for_process(const std::string& dir) {
  HeldLocks& held = held_locks();
  const auto key = folder_key(dir);
  const std::lock_guard<std::mutex> lock(held.mutex);
  if (held.fds.count(key)) return;
  const int fd = try_lock(dir);
  if (fd < 0) throw_busy(dir);
  held.fds[key] = fd;
}

/// Throws when another process holds the lock of `dir` (an existing folder).
void check_not_locked(const std::string& dir) {
  HeldLocks& held = held_locks();
  const auto key = folder_key(dir);
  const std::lock_guard<std::mutex> lock(held.mutex);
  if (held.fds.count(key)) return;  // this process's own
  const int fd = try_lock(dir);
  if (fd < 0) throw_busy(dir);
  ::close(fd);  // closing the only descriptor that holds it releases it
}

/// What `overwrite` removes (nothing for a new or empty folder); throws
/// for a folder that may not be written.  Nothing is changed.
detail::Removal removal_for(const std::string& dir, bool overwrite, bool check_lock) {
  if (dir.empty()) throw IoError("(empty path)", "expected an output folder");
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0) return {};
  if (!S_ISDIR(st.st_mode)) throw IoError(dir, "is not a folder; expected a new or empty output folder");
  if (check_lock) check_not_locked(dir);
  bool has_marker = false;
  const std::vector<fs::path> entries = entries_of(dir, &has_marker);
  if (entries.empty()) return {};
  if (!overwrite)
    throw IoError(dir, "the output folder is not empty (" + listing(entries) +
                           "); give --overwrite to replace an earlier pvbench output, or another folder");
  if (!has_marker)
    throw IoError(dir, "the output folder holds files pvbench did not write (" + listing(entries) + ", no " +
                           kOutputFolderMarker + " marker); it is not emptied, even with --overwrite");
  return detail::plan_removal(dir, [](const fs::path& p) { return is_own_stream(p); });
}

}  // namespace

void check_output_folder(const std::string& dir, bool overwrite) { removal_for(dir, overwrite, true); }

void prepare_output_folder(const std::string& dir, bool overwrite, const std::string& command) {
  removal_for(dir, overwrite, false);  // refused before anything is created
  create_folder(dir);
  lock_for_process(dir);
  // Under the lock: what is there now (another process may have written
  // into the folder since the first look).
  const detail::Removal removal = removal_for(dir, overwrite, false);
  for (const fs::path& p : removal.files) {
    std::error_code ec;
    fs::remove(p, ec);
    if (ec) throw IoError(p.string(), "cannot remove an earlier output: " + ec.message());
  }
  for (const fs::path& p : removal.folders) {
    std::error_code ec;
    fs::remove(p, ec);  // only when empty: a folder holding a kept stream stays
  }
  detail::start_manifest(dir, command);
}

}  // namespace pvb
