#include "pvb/openni/record_target.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "pvb/common/error.hpp"
#include "pvb/common/io_paths.hpp"
#include "pvb/common/output_folder.hpp"

namespace pvb::openni {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void throw_exists(const std::string& record_path) {
  throw IoError(record_path,
                "already exists; a recording never replaces a file (remove it or record to a new name)");
}

}  // namespace

void check_record_not_on(const std::string& record_path, const std::vector<RunFile>& files) {
  for (const RunFile& f : files)
    if (!f.path.empty() && pvb::same_file(record_path, f.path))
      throw IoError(record_path, "is " + f.role + " (" + f.path + "); record to a new file");
}

void check_new_recording_path(const std::string& record_path) {
  const fs::path p(record_path);
  std::error_code ec;
  if (record_path.empty() || fs::is_directory(p, ec) || !p.has_filename())
    throw IoError(record_path, "is a folder; --record takes the path of a new .oni file");
  const fs::path folder = p.has_parent_path() ? p.parent_path() : fs::path(".");
  const fs::file_status st = fs::status(folder, ec);
  if (!fs::exists(st)) {
    const bool missing =
        !ec || ec == std::errc::no_such_file_or_directory || ec == std::errc::not_a_directory;
    throw IoError(record_path, "cannot record: the folder " + folder.string() +
                                   (missing ? " does not exist" : ": " + ec.message()));
  }
  if (!fs::is_directory(st))
    throw IoError(record_path, "cannot record: " + folder.string() + " is not a folder");
  if (fs::exists(fs::symlink_status(p, ec))) throw_exists(record_path);
}

void create_new_recording_file(const std::string& record_path) {
  check_new_recording_path(record_path);
  note_output(record_path);  // a recording into an output folder is listed in it
  const int fd = ::open(record_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    const int err = errno;
    if (err == EEXIST) throw_exists(record_path);
    throw IoError(record_path, std::string("cannot create the recording: ") + std::strerror(err));
  }
  ::close(fd);
}

}  // namespace pvb::openni
