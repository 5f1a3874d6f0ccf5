// pvbench camera: PE-SLAM live on an OpenNI2 RGB-D camera, an .oni
// recording or the simulator's virtual OpenNI2 device (sim://scenario.yaml).
//
// Outputs (folder --out): camera.yaml (the settings used), CameraTrajectory.txt
// (flushed frame by frame), KeyFrameTrajectory.txt, map.ply (the sparse map
// points), stats.json, and for sim:// sources groundtruth.txt and the ATE.
//
// Stages of a run: inputs (scenario, .oni check, where --record may write),
// settings, the tracking loop (outputs flushed as they grow), the final
// files, and the checks that fail the run after everything was written
// (stream error, recording short of frames, SLAM never initialised).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "camera_inputs.hpp"
#include "command.hpp"
#include "count_option.hpp"
#include "io_plan.hpp"
#include "map_options.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/progress.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/fakenect_dump.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/openni/oni_file.hpp"
#include "pvb/openni/openni_source.hpp"
#include "pvb/openni/record_target.hpp"
#include "pvb/openni/sim_uri.hpp"
#include "pvb/run/motion_truth.hpp"
#include "pvb/run/output_names.hpp"
#include "pvb/run/run.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"
#include "sensor_options.hpp"
#include "stop_signals.hpp"
#include "trajectory_output.hpp"

namespace pvb::cli {
namespace {


using Clock = std::chrono::steady_clock;

void write_map_ply(const std::string& path, const std::vector<Eigen::Vector3d>& points) {
  std::ostringstream s;
  s << "ply\nformat ascii 1.0\ncomment PE-SLAM sparse map, world frame, metres\nelement vertex "
    << points.size() << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const Eigen::Vector3d& p : points)
    s << format_g(p.x()) << " " << format_g(p.y()) << " " << format_g(p.z()) << "\n";
  write_file(path, s.str());
}

// ---- tracking --------------------------------------------------------------

/// The files that grow frame by frame.  Ground truth of a sim:// device: the
/// harness re-runs the scenario's physics (deterministic, no rendering)
/// beside the device, so nothing but images travels through OpenNI2
/// (docs/openni.md).
struct LiveOutputs {
  OutputFile cam_traj;
  std::unique_ptr<sim::Simulator> gt_sim;
  OutputFile gt_file;
  std::unique_ptr<dataset::MotionFilesWriter> motion;  ///< a sim:// device's IMU and encoders
  std::unique_ptr<run::MotionTruthWriter> motion_truth;
  OutputFile accel_txt;  ///< a Kinect's accelerometer (freenect://), as TUM records it
  std::string dump_gt;  ///< a fakenect dump's groundtruth.txt, copied at the end
  bool has_gt() const { return gt_sim || !dump_gt.empty(); }
};

LiveOutputs open_live_outputs(const camera::CameraArgs& a, const std::optional<scenes::Scenario>& scenario) {
  const std::string& out = a.out;
  LiveOutputs o;
  if (const std::string dump = camera::fakenect_dump_dir(a); !dump.empty() && camera::readable(dump + "/groundtruth.txt"))
    o.dump_gt = dump + "/groundtruth.txt";
  o.cam_traj = OutputFile(out + "/CameraTrajectory.txt");
  o.cam_traj.append("# timestamp tx ty tz qx qy qz qw (T_w_c)\n");
  if (camera::is_freenect_uri(a)) {
    o.accel_txt = OutputFile(out + "/accelerometer.txt");
    o.accel_txt.append(
        "# accelerometer data\n# file: 'pvbench camera' (libfreenect's freenect_get_mks_accel, the "
        "Kinect's axes)\n# timestamp ax ay az\n");
  }
  if (scenario) {
    o.gt_sim = std::make_unique<sim::Simulator>(*scenario, sim::SceneDetail::kGeometry);  // physics only
    o.gt_file = OutputFile(out + "/groundtruth.txt");
    o.gt_file.append("# timestamp tx ty tz qx qy qz qw (T_w_c, simulator ground truth)\n");
    o.motion = std::make_unique<dataset::MotionFilesWriter>(out, run::robot_calibration_for(*scenario));
    o.motion_truth = std::make_unique<run::MotionTruthWriter>(out);
    run::write_robot_truth(out, *scenario, o.gt_sim->kinematics());
  }
  return o;
}

struct TrackCounts {
  std::size_t frames = 0;
  std::size_t lost = 0;
  std::size_t not_initialized = 0;
  double elapsed_s = 0;
  std::optional<IoError> stream_error;  ///< unplugged camera or broken file
  std::string init_failure;             ///< the core's reason the last frame did not initialise
  /// Per frame: its stream time stamp, and the run's clock (s) when the
  /// source handed it over and when its pose was written.
  std::vector<std::int64_t> t_ns;
  std::vector<double> arrived_s, posed_s;
};

/// Latency from a frame's time stamp to its pose, in ms: the stream's clock
/// is put on the run's by the smallest (arrival - time stamp) of the run,
/// so the fastest-delivered frame counts as arriving at its time stamp and
/// the figure is what the camera path and SLAM add on top of that frame's
/// delivery (queueing included).  With `from_arrival`, from the frame's
/// hand-over instead: the processing alone.  Median and 95th percentile.
std::pair<double, double> latency_ms(const TrackCounts& c, bool from_arrival) {
  if (c.t_ns.empty()) return {0, 0};
  double offset_s = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < c.t_ns.size(); ++i)
    offset_s = std::min(offset_s, c.arrived_s[i] - geom::ns_to_seconds(c.t_ns[i]));
  std::vector<double> ms(c.t_ns.size());
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const double start_s = from_arrival ? c.arrived_s[i] : geom::ns_to_seconds(c.t_ns[i]) + offset_s;
    ms[i] = 1000.0 * (c.posed_s[i] - start_s);
  }
  auto at = [&ms](double q) {
    const auto k = static_cast<std::size_t>(q * static_cast<double>(ms.size() - 1) + 0.5);
    std::nth_element(ms.begin(), ms.begin() + static_cast<long>(k), ms.end());
    return ms[k];
  };
  const double median = at(0.5);
  return {median, at(0.95)};
}

