#include "frame_pipeline.hpp"

#include <algorithm>
#include <exception>
#include <future>
#include <optional>
#include <thread>

#include "pvb/common/closable_queue.hpp"
#include "pvb/common/text.hpp"
#include "pvb/common/threads.hpp"

namespace pvb::run {
namespace {

bool stopping(const RunOptions& opt) { return opt.stop && opt.stop->load(); }

/// The simulator is built: the consumer learns of it, the log names the renderer.
void announce(const SimInfo& info, FrameConsumer& consumer, RunLog& log) {
  consumer.started(info);
  log.line("renderer: " + info.renderer);
}

/// Pushes an item, adding the time spent waiting for room to *wait_ms.
template <typename T>
bool push_timed(ClosableQueue<T>& queue, T&& item, double* wait_ms) {
  const auto t_wait = Clock::now();
  const bool pushed = queue.push(std::move(item));
  *wait_ms += ms_since(t_wait);
  return pushed;
}

/// Sync: producer and consumer in turn on the calling thread.
LoopTimes run_sync(const scenes::Scenario& scenario, sim::GlBackend backend, int frames, Steering* steering,
                   const RunOptions& opt, FrameConsumer& consumer, RunLog& log) {
  LoopTimes t;
  const auto t_setup = Clock::now();
  FrameProducer producer(scenario, backend, frames, steering);
  t.setup_ms = ms_since(t_setup);
  announce(producer.info(), consumer, log);
  t.start = Clock::now();
  t.start_cpu_s = process_cpu_s();
  while (!stopping(opt)) {
    // Nothing else runs in sync mode, so the process CPU time of each half
    // (every thread: llvmpipe's and OpenCV's workers too) is its cost,
    // whatever else loads the machine.
    const double c0 = process_cpu_s();
    std::optional<FrameItem> item = producer.next();
    const double c1 = process_cpu_s();
    t.sim_cpu_ms += 1000.0 * (c1 - c0);
    if (!item) break;
    const bool go_on = consumer.consume(*item);
    t.slam_cpu_ms += 1000.0 * (process_cpu_s() - c1);
    if (!go_on) break;
  }
  return t;
}

/// Pipelined: local and dense mapping workers (found by name) at a lower
/// priority while tracking keeps up with the camera.  A loop that cannot
/// keep up gains nothing from starving local mapping: mapping goes back to
/// the common priority while tracking is more than kBehindFrames periods
/// late, and yields again once it is within kCaughtUpFrames.
class MappingPriority {
 public:
  MappingPriority(const RunOptions& opt, double fps, RunLog& log)
      : pace_(opt.pace), fps_(fps), nice_(opt.mapping_nice.value_or(opt.pace ? 10 : 0)), log_(log) {
    yields_ = nice_ != 0;  // the workers are at nice_
    if (nice_ != 0) {
      // The workers started with the systems and have named themselves by
      // now (the renderer's start-up took far longer).
      const int changed = set_nice(nice_);
      log_.line("mapping workers: " + std::to_string(changed) + " at nice " + std::to_string(nice_));
    }
  }

  /// Frame `index` was tracked `latency_ms` after it was due.
  void after_frame(int index, double latency_ms) {
    // Not in the first second: start-up makes frame 0 late anyway.
    if (!pace_ || nice_ == 0 || index < static_cast<int>(fps_)) return;
    constexpr double kBehindFrames = 6, kCaughtUpFrames = 2;
    const double late_frames = latency_ms * fps_ / 1000.0;
    const bool yield = yields_ ? late_frames < kBehindFrames : late_frames < kCaughtUpFrames;
    if (yield == yields_) return;
    yields_ = yield;
    const int nice = yield ? nice_ : 0;
    set_nice(nice);
    ++changes_;
    if (changes_ <= 10)
      log_.line("frame " + std::to_string(index) + ": tracked " + format_g(latency_ms) +
                " ms after it was due; mapping workers at nice " + std::to_string(nice));
  }

