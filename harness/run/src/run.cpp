#include "pvb/run/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <fstream>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "pvb/common/closable_queue.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/common/threads.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/sim/sim_frame_source.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"

namespace pvb::run {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// CPU time of the whole process (every thread, GL workers included), seconds.
double process_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double wrap_angle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::ofstream open_out(const std::string& path) {
  std::ofstream f(path);
  if (!f) throw IoError(path, "cannot open for writing");
  return f;
}

/// run.log, flushed line by line; also kept for index.html and echoed.
class RunLog {
 public:
  RunLog(const std::string& path, std::function<void(const std::string&)> echo)
      : file_(open_out(path)), echo_(std::move(echo)) {}
  void line(const std::string& text) {
    file_ << text << "\n" << std::flush;
    lines_.push_back(text);
    if (echo_) echo_(text);
  }
  const std::vector<std::string>& lines() const { return lines_; }

 private:
  std::ofstream file_;
  std::function<void(const std::string&)> echo_;
  std::vector<std::string> lines_;
};

/// Closed loop: what the consumer (SLAM) tells the producer (simulator)
/// before the next physics step.
struct Steering {
  std::mutex mutex;
  bool hold = true;                 ///< not initialised or lost: stand still
  std::optional<sim::Pose2d> pose;  ///< the robot's pose as SLAM sees it (site frame)
};

/// One frame from the producer: the sensor frame for SLAM and, beside it
/// (never inside it), the ground truth for the harness.
struct FrameItem {
  sensor::RgbdFrame frame;
  geom::StampedPose gt;  ///< T_w_c of the frame, from the ground-truth sink
  sim::Pose2d base_gt;   ///< robot axle centre, ground truth
  sim::SimFrameSource::StageTimes times;
};

/// A frame between the render stage and the sensor-model stage.
struct RenderedItem {
  sim::RenderedFrame rendered;
  geom::StampedPose gt;
  sim::Pose2d base_gt;
  sim::SimFrameSource::StageTimes times;
};

/// The sensor-model stage: a pure function of the rendered frame (noise
/// seeded by scenario seed and frame index), so it gives the same frame on
/// whichever thread it runs.
FrameItem apply_sensor(const sim::SensorModel& sensor, RenderedItem&& item) {
  sim::Capture cap = sensor.apply(std::move(item.rendered));
  item.times.sensor_ms = cap.sensor_ms;
  return FrameItem{std::move(cap.frame), item.gt, item.base_gt, item.times};
}

/// What the consumer needs to know about the simulator once it is built.
struct SimInfo {
  std::string renderer;
  std::vector<Eigen::Vector2d> route;
  std::optional<sim::SensorModel> sensor;  ///< a copy, for the sensor-model thread
};

/// The simulator side: builds the scene and renderer on the thread that
/// will render (a GL context belongs to its thread), applies the closed-loop
/// steering before each physics step and hands rendered frames out.
class FrameProducer {
 public:
  FrameProducer(const scenes::Scenario& scenario, sim::GlBackend backend, int frames, Steering* steering)
      : source_(scenario, backend, frames, [this](const geom::StampedPose& p) { gt_ = p; }),
        steering_(steering) {
    info_.renderer = source_.camera().description();
    info_.route = source_.simulator().follower().path();
    info_.sensor = source_.sensor_model();
  }
  const SimInfo& info() const { return info_; }

  /// Steering, physics and rendering (the GL thread's part).
  std::optional<RenderedItem> next_rendered() {
    sim::Simulator& sim = source_.simulator();
    if (steering_) {
      std::lock_guard<std::mutex> lock(steering_->mutex);
      sim.set_hold(steering_->hold);
      sim.set_steering_pose(steering_->pose);
    }
    std::optional<sim::RenderedFrame> r = source_.next_rendered();
    if (!r) return std::nullopt;
    return RenderedItem{std::move(*r), gt_, sim.base_pose(), source_.last_stage_times()};
  }

  /// Both stages on the calling thread.
  std::optional<FrameItem> next() {
    std::optional<RenderedItem> r = next_rendered();
    if (!r) return std::nullopt;
    return apply_sensor(source_.sensor_model(), std::move(*r));
  }

