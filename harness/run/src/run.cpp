#include "pvb/run/run.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <optional>

#include "closed_loop.hpp"
#include "frame_pipeline.hpp"
#include "landmark_classes.hpp"
#include "map_scoring.hpp"
#include "motion_report.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/io_paths.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/slam_mode.hpp"
#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/run/blind.hpp"
#include "pvb/run/motion_truth.hpp"
#include "pvb/run/output_names.hpp"
#include "pvb/report/world_json.hpp"
#include "pvb/scenes/route.hpp"
#include "pvb/sim/motion_sensors.hpp"
#include "pvb/slam/core/settings.hpp"
#include "run_log.hpp"
#include "system_sink.hpp"
#include "pvb/run/sensor_setup.hpp"

namespace pvb::run {
namespace {

// --- Building the run: the scenario, the report folder, the SLAM settings ---

scenes::Scenario load_run_scenario(const RunOptions& opt) {
  scenes::Scenario scenario = scenes::load_scenario(opt.scenario_file);
  if (opt.seed) scenario.seed = *opt.seed;
  if (opt.start_m) {
    const std::string expected = start_m_expectation(scenario, *opt.start_m);
    if (!expected.empty()) throw ConfigError("command line", "--start-m", expected, format_g(*opt.start_m));
    scenario.route.start_m = *opt.start_m;
  }
  return scenario;
}

/// SLAM settings from the scenario's camera (kept in the report as
/// camera.yaml, written once the folder is prepared).
struct RunSettings {
  std::string text;  ///< camera.yaml
  slam::Settings slam;
};

RunSettings slam_settings(const scenes::Scenario& scenario, const std::string& out_dir) {
  RunSettings s;
  s.text = dataset::orbslam_settings_text(orbslam_settings_for(scenario));
  s.slam = slam::read_settings_text(s.text, out_dir + "/camera.yaml");
  return s;
}

/// What the run reads and writes, refused before any work when an output
/// would land on an input (the scenario, its bases, the map).
void check_run_paths(const RunOptions& opt, const scenes::Scenario& scenario) {
  IoPlan plan;
  plan.input("the --scenario file", opt.scenario_file)
      .inputs("a base of the --scenario file", scenario.base_files)
      .input("the --map file", opt.map.load_path)
      .output_folder("--out", opt.out_dir, run_output_names())
      .output_file("--save-map", opt.map.save_path);
  plan.check();
  check_output_folder(opt.out_dir, opt.overwrite);
  reserve_output(opt.map.save_path, "--save-map");
}

RunReport new_report(const scenes::Scenario& scenario, const RunOptions& opt) {
  RunReport report;
  report.scenario = scenario.name;
  report.scenario_file = opt.scenario_file;
  report.seed = scenario.seed;
  report.world = world_json(scenario);
  report.sync = opt.sync;
  report.fps = scenario.camera.fps;
  if (const auto cover = scenes::camera_cover_frames(scenario))
    report.camera_covered_frames = std::make_pair(cover->begin, cover->end - 1);
  return report;
}

/// ", sensors S" (--sensors) or ", sensors B against A" (--compare-sensors); "" otherwise.
std::string sensors_part(const RunOptions& opt) {
  if (opt.compare_sensors)
    return std::string(", sensors ") + sensor::to_string(opt.compare_sensors->second) + " against " +
           sensor::to_string(opt.compare_sensors->first);
  return opt.sensors ? std::string(", sensors ") + sensor::to_string(*opt.sensors) : std::string();
}

std::string start_line(const RunOptions& opt, const scenes::Scenario& scenario, int frames,
                       const std::string& mode) {
  const bool compare = opt.mode == SlamMode::kCompare;
  return "pvbench run: scenario " + scenario.name + " (" + opt.scenario_file + "), seed " +
         std::to_string(scenario.seed) + ", " + std::to_string(frames) + " frames, " +
         (compare ? std::string(eval::kPeSlamLabel) + " and the " + eval::kBaselineLabel
                  : eval::mode_label(mode)) +
         (opt.closed_loop
              ? ", closed loop (on loss: " +
                    std::string(scenario.route.on_loss == scenes::OnLoss::kAbort ? "abort" : "wait") + ")"
              : ", open loop") +
         (opt.sync ? ", synchronous" : ", pipelined") + sensors_part(opt);
}

// --- The consumer side of each frame ---

/// Ground truth of every frame: groundtruth.txt (flushed per frame) and the
/// trajectory the systems are evaluated against; beside it the motion
/// sensors' files and their truth (docs/sensors.md).
class GroundTruthSink {
 public:
  GroundTruthSink(const std::string& dir, const scenes::Scenario& scenario)
      : dir_(dir),
        scenario_(scenario),
        file_(dir + "/groundtruth.txt"),
        motion_(dir, robot_calibration_for(scenario)),
        motion_truth_(dir),
        motion_report_(scenes::T_base_imu(scenario), sim::nominal_description(scenario)) {
    file_.append(
        "# timestamp tx ty tz qx qy qz qw (T_w_c: camera optical frame in the site frame, ground truth)\n");
    trajectory_.source = dir + "/groundtruth.txt";
  }
  void started(const SimInfo& info) {
    write_robot_truth(dir_, scenario_, info.kinematics);
    const sensor::DriveDescription described = sim::nominal_description(scenario_);
    wheels_true_ = run::wheels_true(info.kinematics.wheel_radius_m, info.kinematics.track_m, described.wheel_radius_m,
                                    described.track_m, scenario_.robot.radius_difference);
  }
  /// The simulated robot's effective radius and track over its description.
  const std::optional<slam::WheelCalibration>& wheels_true() const { return wheels_true_; }
  void add(const FrameItem& item) {
    file_.append(geom::format_tum_line(item.gt) + "\n");
    trajectory_.poses.push_back(item.gt);
    motion_.write(item.frame);
    motion_truth_.write(item.imu_truth, item.wheel_truth);
    motion_report_.add(item);
    add_bias_truth(item.imu_truth);
  }
  /// The biases in the first and the last IMU reading of every frame
  /// (keep_frame_ends; imu0/truth.csv has them all).
  const std::vector<BiasTruth>& bias_truth() const { return bias_truth_; }
  MotionSensorsReport motion_report() const { return motion_report_.report(); }
  void close() { file_.close(); }
  const eval::Trajectory& trajectory() const { return trajectory_; }

