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
#include <string>

namespace pvb {

/// An output file written with POSIX write(2): every append() reaches the
/// kernel before it returns (no user-space buffer to lose).
class OutputFile {
 public:
  OutputFile() = default;
  /// Creates or truncates `path`; throws IoError when it cannot.
  explicit OutputFile(const std::string& path);
  ~OutputFile();
  OutputFile(OutputFile&& other) noexcept;
  OutputFile& operator=(OutputFile&& other) noexcept;
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  /// Writes `text` whole, or throws IoError (with the system's reason) after
  /// cutting the file back to its size before this call.
  void append(const char* data, std::size_t n);
  void append(const std::string& text) { append(text.data(), text.size()); }
  /// Closes the file (also done by the destructor); throws IoError when the
  /// system reports a failure.
  void close();

  bool is_open() const { return fd_ >= 0; }
  const std::string& path() const { return path_; }
  /// Bytes written by complete appends.
  long long size() const { return size_; }

 private:
  std::string path_;
  int fd_ = -1;
  long long size_ = 0;
};

/// Writes `path` through `path`.tmp: `write` fills the temporary file, which
/// is then renamed over `path`.  On any failure the temporary file is
/// removed and IoError names `path`, so no half-written file ever carries
/// the final name.
void write_file_via_temp(const std::string& path, const std::function<void(OutputFile&)>& write);

}  // namespace pvb
