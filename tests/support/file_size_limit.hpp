#pragma once
// A disk that fills up, for tests: RLIMIT_FSIZE caps the size of every file
// the process writes, and with SIGXFSZ ignored a write past it fails with
// EFBIG ("File too large") as a write to a full disk fails with ENOSPC.
#include <signal.h>
#include <sys/resource.h>

namespace pvb::test {

/// Caps file sizes at `max_bytes` for its lifetime (this process only).
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t max_bytes) {
    getrlimit(RLIMIT_FSIZE, &old_limit_);
    old_handler_ = signal(SIGXFSZ, SIG_IGN);
    rlimit limit = old_limit_;
    limit.rlim_cur = max_bytes;
    setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_limit_);
    signal(SIGXFSZ, old_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit old_limit_{};
  sighandler_t old_handler_ = SIG_DFL;
};

}  // namespace pvb::test