 private:
  sim::SimFrameSource source_;
  Steering* steering_;
  geom::StampedPose gt_;
  SimInfo info_;
};

/// One SLAM system with its output files and bookkeeping.
struct SystemSink {
  SlamRun run;
  std::unique_ptr<slam::System> system;
  std::string dir;
  std::ofstream cam_traj, kf_traj, timing;
  eval::Trajectory est;
  eval::Trajectory refined;  ///< filled by finish()
  slam::TrackingState prev_state = slam::TrackingState::kNotInitialized;
  double tracking_ms = 0, orb_ms = 0, inline_mapping_ms = 0;

  SystemSink(const std::string& mode, const slam::Settings& settings, bool sync, std::uint32_t seed,
             const std::string& out_dir)
      : dir(out_dir) {
    run.mode = mode;
    slam::SystemOptions options;
    options.synchronous = sync;
    options.seed = seed;
    system = std::make_unique<slam::System>(settings, options);
    cam_traj = open_out(dir + "/CameraTrajectory.txt");
    kf_traj = open_out(dir + "/KeyFrameTrajectory.txt");
    timing = open_out(dir + "/timing.csv");
    cam_traj << "# timestamp tx ty tz qx qy qz qw (T_w_c; w = camera frame of the first tracked frame)\n";
    kf_traj << "# timestamp tx ty tz qx qy qz qw (T_w_c)\n";
    timing << "frame,t_s,state,method,features,tracking_ms,orb_ms,pe_match_ms,coarse_matches,matches_kept,"
              "inliers,"
              "keyframe,mapping_ms\n";
    est.source = dir + "/CameraTrajectory.txt";
  }

  /// Tracks one frame, writes its lines and records loss and recovery.
  slam::FrameResult track(const sensor::RgbdFrame& frame, RunLog& log) {
    const slam::FrameResult r = system->track(frame);
    const int index = static_cast<int>(frame.index);
    const double t_s = geom::ns_to_seconds(frame.t_ns);
    ++run.frames;
    if (r.state == slam::TrackingState::kLost) ++run.lost_frames;
    if (r.state == slam::TrackingState::kNotInitialized) ++run.not_initialized_frames;
    tracking_ms += r.tracking_ms;
    orb_ms += r.orb_ms;
    inline_mapping_ms += r.mapping_ms;
    run.per_frame.push_back(
        {index, t_s, r.T_w_c.has_value(), r.tracking_ms, r.tracking.coarse_matches, r.tracking.matches_kept});
    if (r.T_w_c) {
      cam_traj << geom::format_tum_line({r.t_ns, *r.T_w_c}) << "\n" << std::flush;
      est.poses.push_back({r.t_ns, *r.T_w_c});
      if (r.tracking.new_keyframe) kf_traj << geom::format_tum_line({r.t_ns, *r.T_w_c}) << "\n" << std::flush;
    }
    static const char* kMethods[] = {"none", "init", "motion", "refkf", "reloc"};
    timing << index << "," << geom::format_tum_time(r.t_ns) << "," << slam::to_string(r.state) << ","
           << kMethods[static_cast<int>(r.tracking.method)] << "," << r.num_features << ","
           << fmt(r.tracking_ms) << "," << fmt(r.orb_ms) << "," << fmt(r.tracking.pe_match_ms) << ","
           << r.tracking.coarse_matches << "," << r.tracking.matches_kept << "," << r.tracking.inliers << ","
           << (r.tracking.new_keyframe ? 1 : 0) << "," << fmt(r.mapping_ms) << "\n"
           << std::flush;

    char head_buf[96];
    std::snprintf(head_buf, sizeof head_buf, "frame %d (t = %.3f s): %s ", index, t_s, run.mode.c_str());
    const std::string head = head_buf;
    const std::string reason = r.tracking.failure.empty() ? "no reason given" : r.tracking.failure;
    if (r.state == slam::TrackingState::kLost && prev_state != slam::TrackingState::kLost) {
      run.loss_events.push_back({index, t_s, reason, std::nullopt});
      log.line(head + std::string("lost tracking: ") + reason);
    } else if (r.state == slam::TrackingState::kOk && prev_state == slam::TrackingState::kLost) {
      if (!run.loss_events.empty()) run.loss_events.back().recovered_frame = index;
      log.line(head + std::string("relocalised"));
    } else if (r.state == slam::TrackingState::kNotInitialized && run.frames == 1) {
      log.line(head + "not initialised: " + reason);
    } else if (r.state == slam::TrackingState::kOk && prev_state == slam::TrackingState::kNotInitialized) {
      log.line(head + "initialised");
    }
    prev_state = r.state;
    return r;
  }