 private:
  void add_bias_truth(const std::vector<sim::ImuTruth>& readings) {
    std::vector<BiasTruth> frame;
    for (const sim::ImuTruth& t : readings) frame.push_back({t.t_ns, t.gyro_bias, t.accel_bias});
    keep_frame_ends(frame, &bias_truth_);
  }

  std::string dir_;
  const scenes::Scenario& scenario_;
  OutputFile file_;
  dataset::MotionFilesWriter motion_;
  MotionTruthWriter motion_truth_;
  MotionReportBuilder motion_report_;
  eval::Trajectory trajectory_;
  std::vector<BiasTruth> bias_truth_;
  std::optional<slam::WheelCalibration> wheels_true_;
};

/// Stage times the consumer adds up: the producer's, from each frame, and
/// its own bookkeeping after tracking.
struct FrameCosts {
  double physics_ms = 0, render_ms = 0, sensor_ms = 0, output_ms = 0;
};

/// Every SLAM system tracks the frame; the ground truth and the
/// contact-sheet frames are kept; in the closed loop the SLAM pose steers,
/// and a loss aborts the run when the scenario says so.
class RunConsumer : public FrameConsumer {
 public:
  RunConsumer(const RunOptions& opt, const scenes::Scenario& scenario, int frames, SystemSinks& sinks,
              GroundTruthSink& gt, ClosedLoop* closed_loop, RunReport& report, RunLog& log)
      : opt_(opt),
        on_loss_(scenario.route.on_loss),
        frames_(frames),
        sheet_frames_(plot::spread_indices(frames, 12)),
        sinks_(sinks),
        gt_(gt),
        closed_loop_(closed_loop),
        report_(report),
        log_(log) {}

