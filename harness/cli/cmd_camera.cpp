// pvbench camera: PE-SLAM live on an OpenNI2 RGB-D camera, an .oni
// recording or the simulator's virtual OpenNI2 device (sim://scenario.yaml).
//
// Outputs (folder --out): camera.yaml (the settings used), CameraTrajectory.txt
// (flushed frame by frame), KeyFrameTrajectory.txt, map.ply (the sparse map
// points), stats.json, and for sim:// sources groundtruth.txt and the ATE.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "command.hpp"
#include "stop_signals.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/progress.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/openni/oni_file.hpp"
#include "pvb/openni/openni_source.hpp"
#include "pvb/openni/sim_uri.hpp"
#include "pvb/run/run.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"

namespace pvb::cli {
namespace {

struct CameraArgs {
  std::string uri;
  std::string oni;
  std::string settings;
  std::string out;
  std::string record;
  std::size_t frames = 0;
  bool sync = false;
  std::uint32_t seed = 1;
  bool no_pe_match = false;
  int timeout_ms = 10000;
};

using Clock = std::chrono::steady_clock;

std::ofstream open_out(const std::string& path) {
  std::ofstream f(path);
  if (!f) throw IoError(path, "cannot open for writing");
  return f;
}

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

/// The scenario of a sim:// URI with the URI's seed applied.
scenes::Scenario sim_scenario(const openni::SimUri& uri) {
  scenes::Scenario s = scenes::load_scenario(uri.scenario_path);
  if (uri.seed) s.seed = *uri.seed;
  return s;
}

void write_map_ply(const std::string& path, const std::vector<Eigen::Vector3d>& points) {
  std::ostringstream s;
  s << "ply\nformat ascii 1.0\ncomment PE-SLAM sparse map, world frame, metres\nelement vertex "
    << points.size() << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const Eigen::Vector3d& p : points) s << fmt(p.x()) << " " << fmt(p.y()) << " " << fmt(p.z()) << "\n";
  write_file(path, s.str());
}

void write_tum_file(const std::string& path, const std::vector<geom::StampedPose>& poses) {
  std::string text = "# timestamp tx ty tz qx qy qz qw (T_w_c)\n";
  for (const auto& p : poses) text += geom::format_tum_line(p) + "\n";
  write_file(path, text);
}

int run_camera(const CameraArgs& a) {
  const bool from_file = !a.oni.empty();
  const bool is_sim = !from_file && openni::is_sim_uri(a.uri);
  std::optional<openni::SimUri> sim_uri;
  std::optional<scenes::Scenario> scenario;
  if (is_sim) {
    sim_uri = openni::parse_sim_uri(a.uri);
    scenario = sim_scenario(*sim_uri);
  }
  if (from_file) openni::check_oni_complete(a.oni, openni::scan_oni_file(a.oni));  // before anything else
  dataset::make_dirs(a.out);

  // Settings: given, or derived from the scenario's camera.  The file used
  // is saved as camera.yaml; intrinsics never come from the driver.
  const std::string settings_path = a.out + "/camera.yaml";
  if (!a.settings.empty()) {
    std::ifstream probe(a.settings);
    if (!probe) throw IoError(a.settings, "cannot read the settings file");
    const std::string text = read_file(a.settings);
    if (a.settings != settings_path) write_file(settings_path, text);
  } else if (scenario) {
    dataset::OrbSlamSettings o = run::orbslam_settings_for(*scenario);
    o.depth_map_factor = 1000.0;  // OpenNI2 depth is in millimetres
    dataset::write_orbslam_settings(settings_path, o);
  } else {
    throw ConfigError(
        "pvbench camera", "--settings",
        "a settings file with the camera's calibrated intrinsics (only sim:// devices have their own)");
  }
  slam::Settings settings = slam::read_settings(settings_path);
  for (const std::string& w : settings.warnings)
    std::fprintf(stderr, "pvbench camera: warning: %s\n", w.c_str());
  if (a.no_pe_match) settings.pe_match.enabled = false;

  openni::OpenniOptions so;
  so.uri = a.uri == "any" ? std::string() : a.uri;
  so.oni_path = a.oni;
  so.width = settings.K.width;
  so.height = settings.K.height;
  so.fps = static_cast<int>(std::lround(settings.fps));
  so.record_path = a.record;
  so.timeout_ms = a.timeout_ms;
  so.stop_requested = [] { return StopSignals::requested(); };  // Ctrl-C also ends a wait for frames
  openni::OpenniSource source(so);

  slam::SystemOptions options;
  options.synchronous = a.sync;
  options.seed = a.seed;
  slam::System system(settings, options);

  std::ofstream cam_traj = open_out(a.out + "/CameraTrajectory.txt");
  cam_traj << "# timestamp tx ty tz qx qy qz qw (T_w_c)\n" << std::flush;
  // Ground truth of a sim:// device: the harness re-runs the scenario's
  // physics (deterministic, no rendering) beside the device, so nothing but
  // images travels through OpenNI2 (docs/openni.md).
  std::unique_ptr<sim::Simulator> gt_sim;
  std::ofstream gt_file;
  if (scenario) {
    gt_sim = std::make_unique<sim::Simulator>(*scenario);
    gt_file = open_out(a.out + "/groundtruth.txt");
    gt_file << "# timestamp tx ty tz qx qy qz qw (T_w_c, simulator ground truth)\n" << std::flush;
  }

  const std::size_t hint = source.size_hint();
  const std::size_t total = a.frames ? (hint ? std::min(a.frames, hint) : a.frames) : hint;
  std::size_t frames = 0, lost = 0;
  std::optional<IoError> stream_error;
  const auto t0 = Clock::now();
  {
    // Ctrl-C (or SIGTERM) ends a live run cleanly: the loop stops, the
    // recorder is closed and every output is written (exit 0).
    const StopSignals stop_signals;
    ProgressBar bar("camera " + source.describe(), total);
    try {
      while ((a.frames == 0 || frames < a.frames) && !StopSignals::requested()) {
        std::optional<sensor::RgbdFrame> frame = source.next();
        if (!frame) break;
        if (frame->rgb.cols != settings.K.width || frame->rgb.rows != settings.K.height)
          throw ConfigError(
              settings_path, "Camera.width/height",
              std::to_string(frame->rgb.cols) + "x" + std::to_string(frame->rgb.rows) + " (the stream)",
              std::to_string(settings.K.width) + "x" + std::to_string(settings.K.height));
        if (gt_sim) {
          while (gt_sim->frame_index() < static_cast<int>(frame->index)) gt_sim->advance();
          gt_file << geom::format_tum_line({frame->t_ns, gt_sim->T_w_c()}) << "\n" << std::flush;
        }
        const slam::FrameResult r = system.track(*frame);
        ++frames;
        if (r.state == slam::TrackingState::kLost) ++lost;
        if (r.T_w_c) cam_traj << geom::format_tum_line({r.t_ns, *r.T_w_c}) << "\n" << std::flush;
        const double elapsed_s = std::chrono::duration<double>(Clock::now() - t0).count();
        char status[128];
        std::snprintf(status, sizeof status, "%.1f fps, %s, %zu keyframes",
                      elapsed_s > 0 ? static_cast<double>(frames) / elapsed_s : 0.0, slam::to_string(r.state),
                      system.num_keyframes());
        bar.update(frames, status);
      }
    } catch (const IoError& e) {
      // Unplugged camera or broken file: keep everything tracked so far.
      stream_error = e;
    }
  }
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - t0).count();
  std::optional<openni::RecordingSummary> rec;
  if (!stream_error) {
    rec = source.stop();
  } else {
    try {
      rec = source.stop();
    } catch (const Error&) {
      // the stream error is the one to report
    }
  }
  system.shutdown();
  cam_traj.close();
  write_tum_file(a.out + "/KeyFrameTrajectory.txt", system.keyframe_trajectory());
  write_map_ply(a.out + "/map.ply", system.map_point_positions());