/// Tracks one frame and appends its poses (ground truth first).
slam::TrackingState track_frame(const sensor::RgbdFrame& frame, const camera::CameraSettings& settings,
                                slam::System& system, LiveOutputs& live, TrackCounts& counts) {
  const geom::PinholeIntrinsics& K = settings.slam.K;
  if (frame.rgb.cols != K.width || frame.rgb.rows != K.height)
    throw ConfigError(settings.file, "Camera.width/height",
                      std::to_string(frame.rgb.cols) + "x" + std::to_string(frame.rgb.rows) + " (the stream)",
                      std::to_string(K.width) + "x" + std::to_string(K.height));
  sensor::RgbdFrame tracked = frame;  // the images are shared, not copied
  if (live.gt_sim) {
    while (live.gt_sim->frame_index() < static_cast<int>(frame.index)) live.gt_sim->advance();
    live.gt_file.append(geom::format_tum_line({frame.t_ns, live.gt_sim->T_w_c()}) + "\n");
    const sim::MotionBatch b = live.gt_sim->take_motion();  // the readings up to this frame
    live.motion->write(b.imu, b.ticks);
    live.motion_truth->write(b.imu_truth, b.wheel_truth);
    if (settings.slam.motion.setup != sensor::SensorSetup::kCamera) {  // the device's robot's sensors
      tracked.imu = b.imu;
      tracked.wheel_ticks = b.ticks;
    }
  }
  if (live.accel_txt.is_open()) {  // the Kinect's readings back in its own axes, TUM's
    const Eigen::Matrix3d R_k_c = dataset::kinect_accel_to_optical().transpose();
    std::string lines;
    for (const sensor::ImuSample& s : frame.imu) {
      const Eigen::Vector3d k = R_k_c * s.accel_mps2;
      lines += geom::format_tum_time(s.t_ns) + " " + format_g(k.x(), 9) + " " + format_g(k.y(), 9) + " " +
               format_g(k.z(), 9) + "\n";
    }
    live.accel_txt.append(lines);
  }
  const slam::FrameResult r = system.track(tracked);
  ++counts.frames;
  if (r.state == slam::TrackingState::kLost) ++counts.lost;
  if (r.state == slam::TrackingState::kNotInitialized) {
    ++counts.not_initialized;
    counts.init_failure = r.tracking.failure;
  }
  if (r.T_w_c) live.cam_traj.append(geom::format_tum_line({r.t_ns, *r.T_w_c}) + "\n");
  return r.state;
}