  /// Stops mapping, rewrites the keyframe trajectory with refined poses.
  void finish() {
    system->shutdown();
    kf_traj.close();
    std::string text =
        "# timestamp tx ty tz qx qy qz qw (T_w_c, refined by local BA; culled keyframes left out)\n";
    for (const auto& p : system->keyframe_trajectory()) text += geom::format_tum_line(p) + "\n";
    write_file(dir + "/KeyFrameTrajectory.txt", text);
    // Each frame re-anchored on its reference keyframe's final pose (local
    // BA, loop closing), as ORB-SLAM2 saves its trajectory.
    refined.source = dir + "/CameraTrajectoryRefined.txt";
    refined.poses = system->refined_trajectory();
    std::string rtext = "# timestamp tx ty tz qx qy qz qw (T_w_c, re-anchored on the final keyframe poses)\n";
    for (const auto& p : refined.poses) rtext += geom::format_tum_line(p) + "\n";
    write_file(refined.source, rtext);
    if (system->loop_closing_enabled()) {
      const slam::LoopClosingStats loops = system->loop_stats();
      run.loop_closing_json = slam::to_json(loops);
      run.loops_closed = loops.loops.size();
    }
    cam_traj.close();
    timing.close();
    run.keyframes = system->num_keyframes();
    run.map_points = system->num_map_points();
    run.local_mapping = system->mapping_stats();
  }

  void evaluate(const eval::Trajectory& gt) {
    if (est.poses.size() < 3) {
      run.eval_note = "only " + std::to_string(est.poses.size()) + " tracked frames (need 3)";
      return;
    }
    eval::EvalOptions eo;
    try {
      run.eval = eval::evaluate(gt, est, eo);
    } catch (const eval::EvalError& e) {
      // A numerically degenerate set (a robot that did not move): the SLAM
      // world is its first camera frame, so align that instead.
      eo.alignment = eval::Alignment::kOrigin;
      try {
        run.eval = eval::evaluate(gt, est, eo);
        run.eval_note = std::string("se3 alignment impossible (") + e.what() + "); origin alignment";
      } catch (const eval::EvalError& e2) {
        run.eval_note = e2.what();
      }
    }
    if (run.eval && refined.poses.size() >= 3) {
      try {
        run.refined_eval = eval::evaluate(gt, refined, eo);
      } catch (const eval::EvalError&) {
        // left out of the report: the primary evaluation stands
      }
    }
  }
};

}  // namespace

dataset::OrbSlamSettings orbslam_settings_for(const scenes::Scenario& s) {
  dataset::OrbSlamSettings o;
  o.K = {s.camera.fx, s.camera.fy, s.camera.cx(), s.camera.cy(), s.camera.width, s.camera.height};
  o.fps = s.camera.fps;
  o.bf = s.camera.depth_noise.baseline_m * s.camera.fx;
  // ThDepth is in baselines: points beyond depth_range max are "far".
  o.th_depth = s.camera.depth_range_m.y() / s.camera.depth_noise.baseline_m;
  o.rgb_order = 1;
  o.n_features = s.slam.orb_features;
  o.kf_min_tracked_close = s.slam.keyframe_min_tracked_close;
  o.kf_ref_overlap = s.slam.keyframe_ref_overlap;
  return o;
}

double camera_heading(const geom::SE3d& T_w_c) {
  const Eigen::Vector3d z = T_w_c.linear().col(2);
  return std::atan2(z.y(), z.x());
}