  void started(const SimInfo& info) override {
    report_.renderer = info.renderer;
    gt_.started(info);
    if (closed_loop_) closed_loop_->set_route(info.route);
  }

  bool consume(FrameItem& item) override {
    costs_.physics_ms += item.times.physics_ms;
    costs_.render_ms += item.times.render_ms;
    costs_.sensor_ms += item.times.sensor_ms;
    std::vector<slam::FrameResult> results;
    dataset::round_as_written(&item.frame);  // as a replay of the recording reads them
    for (auto& sink : sinks_) {
      try {
        results.push_back(sink->track(item.frame, log_));
      } catch (const IoError& e) {  // a worker's full disk, passed on by the next keyframe's hand-over
        sink->failure = e.what();
        aborted_ = true;
        return false;
      }
    }
    const auto t0 = Clock::now();
    gt_.add(item);
    keep_thumbnail(item);
    if (closed_loop_) {
      closed_loop_->update(item, results.front());
      abort_on_loss(static_cast<int>(item.frame.index), results.front());
    }
    costs_.output_ms += ms_since(t0);
    if (opt_.on_progress) opt_.on_progress(sinks_.front()->run.frames, static_cast<std::size_t>(frames_));
    return !aborted_;
  }

  bool aborted() const { return aborted_; }
  const FrameCosts& costs() const { return costs_; }

 private:
  void keep_thumbnail(const FrameItem& item) {
    const int index = static_cast<int>(item.frame.index);
    if (std::find(sheet_frames_.begin(), sheet_frames_.end(), index) == sheet_frames_.end()) return;
    char label[64];
    std::snprintf(label, sizeof label, "frame %d  t=%.2f s", index, geom::ns_to_seconds(item.frame.t_ns));
    report_.thumbnails.push_back({item.frame.rgb.clone(), label});
  }

  /// Closed loop: tracking lost and the scenario's route.on_loss is abort.
  void abort_on_loss(int index, const slam::FrameResult& r) {
    if (r.state != slam::TrackingState::kLost || on_loss_ != scenes::OnLoss::kAbort) return;
    report_.status = RunStatus::kAborted;
    report_.status_detail = "tracking lost at frame " + std::to_string(index) +
                            " and the scenario's route.on_loss is abort: " + r.tracking.failure;
    log_.line("aborting: " + report_.status_detail);
    aborted_ = true;
  }

