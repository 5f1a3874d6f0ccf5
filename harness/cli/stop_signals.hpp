#pragma once
// Ctrl-C (SIGINT) and SIGTERM as a request to stop, for `pvbench run`,
// `slam` and `camera`: the command polls the flag, stops taking frames and
// still writes everything it has (trajectories, maps, stats, report).
#include <atomic>
#include <csignal>

namespace pvb::cli {

/// Installs the handlers for its lifetime and restores the previous ones
/// afterwards.  The first signal sets flag(); the handler then goes back to
/// the default action, so a second Ctrl-C ends the process at once.
class StopSignals {
 public:
  StopSignals();   ///< clears the flag, installs the handlers
  ~StopSignals();  ///< restores the previous handlers
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// Set by the first SIGINT or SIGTERM (lock-free, so a handler may set it).
  static std::atomic<bool>& flag();
  static bool requested() { return flag().load(); }

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

}  // namespace pvb::cli