/// Reads and tracks frames until the stream ends, `max_frames` (0: no limit)
/// or Ctrl-C / SIGTERM / SIGHUP (StopSignals, from before the output folder
/// is made), which end a live run cleanly (exit 0).  A stream
/// error ends the loop too and is kept in the counts: what was tracked so far
/// is still written.
TrackCounts track_frames(openni::OpenniSource& source, std::size_t max_frames, const camera::CameraSettings& settings,
                         slam::System& system, LiveOutputs& live) {
  const std::size_t hint = source.size_hint();
  const std::size_t total = max_frames ? (hint ? std::min(max_frames, hint) : max_frames) : hint;
  TrackCounts counts;
  const auto t0 = Clock::now();
  {
    ProgressBar bar("camera " + source.describe(), total);
    while ((max_frames == 0 || counts.frames < max_frames) && !StopSignals::requested()) {
      std::optional<sensor::RgbdFrame> frame;
      try {
        frame = source.next();
      } catch (const IoError& e) {  // an error of the stream, not of our outputs
        counts.stream_error = e;
        break;
      }
      if (!frame) break;
      counts.t_ns.push_back(frame->t_ns);
      counts.arrived_s.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      const slam::TrackingState state = track_frame(*frame, settings, system, live, counts);
      counts.posed_s.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      const double elapsed_s = std::chrono::duration<double>(Clock::now() - t0).count();
      char status[128];
      std::snprintf(status, sizeof status, "%.1f fps, %s, %zu keyframes",
                    elapsed_s > 0 ? static_cast<double>(counts.frames) / elapsed_s : 0.0,
                    slam::to_string(state), system.num_keyframes());
      bar.update(counts.frames, status);
    }
  }
  counts.elapsed_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return counts;
}

/// Stops the source; after a stream error, an error of the stop itself is
/// dropped (the stream error is the one to report).
std::optional<openni::RecordingSummary> stop_source(openni::OpenniSource& source, bool after_error) {
  if (!after_error) return source.stop();
  try {
    return source.stop();
  } catch (const Error&) {
    return std::nullopt;
  }
}

// ---- results ---------------------------------------------------------------

bool never_initialized(const TrackCounts& c) { return c.frames > 0 && c.not_initialized == c.frames; }

/// The ATE against the simulator's ground truth, appended to stats.json.
void evaluate_against_ground_truth(const std::string& out, std::ostringstream& js) {
  try {
    const eval::Trajectory gt = eval::read_tum(out + "/groundtruth.txt");
    const eval::Trajectory est = eval::read_tum(out + "/CameraTrajectory.txt");
    const eval::EvalResult res = eval::evaluate(gt, est, eval::EvalOptions{});
    std::printf("ATE RMSE %.4f m over %zu poses\n", res.ate.rmse, est.size());
    js << ",\n  \"ate_rmse_m\": " << format_g(res.ate.rmse)
       << ",\n  \"rpe_trans_rmse_m\": " << format_g(res.rpe_trans_m.rmse);
  } catch (const Error& e) {
    std::fprintf(stderr, "pvbench camera: warning: no evaluation: %s\n", e.what());
  }
}

/// With a map loaded or to save: the localisation scored against the run's
/// ground truth (when it has one) and the map saved; stats.json's "map".
void finish_camera_map(const camera::CameraArgs& a, const std::string& source, slam::System& system,
                       run::MapReport* map, std::ostringstream& js) {
  const auto read = [](const std::string& path) {
    try {
      return eval::read_tum(path);
    } catch (const Error&) {
      return eval::Trajectory{};  // none, or nothing tracked
    }
  };
  const eval::Trajectory gt = camera::readable(a.out + "/groundtruth.txt") ? read(a.out + "/groundtruth.txt") : eval::Trajectory{};
  run::finish_map(system, a.map, gt, read(a.out + "/CameraTrajectory.txt"), source, map);
  for (const std::string& line : run::map_log_lines(*map)) std::printf("%s\n", line.c_str());
  js << ",\n  \"map\": " << run::map_report_json(*map);
}