  const double fps = elapsed_s > 0 ? static_cast<double>(frames) / elapsed_s : 0.0;
  std::ostringstream js;
  js << "{\n  \"source\": \"" << json_escape(source.describe())
     << "\",\n  \"pe_match\": " << (settings.pe_match.enabled ? "true" : "false")
     << ",\n  \"sync\": " << (a.sync ? "true" : "false") << ",\n  \"seed\": " << a.seed
     << ",\n  \"frames\": " << frames << ",\n  \"lost_frames\": " << lost
     << ",\n  \"dropped_colour\": " << source.dropped_colour()
     << ",\n  \"dropped_depth\": " << source.dropped_depth()
     << ",\n  \"keyframes\": " << system.num_keyframes() << ",\n  \"map_points\": " << system.num_map_points()
     << ",\n  \"fps\": " << fmt(fps);
  std::printf("camera: %zu frames (%.1f fps), lost %zu, keyframes %zu, map points %zu%s\n", frames, fps, lost,
              system.num_keyframes(), system.num_map_points(),
              StopSignals::requested() ? " (stopped by a signal)" : "");
  if (rec) {
    std::printf("recorded %u depth and %u colour frames to %s\n", rec->depth_frames, rec->colour_frames,
                rec->path.c_str());
    js << ",\n  \"recorded\": {\"depth_frames\": " << rec->depth_frames
       << ", \"colour_frames\": " << rec->colour_frames << "}";
  }

