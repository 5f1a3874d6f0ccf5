#pragma once
// Outputs that never land on inputs.
//
// Every command lists what it reads and what it writes before it does any
// work, and check_io_apart() refuses, with one line naming both:
//  - an output file that is one of the input files (the same file after
//    following links, or another spelling of its path);
//  - an input inside an output folder that exists (with --overwrite the
//    folder would be emptied before the input is read);
//  - two outputs that are the same file, also a file given for one output
//    that the command writes into one of its output folders
//    (`--save-map OUT/stats.json`);
//  - an output inside a folder the command reads as a recording (a TUM
//    sequence), whatever file it names: a recording is the user's data and
//    nothing is ever written into it.
// Streams (a character device such as /dev/null, a FIFO) are written
// through, never replaced, so they are not compared.
#include <string>
#include <vector>

namespace pvb {

/// A path a command reads or writes, with what it is for messages: an
/// input's role with its article ({"the --scenario file", "scenes/a.yaml"},
/// {"a file of the --sequence folder", ...}), an output's option
/// ({"--save-map", "noon.pvbmap"}).
struct IoPath {
  std::string role;
  std::string path;
};

/// What one command reads and writes.  Empty paths are ignored.
class IoPlan {
 public:
  IoPlan& input(const std::string& role, const std::string& path);
  /// Every input of `roles` at once (e.g. each --est).
  IoPlan& inputs(const std::string& role, const std::vector<std::string>& paths);
  /// A folder read as a whole (a recording): no output may lie inside it.
  IoPlan& input_folder(const std::string& role, const std::string& path);
  IoPlan& output_file(const std::string& role, const std::string& path);
  /// An output folder and what the command writes into it: names relative
  /// to it ("stats.json"; "imu0/" for a folder and all it holds).
  IoPlan& output_folder(const std::string& role, const std::string& path,
                        const std::vector<std::string>& written = {});

  /// Throws IoError naming the output for the first clash (see above).
  void check() const;

  const std::vector<IoPath>& inputs() const { return inputs_; }

 private:
  std::vector<IoPath> inputs_;
  std::vector<IoPath> input_folders_;
  std::vector<IoPath> output_files_;
  std::vector<IoPath> output_folders_;
  std::vector<std::vector<std::string>> written_;  ///< per output folder
};

/// True when a and b are the same file: the same inode when both exist
/// (links and other spellings included), else the same canonical path.
bool same_file(const std::string& a, const std::string& b);

/// True when `rel`, a path relative to an output folder ("stats.json",
/// "imu0/data.csv"), is one of `written`, the names a command writes there:
/// a name, a "dir/" and everything below it, or a name with one `*` for
/// any text ("*.png", "PointCloud*.ply"; not across a "/").
bool is_written_name(const std::string& rel, const std::vector<std::string>& written);

/// True when `path` is `folder` or lies below it, after following links.
bool is_inside(const std::string& path, const std::string& folder);

}  // namespace pvb
