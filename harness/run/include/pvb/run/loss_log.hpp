#pragma once
// The run.log lines of one system's losses between the loss line and the
// recovery line: why each relocalisation attempt failed (consecutive frames
// with the same reason folded into one line), and a summary per loss stretch.
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace pvb::run {

/// Per system: feed every frame in order; write the lines it returns.
class LossLog {
 public:
  /// `mode`: the system's name in the lines ("pe-slam", "baseline");
  /// `starts_lost`: the system starts lost (in a loaded map), so its first
  /// frame is already a relocalisation attempt.
  explicit LossLog(std::string mode, bool starts_lost = false) : mode_(std::move(mode)), in_loss_(starts_lost) {}

  /// Frame `index` at `t_s`, lost or not.  A lost frame after a lost frame
  /// is a failed relocalisation attempt: `reason` is why (TrackingStats::
  /// failure) and `kind` the step it failed at (to_string(RelocFailure)).
  /// Returns the lines to log now: the attempts before this one when its
  /// reason differs, and on the first frame not lost after a loss the
  /// attempts not yet written and the stretch's summary.
  std::vector<std::string> frame(int index, double t_s, bool lost, const std::string& reason,
                                 const std::string& kind);
  /// At the end of the run: the lines of a loss stretch still open.
  std::vector<std::string> finish();

 private:
  void flush(std::vector<std::string>* out);
  std::string summary(const std::string& end) const;

  std::string mode_;
  bool in_loss_ = false;
  int first_lost_ = 0, last_lost_ = 0;
  // attempts with the same reason not yet written: frames, times, reason
  int run_first_ = -1, run_last_ = -1;
  double run_t0_ = 0, run_t1_ = 0;
  std::string run_reason_;
  std::vector<std::pair<std::string, int>> kinds_;  ///< failed attempts per step, in order of first appearance
  int attempts_ = 0;
};

}  // namespace pvb::run
