#pragma once
// The list of what pvbench wrote into an output folder (its marker file,
// .pvbench), kept as the process writes: --overwrite removes what the list
// names and nothing else (output_folder.hpp).
#include <filesystem>
#include <string>
#include <vector>

namespace pvb::detail {

/// What --overwrite removes from a folder: the files and links its lists
/// name (with the temporary files of their killed writes and the lists
/// themselves), then the folders left empty, deepest first.
struct Removal {
  std::vector<std::filesystem::path> files;
  std::vector<std::filesystem::path> folders;
};

/// The removal --overwrite makes in `dir`, a folder holding the marker.
/// A folder below that holds a marker of its own (a sweep's seed, a
/// campaign's session) adds its list for what lies below it.  Throws
/// IoError naming the first entry no list names; `keep` entries (this
/// process's own standard output and error) are left alone and count as
/// known.
Removal plan_removal(const std::string& dir, bool (*keep)(const std::filesystem::path&));

/// Starts the list of `dir` (created, this process holding its lock): the
/// marker file written anew, naming `command`; from now on note_output()
/// adds each file this process writes below `dir`.
void start_manifest(const std::string& dir, const std::string& command);

}  // namespace pvb::detail