/// Prints the summary and writes stats.json (and the ATE for sim:// runs).
void report_run(const camera::CameraArgs& a, const slam::Settings& settings, openni::OpenniSource& source,
                slam::System& system, const TrackCounts& c,
                const std::optional<openni::RecordingSummary>& rec, LiveOutputs& live,
                std::optional<run::MapReport>& map) {
  const double fps = c.elapsed_s > 0 ? static_cast<double>(c.frames) / c.elapsed_s : 0.0;
  std::ostringstream js;
  js << "{\n  \"source\": \"" << json_escape(source.describe())
     << "\",\n  \"pe_match\": " << (settings.pe_match.enabled ? "true" : "false")
     << ",\n  \"sensors\": \"" << sensor::to_string(settings.motion.setup) << "\""
     << ",\n  \"sync\": " << (a.sync ? "true" : "false") << ",\n  \"seed\": " << a.seed
     << ",\n  \"frames\": " << c.frames << ",\n  \"lost_frames\": " << c.lost
     << ",\n  \"not_initialized_frames\": " << c.not_initialized
     << ",\n  \"dropped_colour\": " << source.dropped_colour()
     << ",\n  \"dropped_depth\": " << source.dropped_depth()
     << ",\n  \"keyframes\": " << system.num_keyframes() << ",\n  \"map_points\": " << system.num_map_points()
     << ",\n  \"fps\": " << format_g(fps);
  const auto [latency_median_ms, latency_p95_ms] = latency_ms(c, false);
  const auto [processing_median_ms, processing_p95_ms] = latency_ms(c, true);
  js << ",\n  \"latency_ms\": {\"median\": " << format_g(latency_median_ms)
     << ", \"p95\": " << format_g(latency_p95_ms) << "}"
     << ",\n  \"processing_ms\": {\"median\": " << format_g(processing_median_ms)
     << ", \"p95\": " << format_g(processing_p95_ms) << "}";
  std::printf("camera: %zu frames (%.1f fps), lost %zu, keyframes %zu, map points %zu%s\n", c.frames, fps,
              c.lost, system.num_keyframes(), system.num_map_points(),
              StopSignals::requested() ? " (stopped by a signal)" : "");
  std::printf("latency from frame time stamp to pose: median %.1f ms, p95 %.1f ms (hand-over to pose: %.1f, %.1f)\n",
              latency_median_ms, latency_p95_ms, processing_median_ms, processing_p95_ms);
  if (rec) {
    std::printf("recorded %u depth and %u colour frames to %s\n", rec->depth_frames, rec->colour_frames,
                rec->path.c_str());
    js << ",\n  \"recorded\": {\"depth_frames\": " << rec->depth_frames
       << ", \"colour_frames\": " << rec->colour_frames << "}";
  }
  if (live.has_gt() && c.frames > 0 && !never_initialized(c)) {
    if (live.gt_sim) live.gt_file.close();
    if (!live.dump_gt.empty()) write_file(a.out + "/groundtruth.txt", read_file(live.dump_gt));
    evaluate_against_ground_truth(a.out, js);
  }
  if (map) finish_camera_map(a, source.describe(), system, &*map, js);
  js << "\n}\n";
  write_file(a.out + "/stats.json", js.str());
  std::printf("wrote %s/{camera.yaml,CameraTrajectory.txt,KeyFrameTrajectory.txt,map.ply,stats.json%s}\n",
              a.out.c_str(), live.has_gt() ? ",groundtruth.txt" : "");
}

/// After every output is written: the problems that fail the run.
void fail_on_problems(const std::string& source, const TrackCounts& c,
                      const std::optional<openni::RecordingSummary>& rec) {
  if (c.stream_error) throw IoError(*c.stream_error);
  if (rec && (rec->depth_frames < c.frames || rec->colour_frames < c.frames))
    throw IoError(rec->path, "the recording lost frames: " + std::to_string(rec->depth_frames) +
                                 " depth and " + std::to_string(rec->colour_frames) + " colour for " +
                                 std::to_string(c.frames) + " tracked");
  if (never_initialized(c))
    throw IoError(source, "SLAM never initialised in " + std::to_string(c.frames) + " frames (" +
                              (c.init_failure.empty() ? std::string("no reason given") : c.init_failure) +
                              ")");
}

