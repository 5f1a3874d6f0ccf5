#include "output_manifest.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"

namespace pvb {
namespace {

namespace fs = std::filesystem;

/// A line of the list naming a file, relative to the folder.
constexpr const char* kFileLine = "file ";
/// The line a failed command ends its list with.
constexpr const char* kFailedLine = "failed: ";

/// An output folder this process prepared, and what it wrote there.
struct Manifest {
  fs::path dir;  ///< absolute, lexically normal
  OutputFile file;
  std::set<std::string> names;
};

/// A path reserved for one output, and whether it was written yet.
struct Reserved {
  std::string role;
  bool written = false;
};

struct Registry {
  std::mutex mutex;
  std::vector<std::unique_ptr<Manifest>> folders;
  std::map<fs::path, Reserved> reserved;
};

Registry& registry() {
  static Registry r;
  return r;
}

/// The path made absolute and lexically normal, without following links
/// (the spelling a writer of the folder uses).
fs::path absolute_normal(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (ec) p = fs::path(path);
  p = p.lexically_normal();
  if (!p.has_filename() && p.has_parent_path() && p != p.root_path()) p = p.parent_path();
  return p;
}

/// The path of `p` below `dir` ("rgb/1.png"), or "" when it is not below it.
std::string below(const fs::path& p, const fs::path& dir) {
  auto pi = p.begin();
  for (auto di = dir.begin(); di != dir.end(); ++di, ++pi)
    if (pi == p.end() || *pi != *di) return {};
  if (pi == p.end()) return {};
  fs::path rel;
  for (; pi != p.end(); ++pi) rel /= *pi;
  return rel.string();
}

/// "NAME" of a temporary file "NAME.tmp.PID.N" (write_file_via_temp), else "".
std::string temporary_base(const std::string& name) {
  const std::size_t last = name.rfind('.');
  if (last == std::string::npos || last == 0) return {};
  const std::size_t pid = name.rfind('.', last - 1);
  if (pid == std::string::npos || pid < 4 || name.compare(pid - 4, 4, ".tmp") != 0) return {};
  const auto digits = [&](std::size_t from, std::size_t to) {
    return to > from && std::all_of(name.begin() + static_cast<long>(from), name.begin() + static_cast<long>(to),
                                    [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; });
  };
  if (!digits(last + 1, name.size()) || !digits(pid + 1, last)) return {};
  return name.substr(0, pid - 4);
}

/// The names the list file of a folder gives.
std::set<std::string> read_list(const fs::path& marker) {
  std::set<std::string> names;
  std::istringstream in(read_file(marker.string()));
  const std::string prefix = kFileLine;
  for (std::string line; std::getline(in, line);)
    if (line.compare(0, prefix.size(), prefix) == 0) names.insert(line.substr(prefix.size()));
  return names;
}

using Lists = std::map<fs::path, std::set<std::string>>;

/// True when a list of `p`'s folder or of a folder above it, up to `root`,
/// names it or the file its temporary name stands for.
bool listed(const fs::path& p, const fs::path& root, const Lists& lists) {
  const std::string base = temporary_base(p.filename().string());
  for (fs::path at = p.parent_path();; at = at.parent_path()) {
    if (const auto it = lists.find(at); it != lists.end()) {
      const fs::path rel = p.lexically_relative(at);
      if (it->second.count(rel.string())) return true;
      if (!base.empty() && it->second.count((rel.parent_path() / base).string())) return true;
    }
    if (at == root || !at.has_relative_path()) return false;
  }
}

[[noreturn]] void throw_unknown(const std::string& dir, const fs::path& rel) {
  throw IoError(dir, "the output folder holds " + printable(rel.string()) + ", which pvbench did not write (its " +
                         kOutputFolderMarker +
                         " list does not name it); --overwrite removes only what pvbench wrote: move it away, "
                         "or give another folder");
}

}  // namespace

namespace detail {

Removal plan_removal(const std::string& dir, bool (*keep)(const fs::path&)) {
  const fs::path root = absolute_normal(dir);
  Lists lists;
  lists[root] = read_list(root / kOutputFolderMarker);
  Removal r;
  std::error_code ec;
  fs::recursive_directory_iterator it(root, fs::directory_options::none, ec);
  for (; !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    const fs::path p = it->path();
    std::error_code stat_ec;
    const fs::file_status st = it->symlink_status(stat_ec);
    if (fs::is_directory(st)) {
      if (fs::is_regular_file(p / kOutputFolderMarker, stat_ec)) lists[p] = read_list(p / kOutputFolderMarker);
      r.folders.push_back(p);
      continue;
    }
    if (keep(p)) continue;
    if (p.filename() != kOutputFolderMarker && !listed(p, root, lists)) throw_unknown(dir, p.lexically_relative(root));
    r.files.push_back(p);
  }
  if (ec) throw IoError(dir, "cannot list the folder: " + ec.message());
  std::reverse(r.folders.begin(), r.folders.end());  // listed parents first: remove children first
  return r;
}

void start_manifest(const std::string& dir, const std::string& command) {
  auto m = std::make_unique<Manifest>();
  m->dir = absolute_normal(dir);
  // Opened outside the registry's lock: OutputFile notes its own path.
  m->file = OutputFile(dir + "/" + kOutputFolderMarker);
  m->file.append(std::string("written by pvbench ") + command + " " + version() +
                 "; the files it wrote (--overwrite removes these, and nothing else):\n");
  Registry& reg = registry();
  const std::lock_guard<std::mutex> lock(reg.mutex);
  reg.folders.erase(std::remove_if(reg.folders.begin(), reg.folders.end(),
                                   [&](const std::unique_ptr<Manifest>& f) { return f->dir == m->dir; }),
                    reg.folders.end());
  reg.folders.push_back(std::move(m));
}

}  // namespace detail

void reserve_output(const std::string& path, const std::string& role) {
  if (path.empty()) return;
  Registry& reg = registry();
  const std::lock_guard<std::mutex> lock(reg.mutex);
  reg.reserved.emplace(absolute_normal(path), Reserved{role, false});
}

void note_output(const std::string& path) {
  Registry& reg = registry();
  const std::lock_guard<std::mutex> lock(reg.mutex);
  if (reg.folders.empty() && reg.reserved.empty()) return;
  const fs::path p = absolute_normal(path);
  if (const auto r = reg.reserved.find(p); r != reg.reserved.end()) {
    if (r->second.written)
      throw IoError(path, "is the " + r->second.role +
                              " file, and this command writes it as another of its outputs too; give " +
                              r->second.role + " another path");
    r->second.written = true;
  }
  Manifest* best = nullptr;
  std::string rel;
  for (const std::unique_ptr<Manifest>& m : reg.folders) {
    std::string r = below(p, m->dir);
    if (!r.empty() && (!best || m->dir.string().size() > best->dir.string().size())) {
      best = m.get();
      rel = std::move(r);
    }
  }
  // A name the list cannot hold on one line stays unlisted: --overwrite
  // then refuses the folder rather than guess.
  if (!best || rel.find('\n') != std::string::npos || best->names.count(rel)) return;
  best->file.append(kFileLine + rel + "\n");
  best->names.insert(rel);
}

void mark_output_folders_failed(const std::string& why) {
  Registry& reg = registry();
  const std::lock_guard<std::mutex> lock(reg.mutex);
  for (const std::unique_ptr<Manifest>& m : reg.folders) {
    try {
      m->file.append(kFailedLine + printable(why) + "\n");
    } catch (const IoError&) {
      // already failing: the error line on the terminal says it all
    }
  }
}

}  // namespace pvb
