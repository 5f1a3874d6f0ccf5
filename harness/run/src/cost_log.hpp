#pragma once
// The run's costs as its map grows: a sample every `every_frames` frames
// (and one at the end) of memory and of each stage's time over the frames
// since the sample before, kept and written to costs.csv as they come
// (docs/run.md, "Costs as the map grows").
#include <cstddef>
#include <string>
#include <vector>

#include "pvb/common/output_file.hpp"
#include "pvb/report/report.hpp"
#include "pvb/slam/core/system.hpp"

namespace pvb::run {

class CostLog {
 public:
  static constexpr int kEveryFrames = 300;

  /// Starts costs.csv at `path` with its header.
  void open(const std::string& path, int every_frames = kEveryFrames);
  /// One frame tracked by `system`: a sample after every every_frames-th.
  void frame(slam::System& system, int index, double t_s, double tracking_ms);
  /// The last sample, when frames came since the one before; call before
  /// the system shuts down (its map is still whole).
  void finish(slam::System& system);

  const std::vector<CostSample>& samples() const { return samples_; }
  int every_frames() const { return every_frames_; }

 private:
  void sample(slam::System& system);

  OutputFile csv_;
  int every_frames_ = 0;
  std::vector<double> window_ms_;  ///< tracking times since the last sample
  int last_index_ = 0;
  double last_t_s_ = 0;
  slam::LoopDetectTotals loops_;
  slam::LocalMappingStats mapping_;
  std::vector<CostSample> samples_;
};

}  // namespace pvb::run