  /// The number of changes, when more were made than logged.
  void log_total() const {
    if (changes_ > 10) log_.line("mapping priority changed " + std::to_string(changes_) + " times in all");
  }

 private:
  /// Returns how many threads it changed.
  static int set_nice(int nice) {
    return set_thread_nice("pvb-mapping", nice) + set_thread_nice("pvb-dense", nice);
  }

  bool pace_;
  double fps_;
  int nice_;     ///< while tracking keeps up (0: never changed)
  bool yields_;  ///< the workers are at nice_
  int changes_ = 0;
  RunLog& log_;
};

/// Pipelined: render thread (steering, physics, rendering) -> rendered
/// queue -> sensor thread (sensor model) -> frame queue -> the consumer on
/// the calling thread.  No stage has to fit the whole simulation into one
/// frame period.  In the closed loop the sensor model stays on the render
/// thread and the frame queue holds one frame, so the steering pose is at
/// most two frames old.
class FramePipeline {
 public:
  FramePipeline(const scenes::Scenario& scenario, sim::GlBackend backend, int frames, Steering* steering,
                const RunOptions& opt, RunLog& log)
      : scenario_(scenario),
        backend_(backend),
        frames_(frames),
        steering_(steering),
        opt_(opt),
        log_(log),
        sensor_thread_on_(!opt.closed_loop),
        queue_(opt.closed_loop ? 1 : std::max<std::size_t>(opt.queue_capacity, 1)),
        released_(release_.get_future().share()) {}
  /// However the consumer leaves (end, stop, abort, exception), both stages
  /// are released and joined.
  ~FramePipeline() { stop_and_join(); }

  LoopTimes run(FrameConsumer& consumer);

 private:
  Clock::time_point frame_due(int i) const {
    return pace_start_ + std::chrono::duration_cast<Clock::duration>(
                             std::chrono::duration<double>(static_cast<double>(i) / scenario_.camera.fps));
  }
  void render_stage();
  void render_frames(FrameProducer& producer);
  void sensor_stage();
  void consume_frames(FrameConsumer& consumer, MappingPriority& priority);
  void stop_and_join();

