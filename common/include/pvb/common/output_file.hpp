#pragma once
// Files written as a run goes, checked on every write.
//
// A trajectory, a log or a CSV grows line by line and is flushed as it
// grows, so a run that stops early keeps what it wrote.  A write that fails
// (disk full, a file size limit, an I/O error) throws pvb::IoError naming
// the file at once, instead of going unnoticed until the end, and the file
// is cut back to its last whole append so that what it holds stays valid.
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <utility>

namespace pvb {

struct OutputTarget;

/// An output file written with POSIX write(2): every append() reaches the
/// kernel before it returns (no user-space buffer to lose).
class OutputFile {
 public:
  OutputFile() = default;
  /// Creates or truncates `path`; throws IoError when it cannot.
  explicit OutputFile(const std::string& path);
  /// Opens an existing stream (a character device, a FIFO or a standard
  /// stream, see resolve_output_target) for writing, without truncating or
  /// creating anything; IoError names `path` when it cannot.
  static OutputFile open_stream(const std::string& path, const OutputTarget& target);
  /// Creates `path`, which must not exist yet (nothing of that name is
  /// opened); nullopt when it exists, IoError for any other failure.
  static std::optional<OutputFile> create_new(const std::string& path);
  ~OutputFile();
  OutputFile(OutputFile&& other) noexcept;
  OutputFile& operator=(OutputFile&& other) noexcept;
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  /// Writes `text` whole, or throws IoError (with the system's reason) after
  /// cutting the file back to its size before this call.
  void append(const char* data, std::size_t n);
  void append(const std::string& text) { append(text.data(), text.size()); }
  /// Overwrites `n` bytes already appended, from `offset` (pwrite(2): a
  /// regular file, not a stream), e.g. a length known only once what
  /// follows it is written.  Throws IoError when the write fails.
  void patch(long long offset, const char* data, std::size_t n);
  /// Closes the file (also done by the destructor); throws IoError when the
  /// system reports a failure.
  void close();

  bool is_open() const { return fd_ >= 0; }
  const std::string& path() const { return path_; }
  /// Bytes written by complete appends.
  long long size() const { return size_; }
  /// The descriptor (-1 when closed), e.g. for fchmod.
  int fd() const { return fd_; }

 private:
  OutputFile(std::string path, int fd) : path_(std::move(path)), fd_(fd) {}

  std::string path_;
  int fd_ = -1;
  long long size_ = 0;
};

/// What a path given for a whole-file output is, after following symbolic
/// links: a new or regular file is replaced atomically; a stream (a
/// character device such as /dev/null or /dev/full, a FIFO, or the
/// process's own /dev/stdout, /dev/stderr, /dev/fd/N) is written through.
struct OutputTarget {
  enum class Kind { kNewFile, kRegularFile, kStream };
  Kind kind = Kind::kNewFile;
  std::string path;  ///< the file to write: the link's final target for a symbolic link
  int fd = -1;       ///< for /dev/stdout, /dev/stderr, /dev/fd/N: that descriptor
};

/// Classifies `path` for a whole-file output.  Throws IoError naming `path`
/// for a folder, a socket, a block device or a loop of symbolic links.
OutputTarget resolve_output_target(const std::string& path);

/// Writes `path` whole.  A new or regular file (also through a symbolic
/// link, which stays a link) is written to a temporary file beside it,
/// which is then renamed over it: on any failure the temporary file is
/// removed, the old file is left as it was, and IoError names `path`, so no
/// half-written file ever carries the final name.  A character device, a
/// FIFO or a standard stream is written through (a write to /dev/full fails
/// as on a full disk); nothing else is ever replaced.  The temporary file is
/// named PATH.tmp.PID.N; those of earlier writes of `path` whose process is
/// gone (killed during the write) are removed first.
void write_file_via_temp(const std::string& path, const std::function<void(OutputFile&)>& write);

}  // namespace pvb
