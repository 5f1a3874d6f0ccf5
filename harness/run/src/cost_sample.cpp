// The run's costs as its map grows: a sample every SystemSink::
// cost_every_frames frames (and one at the end) of memory and of each
// stage's time over the frames since the sample before, into run.costs
// and costs.csv (docs/run.md, "Costs as the map grows").
#include "pvb/common/memory.hpp"
#include "pvb/common/text.hpp"
#include "system_sink.hpp"

namespace pvb::run {
namespace {

double megabytes(std::size_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }

/// The sparse map's bytes: the map's keyframes and points, the culled
/// keyframes kept for the trajectory, the place database.
std::size_t sparse_bytes(const slam::SystemMemory& m) {
  return m.map.keyframe_bytes.total() + m.map.point_bytes + m.culled_bytes.total() + m.place_database_bytes;
}

}  // namespace

void SystemSink::sample_costs() {
  CostSample c;
  const FrameRecord& last = run.per_frame.back();
  c.frame = last.frame;
  c.t_s = last.t_s;
  std::vector<double> ms;
  for (std::size_t i = cost_window_.first_frame; i < run.per_frame.size(); ++i)
    ms.push_back(run.per_frame[i].tracking_ms);
  c.tracking_ms_median = percentile(ms, 0.5);
  c.tracking_ms_p95 = percentile(ms, 0.95);
  const slam::SystemMemory memory = system->memory();
  c.keyframes = system->num_keyframes();
  c.points = system->num_map_points();
  c.rss_mb = megabytes(resident_bytes());
  c.sparse_mb = megabytes(sparse_bytes(memory));
  c.dense_mb = megabytes(memory.dense.total());
  const slam::LoopDetectTotals loops = system->loop_detect_totals();
  const slam::LocalMappingStats mapping = system->mapping_stats();
  if (const std::size_t n = loops.detections - cost_window_.loops.detections; n > 0)
    c.loop_detect_ms = (loops.detect_ms - cost_window_.loops.detect_ms) / static_cast<double>(n);
  if (const std::int64_t n = mapping.keyframes - cost_window_.mapping.keyframes; n > 0)
    c.mapping_ms_per_keyframe = (mapping.busy_ms - cost_window_.mapping.busy_ms) / static_cast<double>(n);
  cost_window_ = {run.per_frame.size(), loops, mapping};
  run.costs.push_back(c);
  std::string line;
  for (double v : cost_values(c)) line += (line.empty() ? "" : ",") + format_g(v);
  costs_csv.append(line + "\n");
}

}  // namespace pvb::run
