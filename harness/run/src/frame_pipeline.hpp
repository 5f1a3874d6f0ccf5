#pragma once
// The frame loop of a scenario run: the producer (simulator) hands frames to
// a consumer (SLAM and the harness' bookkeeping), either in turn on the
// calling thread (sync) or pipelined over three threads:
//
//   render thread (pvb-render): steering, physics, rendering -> rendered queue (2)
//   sensor thread (pvb-sensor): sensor model                 -> frame queue (queue_capacity)
//   calling thread:             the consumer (tracking)
//
// paced at the camera's frame rate, with local and dense mapping at a lower
// priority while tracking keeps up.  In the closed loop the sensor model
// stays on the render thread and the frame queue holds one frame.
#include <map>
#include <string>

#include "frame_producer.hpp"
#include "pvb/run/run_options.hpp"
#include "pvb/scenes/scenario.hpp"
#include "run_log.hpp"

namespace pvb::run {

/// The consumer's side of the loop (called on the calling thread).
class FrameConsumer {
 public:
  virtual ~FrameConsumer() = default;
  /// The simulator is built; called once, before the first frame.
  virtual void started(const SimInfo& info) = 0;
  /// One frame; returns false to stop the run.
  virtual bool consume(FrameItem& item) = 0;
};

/// What the loop measured, besides what the consumer records.
struct LoopTimes {
  double setup_ms = 0;      ///< building the simulator and the renderer
  Clock::time_point start;  ///< when frame 0 began
  double start_cpu_s = 0;   ///< process CPU time then
  // Sync: process CPU time of each half (nothing else runs).
  double sim_cpu_ms = 0, slam_cpu_ms = 0;
  // Pipelined: time each stage waited on its queues.
  double producer_wait_ms = 0, sensor_wait_ms = 0, consumer_wait_ms = 0;
  /// Pipelined: from when a frame was due to when it was tracked, summed, and the worst.
  double frame_latency_ms = 0, frame_latency_max_ms = 0;
  /// Pipelined: CPU time per thread (by name) at the start and end of the loop, from /proc.
  std::map<std::string, double> thread_cpu_start, thread_cpu_end;
};

/// The frames of the scenario through `consumer` until the producer runs out,
/// the consumer stops or options.stop is raised; sync or pipelined as
/// options.sync says.  Rethrows an error of any stage; however the loop is
/// left, every stage is stopped and joined.
LoopTimes run_frames(const scenes::Scenario& scenario, sim::GlBackend backend, int frames, Steering* steering,
                     const RunOptions& options, FrameConsumer& consumer, RunLog& log);

}  // namespace pvb::run
