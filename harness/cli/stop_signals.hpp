#pragma once
// Ctrl-C (SIGINT), SIGTERM and SIGHUP (the terminal closed) as a request
// to stop, for `pvbench record`, `run`, `slam`, `camera` and the others that
// take frames: the command polls the flag, stops taking frames and still
// writes everything it has (trajectories, maps, stats, report, meta.json).
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

  /// Set by the first SIGINT, SIGTERM or SIGHUP (lock-free, so a handler may set it).
  static std::atomic<bool>& flag();
  static bool requested() { return flag().load(); }

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
  struct sigaction old_hup_ {};
};

}  // namespace pvb::cli
