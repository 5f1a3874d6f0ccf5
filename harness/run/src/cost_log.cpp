#include "cost_log.hpp"

#include "pvb/common/memory.hpp"
#include "pvb/common/text.hpp"

namespace pvb::run {
namespace {

double megabytes(std::size_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }

/// The sparse map's bytes: the map's keyframes and points, the culled
/// keyframes kept for the trajectory, the place database.
std::size_t sparse_bytes(const slam::SystemMemory& m) {
  return m.map.keyframe_bytes.total() + m.map.point_bytes + m.culled_bytes.total() + m.place_database_bytes;
}

}  // namespace

void CostLog::open(const std::string& path, int every_frames) {
  every_frames_ = every_frames;
  csv_ = OutputFile(path);
  std::string head;
  for (const std::string& c : cost_columns()) head += (head.empty() ? "" : ",") + c;
  csv_.append(head + "\n");
}

void CostLog::frame(slam::System& system, int index, double t_s, double tracking_ms) {
  if (every_frames_ <= 0) return;
  window_ms_.push_back(tracking_ms);
  last_index_ = index;
  last_t_s_ = t_s;
  if (window_ms_.size() >= static_cast<std::size_t>(every_frames_)) sample(system);
}

void CostLog::finish(slam::System& system) {
  if (every_frames_ > 0 && !window_ms_.empty()) sample(system);
  csv_.close();
}

void CostLog::sample(slam::System& system) {
  CostSample c;
  c.frame = last_index_;
  c.t_s = last_t_s_;
  c.tracking_ms_median = percentile(window_ms_, 0.5);
  c.tracking_ms_p95 = percentile(window_ms_, 0.95);
  const slam::SystemMemory memory = system.memory();
  c.keyframes = system.num_keyframes();
  c.points = system.num_map_points();
  // Free pages left in the allocator's arenas (the dense map's spills and
  // loads, the threads' turns) go back first: the column is what the run holds.
  return_free_heap();
  c.rss_mb = megabytes(resident_bytes());
  c.sparse_mb = megabytes(sparse_bytes(memory));
  c.dense_mb = megabytes(memory.dense.total());
  c.dense_disk_mb = megabytes(memory.dense.spilled_keyframe_bytes + memory.dense.spilled_map_bytes);
  c.sparse_disk_mb = megabytes(memory.feature_spill.live_bytes());
  const slam::LoopDetectTotals loops = system.loop_detect_totals();
  const slam::LocalMappingStats mapping = system.mapping_stats();
  if (const std::size_t n = loops.detections - loops_.detections; n > 0)
    c.loop_detect_ms = (loops.detect_ms - loops_.detect_ms) / static_cast<double>(n);
  if (const std::int64_t n = mapping.keyframes - mapping_.keyframes; n > 0)
    c.mapping_ms_per_keyframe = (mapping.busy_ms - mapping_.busy_ms) / static_cast<double>(n);
  if (const std::int64_t n = mapping.local_ba - mapping_.local_ba; n > 0)
    c.local_ba_ms = (mapping.local_ba_ms - mapping_.local_ba_ms) / static_cast<double>(n);
  loops_ = loops;
  mapping_ = mapping;
  window_ms_.clear();
  samples_.push_back(c);
  std::string line;
  for (double v : cost_values(c)) line += (line.empty() ? "" : ",") + format_g(v);
  csv_.append(line + "\n");
}

}  // namespace pvb::run