  if (gt_sim && frames > 0) {
    gt_file.close();
    try {
      const eval::Trajectory gt = eval::read_tum(a.out + "/groundtruth.txt");
      const eval::Trajectory est = eval::read_tum(a.out + "/CameraTrajectory.txt");
      const eval::EvalResult res = eval::evaluate(gt, est, eval::EvalOptions{});
      std::printf("ATE RMSE %.4f m over %zu poses\n", res.ate.rmse, est.size());
      js << ",\n  \"ate_rmse_m\": " << fmt(res.ate.rmse)
         << ",\n  \"rpe_trans_rmse_m\": " << fmt(res.rpe_trans_m.rmse);
    } catch (const Error& e) {
      std::fprintf(stderr, "pvbench camera: warning: no evaluation: %s\n", e.what());
    }
  }
  js << "\n}\n";
  write_file(a.out + "/stats.json", js.str());
  std::printf("wrote %s/{camera.yaml,CameraTrajectory.txt,KeyFrameTrajectory.txt,map.ply,stats.json%s}\n",
              a.out.c_str(), gt_sim ? ",groundtruth.txt" : "");
  if (stream_error) throw IoError(*stream_error);
  if (rec && (rec->depth_frames < frames || rec->colour_frames < frames))
    throw IoError(rec->path, "the recording lost frames: " + std::to_string(rec->depth_frames) +
                                 " depth and " + std::to_string(rec->colour_frames) + " colour for " +
                                 std::to_string(frames) + " tracked");
  return 0;
}

}  // namespace

Command add_camera_command(CLI::App& app) {
  auto args = std::make_shared<CameraArgs>();
  CLI::App* sub =
      app.add_subcommand("camera", "run PE-SLAM live on an OpenNI2 camera, an .oni file or sim://scenario");
  auto* uri =
      sub->add_option("--uri", args->uri,
                      "OpenNI2 device URI: sim://<scenario.yaml>[?seed=S&frames=N&gl=egl], a camera's URI, "
                      "or 'any' for the first device");
  auto* oni = sub->add_option("--oni", args->oni, "play back an .oni recording (in lockstep)");
  uri->excludes(oni);
  sub->add_option("--settings", args->settings,
                  "ORB-SLAM2 RGB-D settings YAML with the calibrated intrinsics (default for sim://: the "
                  "scenario's camera)");
  sub->add_option("--out", args->out, "output folder")->required();
  sub->add_option("--record", args->record,
                  "record the depth and colour streams to this .oni while tracking");
  sub->add_option("--frames", args->frames, "stop after N frames (0: until the stream ends)")
      ->capture_default_str();
  sub->add_flag("--sync", args->sync, "synchronous mode: no worker threads, bit-identical runs");
  sub->add_option("--seed", args->seed, "PE-match seed")->capture_default_str();
  sub->add_flag("--no-pe-match", args->no_pe_match, "baseline: ORB-SLAM2 motion model without PE-match");
  sub->add_option("--timeout-ms", args->timeout_ms, "no frame for this long is an error")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  return {sub, [args, uri, oni] {
            if (uri->count() == 0 && oni->count() == 0)
              throw ConfigError("pvbench camera", "--uri/--oni", "one of them");
            return run_camera(*args);
          }};
}

}  // namespace pvb::cli