int run_camera(camera::CameraArgs a) {
  if (!a.map_mode.empty()) a.map.use = run::parse_map_use(a.map_mode, "--map-mode");
  const std::size_t max_frames =
      parse_count("camera", "--frames", a.frames, 0, 1'000'000'000, " (0: until the stream ends)");
  const int timeout_ms = static_cast<int>(parse_count("camera", "--timeout-ms", a.timeout_ms, 1, 86'400'000));
  // pvbench's MuJoCo handlers before the sim:// driver plug-in's own copy,
  // which OpenNI2 unloads at shutdown.
  sim::install_mujoco_handlers();
  if (const std::optional<sensor::SensorSetup> setup = sensors_from_flag(a.sensors))
    camera::refuse_unfed_setup(a, *setup, "command line", "--sensors");  // before a recording is even scanned
  const std::optional<scenes::Scenario> scenario = camera::check_inputs(a);
  camera::check_settings_source(a, scenario);
  a.map.check();
  // A map of another station than a sim:// scenario's is used after a warning.
  if (scenario) a.map.station = run::station_of(*scenario);
  a.map.allow_other_station = true;
  camera::check_camera_paths(a, scenario);
  const camera::CameraSettings settings = camera::read_camera_settings(a, scenario);
  slam::SystemOptions options;
  options.synchronous = a.sync;
  options.seed = a.seed;
  slam::System system(settings.slam, options);
  std::optional<run::MapReport> map;  // read (and refused when bad) before the folder is made
  if (!a.map.load_path.empty() || !a.map.save_path.empty()) map = run::start_map(system, a.map);
  // From here a stop signal (Ctrl-C during the device's set-up too) ends
  // the run as the end of the stream would: every output written, exit 0.
  const StopSignals stop_signals;
  prepare_output_folder(a.out, a.overwrite, "camera");
  write_file(a.out + "/camera.yaml", settings.text);
  openni::OpenniSource source(camera::source_options(a, settings.slam, timeout_ms));
  LiveOutputs live = open_live_outputs(a, scenario);

  const TrackCounts counts = track_frames(source, max_frames, settings, system, live);
  const std::optional<openni::RecordingSummary> rec = stop_source(source, counts.stream_error.has_value());
  system.shutdown();
  live.cam_traj.close();
  write_tum_file(a.out + "/KeyFrameTrajectory.txt", system.keyframe_trajectory());
  write_map_ply(a.out + "/map.ply", system.map_point_positions());
  report_run(a, settings.slam, source, system, counts, rec, live, map);
  fail_on_problems(source.describe(), counts, rec);
  return 0;
}

}  // namespace

Command add_camera_command(CLI::App& app) {
  auto args = std::make_shared<camera::CameraArgs>();
  CLI::App* sub =
      app.add_subcommand("camera", "run PE-SLAM live on an OpenNI2 camera, an .oni file or sim://scenario");
  auto* uri =
      sub->add_option("--uri", args->uri,
                      "OpenNI2 device URI: sim://<scenario.yaml>[?seed=S&frames=N&gl=egl], freenect://<index> "
                      "(a Kinect v1, or a fakenect dump), a camera's URI, or 'any' for the first device");
  auto* oni = sub->add_option("--oni", args->oni, "play back an .oni recording (in lockstep)")
                  ->check(path_check("camera", "--oni"));
  uri->excludes(oni);
  sub->add_option("--settings", args->settings,
                  "ORB-SLAM2 RGB-D settings YAML with the calibrated intrinsics (default for sim://: the "
                  "scenario's camera)")
      ->check(path_check("camera", "--settings"));
  sub->add_option("--out", args->out, "output folder (created; refused when not empty)")
      ->required()
      ->check(path_check("camera", "--out"));
  sub->add_flag("--overwrite", args->overwrite, "empty an earlier pvbench output in --out first");
  sub->add_option(
      "--record", args->record,
      "record the depth and colour streams to this new .oni file while tracking (an existing file "
      "is never replaced)");
  sub->add_option("--frames", args->frames, "stop after N frames (0: until the stream ends)")
      ->capture_default_str();
  add_sensors_option(sub, &args->sensors);
  sub->add_flag("--sync", args->sync, "synchronous mode: no worker threads, bit-identical runs");
  sub->add_option("--seed", args->seed, "PE-match seed")
      ->capture_default_str()
      ->check(seed_check("camera", "--seed"));
  sub->add_flag("--no-pe-match", args->no_pe_match, "baseline: ORB-SLAM2 motion model without PE-match");
  sub->add_option("--timeout-ms", args->timeout_ms, "no frame for this long is an error")
      ->capture_default_str();
  add_map_options(sub, &args->map, &args->map_mode);
  return {sub, [args, uri, oni] {
            if (uri->count() == 0 && oni->count() == 0)
              throw ConfigError("pvbench camera", "--uri/--oni", "one of them");
            return run_camera(*args);
          }};
}

}  // namespace pvb::cli
