#include "pvb/common/output_folder.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include "pvb/common/error.hpp"
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

/// The entries to remove for `overwrite` (none for a new or empty folder);
/// throws for a folder that may not be written.  Nothing is changed.
std::vector<fs::path> entries_to_replace(const std::string& dir, bool overwrite) {
  if (dir.empty()) throw IoError("(empty path)", "expected an output folder");
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0) return {};
  if (!S_ISDIR(st.st_mode)) throw IoError(dir, "is not a folder; expected a new or empty output folder");
  bool has_marker = false;
  std::vector<fs::path> entries = entries_of(dir, &has_marker);
  if (!entries.empty()) {
    if (!overwrite)
      throw IoError(dir, "the output folder is not empty (" + listing(entries) +
                             "); give --overwrite to replace an earlier pvbench output, or another folder");
    if (!has_marker)
      throw IoError(dir, "the output folder holds files pvbench did not write (" + listing(entries) +
                             ", no " + kOutputFolderMarker + " marker); it is not emptied, even with --overwrite");
  }
  return entries;
}

}  // namespace

void check_output_folder(const std::string& dir, bool overwrite) { entries_to_replace(dir, overwrite); }

void prepare_output_folder(const std::string& dir, bool overwrite, const std::string& command) {
  const std::vector<fs::path> entries = entries_to_replace(dir, overwrite);
  create_folder(dir);
  for (const fs::path& p : entries) {
    std::error_code ec;
    fs::remove_all(p, ec);
    if (ec) throw IoError(p.string(), "cannot remove an earlier output: " + ec.message());
  }
  write_file(dir + "/" + kOutputFolderMarker, "written by pvbench " + command + " " + version() + "\n");
}

}  // namespace pvb