  const RunOptions& opt_;
  const scenes::OnLoss on_loss_;
  const int frames_;
  const std::vector<int> sheet_frames_;
  SystemSinks& sinks_;
  GroundTruthSink& gt_;
  ClosedLoop* closed_loop_;
  RunReport& report_;
  RunLog& log_;
  FrameCosts costs_;
  bool aborted_ = false;
};

// --- After the loop: results and metrics ---

/// Local mapping finished; the loop's wall, CPU and simulated time; an
/// interruption noted in the status.
void finish_loop(const RunOptions& opt, const LoopTimes& loop, bool aborted, int frames, SystemSinks& sinks,
                 RunReport& report, RunLog& log) {
  for (auto& sink : sinks) {
    sink->end_losses(log);
    sink->finish();  // waits for local mapping
  }
  report.wall_s = ms_since(loop.start) / 1000.0;
  report.cpu_s = process_cpu_s() - loop.start_cpu_s;
  report.sim_s = static_cast<double>(sinks.front()->run.frames) / report.fps;
  const bool stopped = opt.stop && opt.stop->load();
  if (stopped && !aborted && report.status == RunStatus::kCompleted) {
    report.status = RunStatus::kInterrupted;
    report.status_detail = "interrupted after " + std::to_string(sinks.front()->run.frames) + " of " +
                           std::to_string(frames) + " frames";
    log.line("interrupted: " + report.status_detail + "; writing the partial report");
  }
}

/// A run whose system stopped working (a worker's IoError: the disk under
/// its spill files filled) failed; what it tracked until then is reported.
void fail_on_system_error(const SystemSinks& sinks, RunReport& report, RunLog& log) {
  for (const auto& sink : sinks) {
    if (sink->failure.empty()) continue;
    report.status = RunStatus::kFailed;
    report.status_detail = sink->run.mode + " stopped after " + std::to_string(sink->run.frames) +
                           " frames: " + sink->failure;
    log.line("failed: " + report.status_detail);
    return;
  }
}

/// A run whose primary system never initialised failed: it tracked nothing,
/// and a map it was asked to save does not exist.
void fail_if_never_initialised(const SlamRun& p, RunReport& report, RunLog& log) {
  if (report.status != RunStatus::kCompleted || p.frames == 0 || p.not_initialized_frames < p.frames) return;
  report.status = RunStatus::kFailed;
  report.status_detail = "tracking never initialised in " + std::to_string(p.frames) + " frames (" +
                         (p.init_failure.empty() ? std::string("no reason given") : p.init_failure) + ")";
  log.line("failed: " + report.status_detail);
}

/// A stop asked for after the last frame (while the map was saved or the
/// maps scored): the work in hand was finished, and the run still ends as
/// interrupted.
void note_late_stop(const RunOptions& opt, RunReport& report, RunLog& log) {
  if (!opt.stop || !opt.stop->load() || report.status != RunStatus::kCompleted) return;
  report.status = RunStatus::kInterrupted;
  report.status_detail = "interrupted after the last frame, while the run was being finished";
  log.line("interrupted: " + report.status_detail + "; writing the report");
}

/// Evaluates every system against the ground truth; returns the time it took (ms).
double evaluate_systems(SystemSinks& sinks, const eval::Trajectory& gt) {
  const auto t_eval = Clock::now();
  for (auto& sink : sinks) {
    if (!gt.empty())
      sink->evaluate(gt);
    else
      sink->run.eval_note = "no frames";
  }
  return ms_since(t_eval);
}

/// The blind stretch of every system, in a scenario whose camera is
/// covered for a while; its summary in the log.
void evaluate_blind_stretch(const scenes::Scenario& scenario, SystemSinks& sinks, const eval::Trajectory& gt,
                            RunLog& log) {
  const std::optional<scenes::CoverFrames> cover = scenes::camera_cover_frames(scenario);
  if (!cover || sinks.front()->run.frames <= static_cast<std::size_t>(cover->begin)) return;
  for (auto& sink : sinks) {
    SlamRun& run = sink->run;
    run.blind = blind_stretch(*cover, scenario.camera.fps, run.per_frame, sink->est, gt, run.eval);
    log.line(run.label + ": " + blind_summary(*run.blind));
  }
}

/// The dense maps scored against the true surface, unless the options say
/// not to; returns the time it took (ms).
double score_or_skip_maps(const RunOptions& opt, const scenes::Scenario& scenario, sim::GlBackend backend,
                          const eval::Trajectory& gt, SystemSinks& sinks, RunLog& log) {
  if (opt.map_eval && !gt.empty()) return score_dense_maps(scenario, backend, gt, sinks, log);
  for (auto& sink : sinks) {
    if (sink->run.dense_map) sink->run.dense_map->note = opt.map_eval ? "no frames" : "not scored (--no-map-eval)";
  }
  return 0.0;
}

/// Pipelined: the queue waits, the latency from due to tracked, and the CPU
/// time of each thread (group) over the loop: pvb-render (physics, GL
/// calls), llvmpipe (its rasteriser workers), pvb-sensor, pvbench (this
/// thread: tracking), pvb-mapping, pvb-dense, and OpenCV's pool under the
/// name of the thread that started it.
void add_pipeline_entries(const RunOptions& opt, const LoopTimes& loop, std::size_t frames,
                          std::vector<StageTime>* profile) {
  profile->push_back({"producer_wait", loop.producer_wait_ms, frames, "render"});
  if (!opt.closed_loop) profile->push_back({"sensor_wait", loop.sensor_wait_ms, frames, "sensor"});
  profile->push_back({"consumer_wait", loop.consumer_wait_ms, frames, "consumer"});
  // Paced: how long after the camera delivered it each frame was tracked
  // (a loop that keeps up stays within a few periods); mean per frame,
  // and the worst frame as its own entry.
  if (opt.pace) {
    profile->push_back({"frame_latency", loop.frame_latency_ms, frames, "consumer"});
    profile->push_back({"frame_latency_max", loop.frame_latency_max_ms, 1, "consumer"});
  }
  for (const auto& [name, end_ms] : loop.thread_cpu_end) {
    const auto it = loop.thread_cpu_start.find(name);
    const double ms = end_ms - (it == loop.thread_cpu_start.end() ? 0.0 : it->second);
    profile->push_back({"cpu_thread_" + name, ms, frames, name});
  }
}

/// The profile entries of metrics.json and index.html ("Where the time went").
std::vector<StageTime> profile_entries(const RunOptions& opt, const LoopTimes& loop, const FrameCosts& costs,
                                       const SystemSinks& sinks, std::size_t frames, double eval_ms) {
  const char* render_thread = opt.sync ? "main" : "render";
  const char* sensor_thread = opt.sync ? "main" : opt.closed_loop ? "render" : "sensor";
  const char* consumer_thread = opt.sync ? "main" : "consumer";
  std::vector<StageTime> profile = {{"setup", loop.setup_ms, 1, render_thread},
                                    {"physics", costs.physics_ms, frames, render_thread},
                                    {"render", costs.render_ms, frames, render_thread},
                                    {"sensor_model", costs.sensor_ms, frames, sensor_thread}};
  for (const auto& sink : sinks) {
    const std::string suffix = sink == sinks.front() ? "" : "_baseline";
    profile.push_back({"tracking" + suffix, sink->tracking_ms, frames, consumer_thread});
    profile.push_back({"orb_extraction" + suffix, sink->orb_ms, frames, consumer_thread});
    profile.push_back({"mapping" + suffix, sink->system->mapping_stats().busy_ms, sink->run.keyframes,
                       opt.sync ? "main" : "mapping"});
  }
  profile.push_back({"output", costs.output_ms, frames, consumer_thread});
  if (!opt.sync) add_pipeline_entries(opt, loop, frames, &profile);
  if (opt.sync) {
    profile.push_back({"cpu_simulation", loop.sim_cpu_ms, frames, "main"});
    profile.push_back({"cpu_slam", loop.slam_cpu_ms, frames, "main"});
  }
  profile.push_back({"eval", eval_ms, 1, "main"});
  return profile;
}

/// The one-line summary of the primary run.
std::string summary_line(const RunReport& report) {
  const SlamRun& p = report.primary;
  std::vector<double> tracking_ms;
  for (const auto& f : p.per_frame) tracking_ms.push_back(f.tracking_ms);
  char summary[512];
  std::snprintf(
      summary, sizeof summary,
      "%s: %zu frames, %zu lost, %zu keyframes, ATE rmse %s m, tracking median %.2f ms, realtime factor "
      "%.2f (%.2f s simulated in %.2f s wall, %.2f s CPU)",
      to_string(report.status), p.frames, p.lost_frames, p.keyframes,
      p.eval ? format_g(p.eval->ate.rmse).c_str() : "n/a", percentile(tracking_ms, 0.5),
      realtime_factor(report.sim_s, report.wall_s), report.sim_s, report.wall_s, report.cpu_s);
  return summary;
}

/// The summary, the refined trajectories, the closed loop and the comparison table.
void log_summary(const RunReport& report, RunLog& log) {
  log.line(summary_line(report));
  if (report.primary.map)
    for (const std::string& line : map_log_lines(*report.primary.map)) log.line(line);
  for (const SlamRun* r : {&report.primary, report.baseline ? &*report.baseline : nullptr}) {
    if (!r || (!r->refined_eval && r->loop_closing_json.empty())) continue;
    log.line(r->label + ": refined trajectory ATE rmse " +
             (r->refined_eval ? format_g(r->refined_eval->ate.rmse) : "n/a") + " m, " +
             std::to_string(r->loops_closed) + " loops closed");
  }
  if (report.closed_loop)
    log.line("closed loop: path error rmse " + format_g(report.closed_loop->path_error_rmse_m) + " m, max " +
             format_g(report.closed_loop->path_error_max_m) + " m, held " +
             std::to_string(report.closed_loop->hold_frames) + " frames");
  const std::string table = comparison_table(report);
  if (table.empty()) return;
  log.line(comparison_heading(report) + " on the same frames:");
  for (std::size_t a = 0, b; a < table.size(); a = b + 1) {
    b = table.find('\n', a);
    if (b == std::string::npos) b = table.size();
    log.line(table.substr(a, b - a));
  }
}

// --- The report ---

/// The report folder (figures, contact sheet, metrics.json, index.html);
/// metrics.json and index.html are written again at the end so that the
/// report's own time and last log line are in them.
void write_run_report(RunReport& report, RunLog& log, const std::string& out_dir) {
  const auto t_report = Clock::now();
  report.log_lines = log.lines();
  const std::vector<std::string> figures = write_report(report, out_dir);
  report.profile.push_back({"report", ms_since(t_report), 1, "main"});
  log.line("report written to " + out_dir + "/index.html");
  report.log_lines = log.lines();
  write_file(out_dir + "/metrics.json", metrics_json(report));
  write_file(out_dir + "/index.html", index_html(report, figures));
}

}  // namespace

dataset::OrbSlamSettings orbslam_settings_for(const scenes::Scenario& s) {
  dataset::OrbSlamSettings o;
  o.K = {s.camera.fx, s.camera.fy, s.camera.cx(), s.camera.cy(), s.camera.width, s.camera.height};
  o.fps = s.camera.fps;
  o.bf = s.camera.depth_baseline_m() * s.camera.fx;
  // ThDepth is in baselines: points beyond depth_range max are "far".
  o.th_depth = s.camera.depth_range_m.y() / s.camera.depth_baseline_m();
  o.rgb_order = 1;
  o.n_features = s.slam.orb_features;
  o.kf_min_tracked_close = s.slam.keyframe_min_tracked_close;
  o.kf_ref_overlap = s.slam.keyframe_ref_overlap;
  o.sensors = s.slam.sensors;
  o.robot = robot_calibration_for(s);
  return o;
}

dataset::RobotCalibration robot_calibration_for(const scenes::Scenario& s) {
  dataset::RobotCalibration c;
  c.imu = scenes::kalibr_noise(s.imu);
  c.imu_rate_hz = scenes::imu_rate_hz(s);
  c.drive = sim::nominal_description(s);
  c.encoder_rate_hz = scenes::wheel_rate_hz(s);
  c.T_b_c = scenes::T_base_camera(s);
  c.T_b_i = scenes::T_base_imu(s);
  return c;
}

std::string start_m_expectation(const scenes::Scenario& scenario, double start_m,
                                const std::string& scenario_file) {
  const double length = scenes::polyline_length(scenes::route_polyline(scenario));
  if (start_m >= 0 && start_m < length - 1.0) return "";
  return "a distance from 0 to 1 m before the route's end (" +
         (scenario_file.empty() ? std::string() : "the route of " + scenario_file + " is ") +
         format_fixed(length, 2) + " m long)";
}

RunReport run_scenario(const RunOptions& opt) {
  // Build: the scenario, the SLAM systems (a saved map loaded and checked),
  // and only then the report folder and its log.
  const sim::GlBackend backend = sim::parse_gl_backend(opt.gl);
  const scenes::Scenario scenario = load_run_scenario(opt);
  const int n = scenes::frame_count(scenario, opt.max_frames);
  opt.map.check();
  check_run_paths(opt, scenario);
  RunSettings settings = slam_settings(scenario, opt.out_dir);
  if (opt.compare_sensors && opt.mode == SlamMode::kCompare)
    throw ConfigError("pvbench run", "--compare/--compare-sensors", "at most one of them");
  if (opt.sensors) apply_sensor_setup(&settings.slam, *opt.sensors);
  MapOptions map = opt.map;
  map.station = station_of(scenario);
  SystemSinks sinks = make_systems(settings.slam, opt, static_cast<std::uint32_t>(scenario.seed), map);
  prepare_output_folder(opt.out_dir, opt.overwrite, "run");
  write_file(opt.out_dir + "/camera.yaml", settings.text);
  RunLog log(opt.out_dir + "/run.log", opt.on_log);
  for (const std::string& w : settings.slam.warnings) log.line("warning: " + w);
  for (auto& sink : sinks) sink->open_outputs();
  RunReport report = new_report(scenario, opt);
  GroundTruthSink gt(opt.out_dir, scenario);
  std::optional<ClosedLoop> closed_loop;
  if (opt.closed_loop) closed_loop.emplace();
  RunConsumer consumer(opt, scenario, n, sinks, gt, closed_loop ? &*closed_loop : nullptr, report, log);
  log.line(start_line(opt, scenario, n, sinks.front()->run.mode));

  // The frames: sync, or pipelined and paced.
  const LoopTimes loop =
      run_frames(scenario, backend, n, closed_loop ? closed_loop->steering() : nullptr, opt, consumer, log);

  // Results and metrics.
  finish_loop(opt, loop, consumer.aborted(), n, sinks, report, log);
  fail_on_system_error(sinks, report, log);
  fail_if_never_initialised(sinks.front()->run, report, log);
  gt.close();
  const double eval_ms = evaluate_systems(sinks, gt.trajectory());
  for (auto& sink : sinks) sink->evaluate_inertial(gt.bias_truth(), gt.wheels_true());
  evaluate_blind_stretch(scenario, sinks, gt.trajectory(), log);
  if (report.status == RunStatus::kFailed && !opt.map.save_path.empty())
    log.line("the map is not saved: the run failed (" + opt.map.save_path + " is as it was)");
  else if (!opt.map.save_path.empty())
    log.line("saving the map to " + opt.map.save_path);
  if (report.status != RunStatus::kFailed)
    for (auto& sink : sinks) sink->finish_map(gt.trajectory(), scenario.name, opt.scenario_file);
  if (SlamRun& p = sinks.front()->run; p.map && p.map->localisation)
    classify_matched_landmarks(*sinks.front()->system, backend, &*p.map);
  const double map_ms = score_or_skip_maps(opt, scenario, backend, gt.trajectory(), sinks, log);
  if (closed_loop) report.closed_loop = closed_loop->metrics();
  report.motion = gt.motion_report();
  report.primary = sinks.front()->run;
  if (sinks.size() > 1) report.baseline = sinks[1]->run;
  report.profile = profile_entries(opt, loop, consumer.costs(), sinks, report.primary.frames, eval_ms);
  report.profile.push_back({"map_eval", map_ms, 1, "main"});
  note_late_stop(opt, report, log);
  log_summary(report, log);

  write_run_report(report, log, opt.out_dir);
  return report;
}

}  // namespace pvb::run
