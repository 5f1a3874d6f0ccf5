#include "pvb/common/io_paths.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"

namespace pvb {
namespace {

namespace fs = std::filesystem;

/// The path made absolute with every link and ".." resolved as far as it exists.
fs::path canonical_of(const std::string& p) {
  std::error_code ec;
  fs::path abs = fs::absolute(p, ec);
  if (ec) return fs::path(p).lexically_normal();
  fs::path c = fs::weakly_canonical(abs, ec);
  return ec ? abs.lexically_normal() : c;
}

/// A character device or a FIFO: written through, never replaced.
bool is_stream(const std::string& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode));
}

/// "the --scenario file (scenes/a.yaml)", the path only when spelled otherwise.
std::string spelled(const IoPath& in, const std::string& as) {
  return in.role + (in.path == as ? std::string() : " (" + in.path + ")");
}

void check_output_file(const IoPath& out, const std::vector<IoPath>& inputs) {
  if (is_stream(out.path)) return;
  for (const IoPath& in : inputs)
    if (same_file(out.path, in.path))
      throw IoError(out.path, "is " + spelled(in, out.path) + ", an input of this command; give " + out.role +
                                  " another path");
}

/// An output file's place, before any work: not a folder (nor a socket, a
/// block device, a loop of links), in a folder that exists and can be
/// written, unless that folder is one of the command's output folders
/// (created by the command).
void check_file_place(const IoPath& out, const std::vector<IoPath>& folders) {
  bool in_output_folder = false;
  for (const IoPath& f : folders) in_output_folder = in_output_folder || is_inside(out.path, f.path);
  const fs::path parent =
      fs::path(out.path).has_parent_path() ? fs::path(out.path).parent_path() : fs::path(".");
  struct stat st {};
  if (!in_output_folder && ::stat(parent.c_str(), &st) != 0)
    throw IoError(out.path,
                  "cannot write the " + out.role + " output: the folder " + parent.string() +
                      (errno == ENOENT ? " does not exist" : ": " + std::string(std::strerror(errno))));
  if (!in_output_folder && !S_ISDIR(st.st_mode))
    throw IoError(out.path,
                  "cannot write the " + out.role + " output: " + parent.string() + " is not a folder");
  if (!in_output_folder && ::access(parent.c_str(), W_OK) != 0)
    throw IoError(out.path, "cannot write the " + out.role + " output: the folder " + parent.string() +
                                " is not writable: " + std::strerror(errno));
  try {
    resolve_output_target(out.path);  // a folder, a socket, a block device, a loop of links
  } catch (const IoError& e) {
    throw IoError(out.path, "the " + out.role + " output " + e.message());
  }
}

/// An output in a folder read as a recording: refused, whatever it names.
void check_not_in_recording(const IoPath& out, bool folder, const std::vector<IoPath>& recordings) {
  for (const IoPath& in : recordings) {
    if (!is_inside(out.path, in.path)) continue;
    const std::string what = folder ? "the " + out.role + " folder lies in " : std::string("lies in ");
    throw IoError(out.path, what + spelled(in, out.path) +
                                ", a recording this command reads, and nothing is written into a recording; give " +
                                out.role + (folder ? " another folder" : " another path"));
  }
}

/// `out`'s name in `folder` when it is one of the files the command writes
/// there (is_written_name), else "".
std::string written_name(const std::string& out, const std::string& folder, const std::vector<std::string>& written) {
  if (!is_inside(out, folder)) return {};
  const std::string rel = canonical_of(out).lexically_relative(canonical_of(folder)).generic_string();
  return rel != "." && is_written_name(rel, written) ? rel : std::string();
}

void check_output_folder(const IoPath& out, const std::vector<IoPath>& inputs) {
  struct stat st {};
  if (::stat(out.path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) return;  // new: holds nothing yet
  for (const IoPath& in : inputs)
    if (is_inside(in.path, out.path))
      throw IoError(out.path, "the " + out.role + " folder holds " + spelled(in, "") +
                                  ", an input of this command, which --overwrite would remove; give " +
                                  out.role + " another folder");
}

}  // namespace

IoPlan& IoPlan::input(const std::string& role, const std::string& path) {
  if (!path.empty()) inputs_.push_back({role, path});
  return *this;
}

IoPlan& IoPlan::inputs(const std::string& role, const std::vector<std::string>& paths) {
  for (const std::string& p : paths) input(role, p);
  return *this;
}

IoPlan& IoPlan::output_file(const std::string& role, const std::string& path) {
  if (!path.empty()) output_files_.push_back({role, path});
  return *this;
}

IoPlan& IoPlan::input_folder(const std::string& role, const std::string& path) {
  if (!path.empty()) input_folders_.push_back({role, path});
  return *this;
}

IoPlan& IoPlan::output_folder(const std::string& role, const std::string& path,
                              const std::vector<std::string>& written) {
  if (path.empty()) return *this;
  output_folders_.push_back({role, path});
  written_.push_back(written);
  return *this;
}

void IoPlan::check() const {
  std::vector<IoPath> read = inputs_;
  read.insert(read.end(), input_folders_.begin(), input_folders_.end());
  for (const IoPath& out : output_folders_) {
    check_not_in_recording(out, true, input_folders_);
    check_output_folder(out, read);
  }
  for (std::size_t i = 0; i < output_files_.size(); ++i) {
    const IoPath& out = output_files_[i];
    check_file_place(out, output_folders_);
    check_output_file(out, inputs_);
    if (is_stream(out.path)) continue;
    check_not_in_recording(out, false, input_folders_);
    for (std::size_t k = 0; k < output_folders_.size(); ++k)
      if (const std::string name = written_name(out.path, output_folders_[k].path, written_[k]); !name.empty())
        throw IoError(out.path, "is " + name + " of the " + output_folders_[k].role +
                                    " folder, which this command writes; give " + out.role + " another path");
    for (std::size_t j = 0; j < i; ++j)
      if (same_file(out.path, output_files_[j].path))
        throw IoError(out.path, output_files_[j].role + " and " + out.role +
                                    " name the same file; give each output its own path");
  }
}

bool is_written_name(const std::string& rel, const std::vector<std::string>& written) {
  for (const std::string& w : written) {
    if (w.empty()) continue;
    if (w.back() == '/' && (rel.compare(0, w.size(), w) == 0 || rel + "/" == w)) return true;
    const std::size_t star = w.find('*');
    if (star == std::string::npos) {
      if (rel == w) return true;
      continue;
    }
    const std::string head = w.substr(0, star), tail = w.substr(star + 1);
    if (rel.find('/') == std::string::npos && rel.size() >= head.size() + tail.size() &&
        rel.compare(0, head.size(), head) == 0 && rel.compare(rel.size() - tail.size(), tail.size(), tail) == 0)
      return true;
  }
  return false;
}

bool same_file(const std::string& a, const std::string& b) {
  struct stat sa {
  }, sb{};
  const bool a_exists = ::stat(a.c_str(), &sa) == 0;
  const bool b_exists = ::stat(b.c_str(), &sb) == 0;
  if (a_exists && b_exists) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  if (a_exists != b_exists) return false;
  return canonical_of(a) == canonical_of(b);
}

bool is_inside(const std::string& path, const std::string& folder) {
  const auto trimmed = [](fs::path c) { return c.has_filename() ? c : c.parent_path(); };
  const fs::path p = trimmed(canonical_of(path)), f = trimmed(canonical_of(folder));
  auto pi = p.begin();
  for (auto fi = f.begin(); fi != f.end(); ++fi, ++pi)
    if (pi == p.end() || *pi != *fi) return false;
  return true;
}

}  // namespace pvb