CameraMount measure_mount(const sim::Pose2d& base, const geom::SE3d& T_w_c) {
  CameraMount m;
  m.yaw_offset = wrap_angle(camera_heading(T_w_c) - base.yaw);
  const Eigen::Vector2d d(T_w_c.translation().x() - base.x, T_w_c.translation().y() - base.y);
  const double c = std::cos(base.yaw), s = std::sin(base.yaw);
  m.offset_b = Eigen::Vector2d(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
  return m;
}

sim::Pose2d base_from_camera(const geom::SE3d& T_w_c, const CameraMount& mount) {
  sim::Pose2d p;
  p.yaw = wrap_angle(camera_heading(T_w_c) - mount.yaw_offset);
  const double c = std::cos(p.yaw), s = std::sin(p.yaw);
  p.x = T_w_c.translation().x() - (c * mount.offset_b.x() - s * mount.offset_b.y());
  p.y = T_w_c.translation().y() - (s * mount.offset_b.x() + c * mount.offset_b.y());
  return p;
}

RunReport run_scenario(const RunOptions& opt) {
  const sim::GlBackend backend = sim::parse_gl_backend(opt.gl);
  scenes::Scenario scenario = scenes::load_scenario(opt.scenario_file);
  if (opt.seed) scenario.seed = *opt.seed;
  const int n = scenes::frame_count(scenario, opt.max_frames);
  dataset::make_dirs(opt.out_dir);
  const bool compare = opt.mode == SlamMode::kCompare;
  if (compare) dataset::make_dirs(opt.out_dir + "/baseline");

  RunLog log(opt.out_dir + "/run.log", opt.on_log);
  auto stopping = [&opt] { return opt.stop && opt.stop->load(); };

  // SLAM settings from the scenario's camera, kept in the report as camera.yaml.
  dataset::write_orbslam_settings(opt.out_dir + "/camera.yaml", orbslam_settings_for(scenario));
  slam::Settings settings = slam::read_settings(opt.out_dir + "/camera.yaml");
  for (const std::string& w : settings.warnings) log.line("warning: " + w);
  const auto slam_seed = static_cast<std::uint32_t>(scenario.seed);
  std::vector<std::unique_ptr<SystemSink>> sinks;
  {
    slam::Settings s = settings;
    s.loop.enabled = s.loop.enabled && opt.loop_closing;
    s.pe_match.enabled = opt.mode != SlamMode::kBaseline;
    sinks.push_back(std::make_unique<SystemSink>(s.pe_match.enabled ? "pe-slam" : "orb-slam2", s, opt.sync,
                                                 slam_seed, opt.out_dir));
    if (compare) {
      s.pe_match.enabled = false;
      sinks.push_back(
          std::make_unique<SystemSink>("orb-slam2", s, opt.sync, slam_seed, opt.out_dir + "/baseline"));
    }
  }

  RunReport report;
  report.scenario = scenario.name;
  report.scenario_file = opt.scenario_file;
  report.seed = scenario.seed;
  report.sync = opt.sync;
  report.fps = scenario.camera.fps;

  std::ofstream gt_file = open_out(opt.out_dir + "/groundtruth.txt");
  gt_file
      << "# timestamp tx ty tz qx qy qz qw (T_w_c: camera optical frame in the site frame, ground truth)\n";
  eval::Trajectory gt;
  gt.source = opt.out_dir + "/groundtruth.txt";

  Steering steering;
  Steering* steering_ptr = opt.closed_loop ? &steering : nullptr;
  ClosedLoopMetrics closed;
  std::vector<Eigen::Vector2d> route;
  CameraMount mount;
  geom::SE3d T_site_slam = geom::SE3d::Identity();  // SLAM world (first camera frame) in the site frame
  const std::vector<int> sheet_frames = plot::spread_indices(n, 12);

  double physics_ms = 0, render_ms = 0, sensor_ms = 0, producer_wait_ms = 0, sensor_wait_ms = 0,
         consumer_wait_ms = 0, output_ms = 0;
  double frame_latency_ms = 0, frame_latency_max_ms = 0;  // pipelined: due time to tracked
  // Pipelined: CPU time per thread (by name) over the loop, from /proc.
  std::map<std::string, double> thread_cpu_start, thread_cpu_end;
  double setup_ms = 0;
  double sim_cpu_ms = 0, slam_cpu_ms = 0;  // sync mode: process CPU time of each half
  bool abort_run = false;

  // The consumer side for one frame; returns false to stop the run.
  auto consume = [&](FrameItem& item) -> bool {
    physics_ms += item.times.physics_ms;
    render_ms += item.times.render_ms;
    sensor_ms += item.times.sensor_ms;
    const int index = static_cast<int>(item.frame.index);
    std::vector<slam::FrameResult> results;
    for (auto& sink : sinks) results.push_back(sink->track(item.frame, log));
    const auto t0 = Clock::now();
    gt_file << geom::format_tum_line(item.gt) << "\n" << std::flush;
    gt.poses.push_back(item.gt);
    if (std::find(sheet_frames.begin(), sheet_frames.end(), index) != sheet_frames.end()) {
      char label[64];
      std::snprintf(label, sizeof label, "frame %d  t=%.2f s", index, geom::ns_to_seconds(item.frame.t_ns));
      report.thumbnails.push_back({item.frame.rgb.clone(), label});
    }
    if (opt.closed_loop) {
      if (index == 0) {
        // The robot knows where it starts: its start pose in the site frame
        // (here the ground truth of frame 0) and the camera's mounting.  It
        // stands still until SLAM initialises, so the SLAM world (the first
        // tracked camera frame) is the start camera pose.
        mount = measure_mount(item.base_gt, item.gt.T_w_c);
        T_site_slam = item.gt.T_w_c;
      }
      const slam::FrameResult& r = results.front();
      const double err = distance_to_polyline(Eigen::Vector2d(item.base_gt.x, item.base_gt.y), route);
      closed.t_s.push_back(geom::ns_to_seconds(item.frame.t_ns));
      closed.path_error_m.push_back(err);
      const bool ok = r.state == slam::TrackingState::kOk && r.T_w_c;
      if (!ok) ++closed.hold_frames;
      {
        std::lock_guard<std::mutex> lock(steering.mutex);
        steering.hold = !ok;
        if (ok) steering.pose = base_from_camera(T_site_slam * *r.T_w_c, mount);
      }
      if (r.state == slam::TrackingState::kLost && scenario.route.on_loss == scenes::OnLoss::kAbort) {
        report.status = RunStatus::kAborted;
        report.status_detail = "tracking lost at frame " + std::to_string(index) +
                               " and the scenario's route.on_loss is abort: " + r.tracking.failure;
        log.line("aborting: " + report.status_detail);
        abort_run = true;
      }
    }
    output_ms += ms_since(t0);
    if (opt.on_progress) opt.on_progress(sinks.front()->run.frames, static_cast<std::size_t>(n));
    return !abort_run;
  };

  log.line("pvbench run: scenario " + scenario.name + " (" + opt.scenario_file + "), seed " +
           std::to_string(scenario.seed) + ", " + std::to_string(n) + " frames, " +
           (compare ? "pe-slam and orb-slam2" : sinks.front()->run.mode) +
           (opt.closed_loop
                ? ", closed loop (on loss: " +
                      std::string(scenario.route.on_loss == scenes::OnLoss::kAbort ? "abort" : "wait") + ")"
                : ", open loop") +
           (opt.sync ? ", synchronous" : ", pipelined"));

  Clock::time_point loop_start;
  double loop_start_cpu_s = 0;
  if (opt.sync) {
    const auto t_setup = Clock::now();
    FrameProducer producer(scenario, backend, n, steering_ptr);
    setup_ms = ms_since(t_setup);
    report.renderer = producer.info().renderer;
    route = producer.info().route;
    log.line("renderer: " + report.renderer);
    loop_start = Clock::now();
    loop_start_cpu_s = process_cpu_s();
    while (!stopping()) {
      // Nothing else runs in sync mode, so the process CPU time of each half
      // (every thread: llvmpipe's and OpenCV's workers too) is its cost,
      // whatever else loads the machine.
      const double c0 = process_cpu_s();
      std::optional<FrameItem> item = producer.next();
      const double c1 = process_cpu_s();
      sim_cpu_ms += 1000.0 * (c1 - c0);
      if (!item) break;
      const bool go_on = consume(*item);
      slam_cpu_ms += 1000.0 * (process_cpu_s() - c1);
      if (!go_on) break;
    }
  } else {
    // Render thread: steering, physics, rendering -> rendered queue; sensor
    // thread: sensor model -> frame queue; this thread: tracking.  No stage
    // has to fit the whole simulation into one frame period.  In the closed
    // loop the sensor model stays on the render thread and the frame queue
    // holds one frame, so the steering pose is at most two frames old.
    const bool sensor_thread_on = !opt.closed_loop;
    ClosableQueue<RenderedItem> rendered_queue(2);
    ClosableQueue<FrameItem> queue(opt.closed_loop ? 1 : std::max<std::size_t>(opt.queue_capacity, 1));
    std::promise<SimInfo> ready;
    std::future<SimInfo> ready_future = ready.get_future();
    // Pacing: frame i is due at pace_start + i / fps (set before `ready`).
    Clock::time_point pace_start;
    const auto frame_due = [&](int i) {
      return pace_start + std::chrono::duration_cast<Clock::duration>(
                              std::chrono::duration<double>(static_cast<double>(i) / scenario.camera.fps));
    };
    std::exception_ptr producer_error, sensor_error;
    double producer_setup_ms = 0;
    std::thread producer_thread, sensor_thread;
    // The render thread keeps its GL context (and llvmpipe's threads) until
    // released, so that the per-thread CPU times can be read at the end.
    std::promise<void> release;
    std::shared_future<void> released = release.get_future().share();
    bool release_set = false;
    auto release_producer = [&] {
      if (!release_set) release.set_value();
      release_set = true;
    };
    // However the consumer leaves (end, stop, abort, exception), both
    // stages are released and joined.
    struct JoinGuard {
      ClosableQueue<RenderedItem>& rendered_queue;
      ClosableQueue<FrameItem>& queue;
      std::function<void()> release;
      std::thread& producer;
      std::thread& sensor;
      ~JoinGuard() {
        queue.close_and_clear();
        rendered_queue.close_and_clear();
        release();
        if (sensor.joinable()) sensor.join();
        if (producer.joinable()) producer.join();
      }
    } guard{rendered_queue, queue, release_producer, producer_thread, sensor_thread};
    producer_thread = std::thread([&] {
      set_thread_name("pvb-render");
      bool started = false;
      try {
        const auto t_setup = Clock::now();
        FrameProducer producer(scenario, backend, n, steering_ptr);
        producer_setup_ms = ms_since(t_setup);
        pace_start = Clock::now();
        ready.set_value(producer.info());
        started = true;
        for (int i = 0; !stopping(); ++i) {
          // A camera delivers frame i at i / fps: wait for it (a blocking
          // sleep of at most one period, so Ctrl-C is seen in time).
          if (opt.pace) std::this_thread::sleep_until(frame_due(i));
          bool pushed = false;
          if (sensor_thread_on) {
            std::optional<RenderedItem> item = producer.next_rendered();
            if (!item) break;
            const auto t_wait = Clock::now();
            pushed = rendered_queue.push(std::move(*item));
            producer_wait_ms += ms_since(t_wait);
          } else {
            std::optional<FrameItem> item = producer.next();
            if (!item) break;
            const auto t_wait = Clock::now();
            pushed = queue.push(std::move(*item));
            producer_wait_ms += ms_since(t_wait);
          }
          if (!pushed) break;
        }
        rendered_queue.close();
        if (!sensor_thread_on) queue.close();
        released.wait();
      } catch (...) {
        if (started)
          producer_error = std::current_exception();
        else
          ready.set_exception(std::current_exception());
        rendered_queue.close();
        queue.close();
      }
    });
    const SimInfo info = ready_future.get();  // rethrows a setup error (the guard joins)
    setup_ms = producer_setup_ms;
    report.renderer = info.renderer;
    route = info.route;
    log.line("renderer: " + report.renderer);
    const int mapping_nice = opt.mapping_nice.value_or(opt.pace ? 10 : 0);
    // Local and dense mapping workers, found by name; returns how many.
    const auto set_mapping_nice = [](int nice) {
      return set_thread_nice("pvb-mapping", nice) + set_thread_nice("pvb-dense", nice);
    };
    if (mapping_nice != 0) {
      // The workers started with the systems and have named themselves by
      // now (the renderer's start-up took far longer).
      const int changed = set_mapping_nice(mapping_nice);
      log.line("mapping workers: " + std::to_string(changed) + " at nice " + std::to_string(mapping_nice));
    }
    bool mapping_yields = mapping_nice != 0;  // the workers are at mapping_nice
    int mapping_priority_changes = 0;
    log.line(opt.pace ? "frames paced at " + fmt(scenario.camera.fps) + " Hz"
                      : "frames not paced (as fast as the stages go)");
    if (sensor_thread_on) {
      sensor_thread = std::thread([&] {
        set_thread_name("pvb-sensor");
        try {
          while (true) {
            auto t_wait = Clock::now();
            std::optional<RenderedItem> item = rendered_queue.pop();
            sensor_wait_ms += ms_since(t_wait);
            if (!item) break;
            FrameItem frame = apply_sensor(*info.sensor, std::move(*item));
            t_wait = Clock::now();
            const bool pushed = queue.push(std::move(frame));
            sensor_wait_ms += ms_since(t_wait);
            if (!pushed) break;
          }
        } catch (...) {
          sensor_error = std::current_exception();
        }
        rendered_queue.close_and_clear();  // the render thread stops too
        queue.close();
        released.wait();  // alive for the CPU table
      });
    }
    loop_start = pace_start;  // when frame 0 began (set before `ready`, so visible here)
    loop_start_cpu_s = process_cpu_s();
    thread_cpu_start = thread_cpu_ms();
    while (!stopping()) {
      const auto t_wait = Clock::now();
      std::optional<FrameItem> item = queue.pop();
      consumer_wait_ms += ms_since(t_wait);
      if (!item) break;
      const int index = static_cast<int>(item->frame.index);
      const bool go_on = consume(*item);
      // From when the frame was due (paced) or rendering began on the
      // simulated clock (not paced) to when it is tracked.
      const double latency_ms =
          std::chrono::duration<double, std::milli>(Clock::now() - frame_due(index)).count();
      frame_latency_ms += latency_ms;
      frame_latency_max_ms = std::max(frame_latency_max_ms, latency_ms);
      // A loop that cannot keep up with the camera gains nothing from
      // starving local mapping: mapping goes back to the common priority
      // while tracking is more than kBehindFrames periods late, and yields
      // again once it is within kCaughtUpFrames.
      // (Not in the first second: start-up makes frame 0 late anyway.)
      if (opt.pace && mapping_nice != 0 && index >= static_cast<int>(scenario.camera.fps)) {
        constexpr double kBehindFrames = 6, kCaughtUpFrames = 2;
        const double late_frames = latency_ms * scenario.camera.fps / 1000.0;
        const bool yield = mapping_yields ? late_frames < kBehindFrames : late_frames < kCaughtUpFrames;
        if (yield != mapping_yields) {
          mapping_yields = yield;
          const int nice = yield ? mapping_nice : 0;
          set_mapping_nice(nice);
          ++mapping_priority_changes;
          if (mapping_priority_changes <= 10)
            log.line("frame " + std::to_string(index) + ": tracked " + fmt(latency_ms) +
                     " ms after it was due; mapping workers at nice " + std::to_string(nice));
        }
      }
      if (!go_on) break;
    }
    if (mapping_priority_changes > 10)
      log.line("mapping priority changed " + std::to_string(mapping_priority_changes) + " times in all");
    queue.close_and_clear();
    rendered_queue.close_and_clear();
    thread_cpu_end = thread_cpu_ms();  // every stage still lives, waiting for release
    release_producer();
    if (sensor_thread.joinable()) sensor_thread.join();
    producer_thread.join();
    if (producer_error) std::rethrow_exception(producer_error);
    if (sensor_error) std::rethrow_exception(sensor_error);
  }
  for (auto& sink : sinks) sink->finish();  // waits for local mapping
  report.wall_s = ms_since(loop_start) / 1000.0;
  report.cpu_s = process_cpu_s() - loop_start_cpu_s;
  report.sim_s = static_cast<double>(sinks.front()->run.frames) / scenario.camera.fps;
  if (stopping() && !abort_run && report.status == RunStatus::kCompleted) {
    report.status = RunStatus::kInterrupted;
    report.status_detail = "interrupted after " + std::to_string(sinks.front()->run.frames) + " of " +
                           std::to_string(n) + " frames";
    log.line("interrupted: " + report.status_detail + "; writing the partial report");
  }
  gt_file.close();

  const auto t_eval = Clock::now();
  for (auto& sink : sinks) {
    if (!gt.empty())
      sink->evaluate(gt);
    else
      sink->run.eval_note = "no frames";
  }
  const double eval_ms = ms_since(t_eval);

  if (opt.closed_loop && !closed.path_error_m.empty()) {
    double sum2 = 0;
    for (double e : closed.path_error_m) {
      sum2 += e * e;
      closed.path_error_max_m = std::max(closed.path_error_max_m, e);
    }
    closed.path_error_rmse_m = std::sqrt(sum2 / static_cast<double>(closed.path_error_m.size()));
    report.closed_loop = closed;
  } else if (opt.closed_loop) {
    report.closed_loop = closed;
  }

  report.primary = sinks.front()->run;
  if (compare) report.baseline = sinks[1]->run;

  const std::size_t frames = report.primary.frames;
  const char* render_thread = opt.sync ? "main" : "render";
  const char* sensor_thread_name = opt.sync ? "main" : opt.closed_loop ? "render" : "sensor";
  report.profile = {{"setup", setup_ms, 1, render_thread},
                    {"physics", physics_ms, frames, render_thread},
                    {"render", render_ms, frames, render_thread},
                    {"sensor_model", sensor_ms, frames, sensor_thread_name}};
  for (const auto& sink : sinks) {
    const std::string suffix = sink.get() == sinks.front().get() ? "" : "_baseline";
    report.profile.push_back(
        {"tracking" + suffix, sink->tracking_ms, frames, opt.sync ? "main" : "consumer"});
    report.profile.push_back(
        {"orb_extraction" + suffix, sink->orb_ms, frames, opt.sync ? "main" : "consumer"});
    report.profile.push_back({"mapping" + suffix, sink->system->mapping_stats().busy_ms, sink->run.keyframes,
                              opt.sync ? "main" : "mapping"});
  }
  report.profile.push_back({"output", output_ms, frames, opt.sync ? "main" : "consumer"});
  if (!opt.sync) {
    report.profile.push_back({"producer_wait", producer_wait_ms, frames, "render"});
    if (!opt.closed_loop) report.profile.push_back({"sensor_wait", sensor_wait_ms, frames, "sensor"});
    report.profile.push_back({"consumer_wait", consumer_wait_ms, frames, "consumer"});
    // Paced: how long after the camera delivered it each frame was tracked
    // (a loop that keeps up stays within a few periods); mean per frame,
    // and the worst frame as its own entry.
    if (opt.pace) {
      report.profile.push_back({"frame_latency", frame_latency_ms, frames, "consumer"});
      report.profile.push_back({"frame_latency_max", frame_latency_max_ms, 1, "consumer"});
    }
    // CPU time of each thread (group) over the loop: pvb-render (physics,
    // GL calls), llvmpipe (its rasteriser workers), pvb-sensor, pvbench
    // (this thread: tracking), pvb-mapping, pvb-dense, and OpenCV's pool
    // under the name of the thread that started it.
    for (const auto& [name, end_ms] : thread_cpu_end) {
      const auto it = thread_cpu_start.find(name);
      const double ms = end_ms - (it == thread_cpu_start.end() ? 0.0 : it->second);
      report.profile.push_back({"cpu_thread_" + name, ms, frames, name});
    }
  }
  if (opt.sync) {
    report.profile.push_back({"cpu_simulation", sim_cpu_ms, frames, "main"});
    report.profile.push_back({"cpu_slam", slam_cpu_ms, frames, "main"});
  }
  report.profile.push_back({"eval", eval_ms, 1, "main"});

  char summary[512];
  const SlamRun& p = report.primary;
  std::snprintf(
      summary, sizeof summary,
      "%s: %zu frames, %zu lost, %zu keyframes, ATE rmse %s m, tracking median %.2f ms, realtime factor "
      "%.2f (%.2f s simulated in %.2f s wall, %.2f s CPU)",
      to_string(report.status), p.frames, p.lost_frames, p.keyframes,
      p.eval ? fmt(p.eval->ate.rmse).c_str() : "n/a",
      percentile(
          [&] {
            std::vector<double> v;
            for (const auto& f : p.per_frame) v.push_back(f.tracking_ms);
            return v;
          }(),
          0.5),
      realtime_factor(report.sim_s, report.wall_s), report.sim_s, report.wall_s, report.cpu_s);
  log.line(summary);
  for (const SlamRun* r : {&report.primary, report.baseline ? &*report.baseline : nullptr}) {
    if (!r || (!r->refined_eval && r->loop_closing_json.empty())) continue;
    log.line(r->mode + ": refined trajectory ATE rmse " + (r->refined_eval ? fmt(r->refined_eval->ate.rmse) : "n/a") +
             " m, " + std::to_string(r->loops_closed) + " loops closed");
  }
  if (report.closed_loop)
    log.line("closed loop: path error rmse " + fmt(report.closed_loop->path_error_rmse_m) + " m, max " +
             fmt(report.closed_loop->path_error_max_m) + " m, held " +
             std::to_string(report.closed_loop->hold_frames) + " frames");
  const std::string table = comparison_table(report);
  if (!table.empty()) {
    log.line("PE-SLAM against the ORB-SLAM2 baseline on the same frames:");
    for (std::size_t a = 0, b; a < table.size(); a = b + 1) {
      b = table.find('\n', a);
      if (b == std::string::npos) b = table.size();
      log.line(table.substr(a, b - a));
    }
  }

  const auto t_report = Clock::now();
  report.log_lines = log.lines();
  const std::vector<std::string> figures = write_report(report, opt.out_dir);
  report.profile.push_back({"report", ms_since(t_report), 1, "main"});
  // Again, so the report's own time is in it.
  log.line("report written to " + opt.out_dir + "/index.html");
  report.log_lines = log.lines();
  write_file(opt.out_dir + "/metrics.json", metrics_json(report));
  write_file(opt.out_dir + "/index.html", index_html(report, figures));
  return report;
}

}  // namespace pvb::run