  const scenes::Scenario& scenario_;
  const sim::GlBackend backend_;
  const int frames_;
  Steering* const steering_;
  const RunOptions& opt_;
  RunLog& log_;
  const bool sensor_thread_on_;
  ClosableQueue<RenderedItem> rendered_queue_{2};
  ClosableQueue<FrameItem> queue_;
  std::promise<SimInfo> ready_;
  SimInfo info_;                  ///< from the render thread, once the simulator is built
  Clock::time_point pace_start_;  ///< frame i is due at pace_start_ + i / fps (set before ready_)
  LoopTimes times_;               ///< each field written by one thread, read after the joins
  std::exception_ptr render_error_, sensor_error_;
  // The render thread keeps its GL context (and llvmpipe's threads) until
  // released, so that the per-thread CPU times can be read at the end.
  std::promise<void> release_;
  std::shared_future<void> released_;
  bool release_set_ = false;
  std::thread render_thread_, sensor_thread_;
};

LoopTimes FramePipeline::run(FrameConsumer& consumer) {
  std::future<SimInfo> ready = ready_.get_future();
  render_thread_ = std::thread([this] { render_stage(); });
  info_ = ready.get();  // rethrows a setup error (the destructor joins)
  announce(info_, consumer, log_);
  MappingPriority priority(opt_, scenario_.camera.fps, log_);
  log_.line(opt_.pace ? "frames paced at " + format_g(scenario_.camera.fps) + " Hz"
                      : "frames not paced (as fast as the stages go)");
  if (sensor_thread_on_) sensor_thread_ = std::thread([this] { sensor_stage(); });
  times_.start = pace_start_;  // when frame 0 began (set before `ready`, so visible here)
  times_.start_cpu_s = process_cpu_s();
  times_.thread_cpu_start = thread_cpu_ms();
  consume_frames(consumer, priority);
  priority.log_total();
  queue_.close_and_clear();
  rendered_queue_.close_and_clear();
  times_.thread_cpu_end = thread_cpu_ms();  // every stage still lives, waiting for release
  stop_and_join();
  if (render_error_) std::rethrow_exception(render_error_);
  if (sensor_error_) std::rethrow_exception(sensor_error_);
  return times_;
}

void FramePipeline::render_stage() {
  set_thread_name("pvb-render");
  bool started = false;
  try {
    const auto t_setup = Clock::now();
    FrameProducer producer(scenario_, backend_, frames_, steering_);
    times_.setup_ms = ms_since(t_setup);
    pace_start_ = Clock::now();
    ready_.set_value(producer.info());
    started = true;
    render_frames(producer);
    rendered_queue_.close();
    if (!sensor_thread_on_) queue_.close();
    released_.wait();
  } catch (...) {
    if (started)
      render_error_ = std::current_exception();
    else
      ready_.set_exception(std::current_exception());
    rendered_queue_.close();
    queue_.close();
  }
}

void FramePipeline::render_frames(FrameProducer& producer) {
  for (int i = 0; !stopping(opt_); ++i) {
    // A camera delivers frame i at i / fps: wait for it (a blocking
    // sleep of at most one period, so Ctrl-C is seen in time).
    if (opt_.pace) std::this_thread::sleep_until(frame_due(i));
    bool pushed = false;
    if (sensor_thread_on_) {
      std::optional<RenderedItem> item = producer.next_rendered();
      if (!item) break;
      pushed = push_timed(rendered_queue_, std::move(*item), &times_.producer_wait_ms);
    } else {
      std::optional<FrameItem> item = producer.next();
      if (!item) break;
      pushed = push_timed(queue_, std::move(*item), &times_.producer_wait_ms);
    }
    if (!pushed) break;
  }
}

void FramePipeline::sensor_stage() {
  set_thread_name("pvb-sensor");
  try {
    while (true) {
      const auto t_wait = Clock::now();
      std::optional<RenderedItem> item = rendered_queue_.pop();
      times_.sensor_wait_ms += ms_since(t_wait);
      if (!item) break;
      FrameItem frame = apply_sensor(*info_.sensor, std::move(*item));
      if (!push_timed(queue_, std::move(frame), &times_.sensor_wait_ms)) break;
    }
  } catch (...) {
    sensor_error_ = std::current_exception();
  }
  rendered_queue_.close_and_clear();  // the render thread stops too
  queue_.close();
  released_.wait();  // alive for the CPU table
}

void FramePipeline::consume_frames(FrameConsumer& consumer, MappingPriority& priority) {
  while (!stopping(opt_)) {
    const auto t_wait = Clock::now();
    std::optional<FrameItem> item = queue_.pop();
    times_.consumer_wait_ms += ms_since(t_wait);
    if (!item) break;
    const int index = static_cast<int>(item->frame.index);
    const bool go_on = consumer.consume(*item);
    // From when the frame was due (paced) or rendering began on the
    // simulated clock (not paced) to when it is tracked.
    const double latency_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - frame_due(index)).count();
    times_.frame_latency_ms += latency_ms;
    times_.frame_latency_max_ms = std::max(times_.frame_latency_max_ms, latency_ms);
    priority.after_frame(index, latency_ms);
    if (!go_on) break;
  }
}

void FramePipeline::stop_and_join() {
  queue_.close_and_clear();
  rendered_queue_.close_and_clear();
  if (!release_set_) release_.set_value();
  release_set_ = true;
  if (sensor_thread_.joinable()) sensor_thread_.join();
  if (render_thread_.joinable()) render_thread_.join();
}

}  // namespace

LoopTimes run_frames(const scenes::Scenario& scenario, sim::GlBackend backend, int frames, Steering* steering,
                     const RunOptions& options, FrameConsumer& consumer, RunLog& log) {
  if (options.sync) return run_sync(scenario, backend, frames, steering, options, consumer, log);
  FramePipeline pipeline(scenario, backend, frames, steering, options, log);
  return pipeline.run(consumer);
}

}  // namespace pvb::run
