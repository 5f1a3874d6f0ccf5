#pragma once
// The exception a worker thread met, kept for the thread that owns it: an
// exception that leaves a thread's function ends the process with abort()
// (exit 134, no message, outputs half written), so a worker runs its loop
// through WorkerError::run and its owner rethrows at its next call.
#include <atomic>
#include <exception>
#include <mutex>
#include <utility>

namespace pvb {

class WorkerError {
 public:
  /// Runs `fn`, keeping the first exception it throws; false when it threw.
  template <typename Fn>
  bool run(Fn&& fn) noexcept {
    try {
      std::forward<Fn>(fn)();
      return true;
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
      failed_ = true;
      return false;
    }
  }

  /// True once the worker failed.
  bool failed() const { return failed_.load(); }

  /// Rethrows the kept exception, once (a second call does nothing).
  void rethrow() {
    if (!failed_.load()) return;
    std::exception_ptr e;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      std::swap(e, error_);
    }
    if (e) std::rethrow_exception(e);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr error_;
  std::atomic<bool> failed_{false};
};

}  // namespace pvb
