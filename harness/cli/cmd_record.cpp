// pvbench record: render a scenario into a TUM RGB-D sequence folder, or
// (--format fakenect) into a Kinect v1 dump that libfreenect's fakenect plays.
//
// Ctrl-C (SIGINT) or SIGTERM stops at the next frame: the lists (rgb.txt,
// depth.txt, groundtruth.txt, associations.txt) hold the frames written,
// meta.json says "interrupted": true with that frame count, and the exit
// code is 130, as for `pvbench run` and `pvbench slam`.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>

#include "command.hpp"
#include "count_option.hpp"
#include "io_plan.hpp"
#include "pvb/common/clock.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/progress.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/fakenect_dump.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/plot/contact_sheet.hpp"
#include "pvb/run/motion_truth.hpp"
#include "pvb/run/run.hpp"
#include "pvb/report/world_json.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sensor/kinect_v1.hpp"
#include "pvb/sim/sim_frame_source.hpp"
#include "stop_signals.hpp"

namespace pvb::cli {
namespace {

struct RecordOptions {
  std::string scenario;
  std::string out;
  std::string frames;  ///< empty: the scenario's duration; else checked by parse_count
  std::string every = "1";  ///< record every Nth simulated frame
  std::optional<std::uint64_t> seed;
  std::string gl = "auto";
  std::string format = "tum";
  bool overwrite = false;
};

/// A fakenect dump is a Kinect v1's: its camera, 640 x 480 at 30 Hz, the
/// one mode the freenect:// device serves and fakenect replays.  Refused
/// before the output folder is touched.
void check_fakenect_scenario(const scenes::Scenario& s, const std::string& file) {
  const std::string why =
      " for --format fakenect: a dump is a Kinect v1's, and the freenect:// device that plays it serves the "
      "Kinect's 640x480 depth and colour at 30 Hz only";
  if (s.camera.model != scenes::CameraKind::kKinect)
    throw ConfigError(file, "camera.model", "kinect" + why + " (a Kinect measures depth by structured light)",
                      "d435");
  if (s.camera.width != sensor::kinect::kWidth || s.camera.height != sensor::kinect::kHeight)
    throw ConfigError(file, "camera.width/height", "640x480" + why,
                      std::to_string(s.camera.width) + "x" + std::to_string(s.camera.height));
  if (s.camera.fps != 30.0) throw ConfigError(file, "camera.fps", "30" + why, format_exact(s.camera.fps));
}

/// A scenario recorded as a Kinect v1 would have seen it: the rendered
/// (noise-free) depth, cut to the camera's range, as raw IR-view disparity
/// (sensor::kinect), the colour as the sensor model made it, and the
/// accelerometer's reading of gravity (docs/openni.md, "fakenect dumps").
class FakenectDump {
 public:
  FakenectDump(const std::string& dir, const scenes::Scenario& s, sim::SimFrameSource& source)
      : source_(source),
        min_m_(s.camera.depth_range_m[0]),
        max_m_(s.camera.depth_range_m[1]),
        registration_(sensor::kinect::Calibration{}),
        writer_(dir, registration_.calibration()),
        R_c_i_(scenes::T_camera_imu(s.imu).linear()) {}

  void write(const sensor::RgbdFrame& frame, const geom::StampedPose& gt) {
    cv::Mat depth_m = source_.last_depth_gt_m().clone();
    depth_m.setTo(0.0f, (depth_m < min_m_) | (depth_m > max_m_));
    if (cv::countNonZero(frame.depth_m) == 0) depth_m = 0.0f;  // a covered lens (kidnap) sees nothing
    writer_.write(frame.t_ns, frame.rgb, registration_.encode_ir_raw(depth_m), kinect_accel(frame, gt), gt.T_w_c);
  }

 private:
  /// The Kinect's accelerometer gives one reading a frame (its counts are
  /// the writer's): the IMU's specific force over the frame, in camera
  /// axes.  Frame 0 has no readings yet: the robot stands, the reading is
  /// gravity's.
  Eigen::Vector3d kinect_accel(const sensor::RgbdFrame& frame, const geom::StampedPose& gt) const {
    if (frame.imu.empty()) return gt.T_w_c.linear().transpose() * Eigen::Vector3d(0.0, 0.0, 9.80665);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const sensor::ImuSample& s : frame.imu) sum += s.accel_mps2;
    return R_c_i_ * sum / static_cast<double>(frame.imu.size());
  }

 public:

 private:
  sim::SimFrameSource& source_;
  double min_m_, max_m_;
  sensor::kinect::DepthRegistration registration_;
  dataset::FakenectWriter writer_;
  Eigen::Matrix3d R_c_i_;  ///< the IMU's axes in the camera's
};

using Clock = std::chrono::steady_clock;

/// What the frame loop did.
struct RecordLoop {
  int frames = 0;  ///< frames written
  bool interrupted = false;
  double capture_ms = 0, write_ms = 0, loop_s = 0;
  sim::SimFrameSource::StageTimes stages;  ///< summed over the frames
  std::vector<plot::Thumbnail> thumbs;  ///< for the contact sheet
};

/// Renders and writes up to n frames; stops early at the end of the source
/// or, before the next frame, on Ctrl-C / SIGTERM.
/// Writes one frame with its ground-truth pose (TUM folder or fakenect dump).
using FrameWriter = std::function<void(const sensor::RgbdFrame&, const geom::StampedPose&)>;

RecordLoop record_frames(sim::SimFrameSource& source, const geom::StampedPose& gt, const FrameWriter& write,
                         const std::string& name, int n, int every) {
  RecordLoop loop;
  const std::vector<int> sheet_frames = plot::spread_indices(n, 12);
  const auto t_loop = Clock::now();
  ProgressBar bar("record " + name, static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    if (StopSignals::requested()) {
      loop.interrupted = true;
      break;
    }
    auto t0 = Clock::now();
    // The frames between two recorded ones are simulated, not drawn: the
    // next frame's motion readings span them.
    bool more = true;
    for (int k = 1; k < every && i > 0 && more; ++k) more = source.skip();
    const std::optional<sensor::RgbdFrame> frame = more ? source.next() : std::nullopt;
    loop.capture_ms += ms_since(t0);
    if (!frame) break;
    const sim::SimFrameSource::StageTimes& st = source.last_stage_times();
    loop.stages.physics_ms += st.physics_ms;
    loop.stages.render_ms += st.render_ms;
    loop.stages.sensor_ms += st.sensor_ms;
    loop.stages.stereo_match_ms += st.stereo_match_ms;
    t0 = Clock::now();
    write(*frame, gt);
    loop.write_ms += ms_since(t0);
    if (std::find(sheet_frames.begin(), sheet_frames.end(), i) != sheet_frames.end()) {
      char label[64];
      std::snprintf(label, sizeof label, "frame %d  t=%.2f s", i, geom::ns_to_seconds(frame->t_ns));
      loop.thumbs.push_back({frame->rgb.clone(), label});
    }
    loop.frames = i + 1;
    bar.update(static_cast<std::size_t>(i + 1));
  }
  bar.finish();
  loop.loop_s = ms_since(t_loop) / 1000.0;
  return loop;
}

void write_meta(const std::string& path, const RecordOptions& opt, const scenes::Scenario& scenario,
                sim::SimFrameSource& source, const RecordLoop& loop, double total_s, double setup_ms, int every) {
  const sim::Simulator& sim = source.simulator();
  const double per_frame = loop.frames > 0 ? 1.0 / loop.frames : 0.0;
  // The world first, whatever its size; the rest fits a line each.
  std::string meta = "{\n  \"scenario\": {\"name\": \"" + json_escape(scenario.name) + "\", \"file\": \"" +
                     json_escape(opt.scenario) + "\"},\n  \"seed\": " + std::to_string(scenario.seed) +
                     ",\n  \"world\": " + run::world_json(scenario) + ",\n";
  char rest[2048];
  std::snprintf(rest, sizeof rest,
                "  \"frames\": %d,\n"
                "  \"interrupted\": %s,\n"
                "  \"fps\": %.6g,\n"
                "  \"every\": %d,\n"
                "  \"versions\": {\"pvbench\": \"%s\", \"mujoco\": \"%s\"},\n"
                "  \"renderer\": {\"backend\": \"%s\", \"description\": \"%s\"},\n"
                "  \"physics\": {\"timestep_s\": %.9g, \"substeps_per_frame\": %d},\n"
                "  \"kinematics\": {\"wheel_radius_m\": %.6f, \"track_m\": %.6f},\n"
                "  \"motion_sensors\": {\"imu\": \"%s\", \"imu_rate_hz\": %.9g, \"encoder_rate_hz\": %.9g, "
                "\"ticks_per_rev\": %d},\n"
                "  \"timings\": {\"total_s\": %.3f, \"setup_ms\": %.1f, \"capture_ms_per_frame\": %.3f, "
                "\"write_ms_per_frame\": %.3f, \"frames_per_s\": %.2f, \"physics_ms_per_frame\": %.3f, "
                "\"render_ms_per_frame\": %.3f, \"sensor_ms_per_frame\": %.3f, \"stereo_match_ms_per_frame\": %.3f}\n"
                "}\n",
                loop.frames, loop.interrupted ? "true" : "false", scenario.camera.fps / every, every, pvb::version(),
                mj_versionString(), sim::to_string(source.camera().backend()),
                json_escape(source.camera().description()).c_str(), sim.assets().timestep_s, sim.assets().substeps,
                sim.kinematics().wheel_radius_m, sim.kinematics().track_m, scenes::to_string(scenario.imu.part),
                scenes::imu_rate_hz(scenario), scenes::wheel_rate_hz(scenario), scenario.wheels.ticks_per_rev,
                total_s, setup_ms,
                loop.capture_ms * per_frame, loop.write_ms * per_frame,
                loop.loop_s > 0 ? loop.frames / loop.loop_s : 0.0, loop.stages.physics_ms * per_frame,
                loop.stages.render_ms * per_frame, loop.stages.sensor_ms * per_frame,
                loop.stages.stereo_match_ms * per_frame);
  meta += rest;
  write_file(path, meta);
}

/// What a recording of n frames of the scenario's camera will take on the
/// disk, estimated before it starts: the default station's frames, noisy
/// colour PNG 1.45 bytes a pixel and 16-bit depth PNG 0.5, measured on
/// `pv_station` (150 frames: 433 and 140 KB a frame at 640 x 480), plus
/// 1 KB a frame of lists and motion readings and 16 MB of scene and textures.
double recording_bytes(const scenes::Scenario& s, int n) {
  const double pixels = static_cast<double>(s.camera.width) * s.camera.height;
  return n * (pixels * (1.45 + 0.5) + 1024.0) + 16e6;
}

/// Refuses, with one line, a recording the disk under `out` cannot hold;
/// else says what it will take when that is a gigabyte or more.
void check_disk(const std::string& out, const scenes::Scenario& s, int n) {
  std::error_code ec;
  const std::filesystem::space_info space = std::filesystem::space(out, ec);
  const double need = recording_bytes(s, n);
  const auto gb = [](double b) { return format_number("%.2f GB", b / 1e9); };
  if (ec) return;  // no figure to judge by: the writes say so if the disk fills
  if (static_cast<double>(space.available) < need)
    throw IoError(out, "expected a disk with about " + gb(need) + " free for " + std::to_string(n) +
                           " frames (fewer with --frames or --every), got " +
                           gb(static_cast<double>(space.available)) + " free");
  if (need >= 1e9)
    std::printf("record: %d frames, about %s on the disk (%s free)\n", n, gb(need).c_str(),
                gb(static_cast<double>(space.available)).c_str());
}

int run_record(const RecordOptions& opt, bool frames_given) {
  const int max_frames =
      frames_given ? static_cast<int>(parse_count("record", "--frames", opt.frames, 1, 1'000'000'000)) : 0;
  const int every = static_cast<int>(parse_count("record", "--every", opt.every, 1, 1'000'000));
  const sim::GlBackend backend = sim::parse_gl_backend(opt.gl);
  scenes::Scenario scenario = scenes::load_scenario(opt.scenario);
  if (opt.seed) scenario.seed = *opt.seed;
  if (opt.format == "fakenect") check_fakenect_scenario(scenario, opt.scenario);
  if (opt.format == "fakenect" && every > 1)
    throw ConfigError("pvbench record", "--every", "1 with --format fakenect (a Kinect v1 dump is 30 Hz)",
                      std::to_string(every));
  IoPlan plan;
  add_scenario_inputs(&plan, "--scenario", scenario);
  plan.output_folder("--out", opt.out).check();
  prepare_output_folder(opt.out, opt.overwrite, "record");  // before the work: never into another recording
  const StopSignals stop_signals;  // Ctrl-C during the set-up stops before the first frame

  const auto t_start = Clock::now();
  // n recorded frames, every `every`th of the scenario's.
  const int simulated = scenes::frame_count(scenario);
  const int n = std::min((simulated - 1) / every + 1, max_frames > 0 ? max_frames : simulated);
  check_disk(opt.out, scenario, n);
  geom::StampedPose gt;  // ground truth arrives through its own sink
  sim::SimFrameSource source(scenario, backend, (n - 1) * every + 1,
                             [&gt](const geom::StampedPose& p) { gt = p; });
  const double setup_ms = ms_since(t_start);

  sim::write_scene(source.simulator().assets(), opt.out);
  dataset::OrbSlamSettings settings = run::orbslam_settings_for(scenario);
  settings.fps = scenario.camera.fps / every;
  std::unique_ptr<dataset::TumSequenceWriter> tum;
  std::unique_ptr<FakenectDump> dump;
  std::unique_ptr<dataset::MotionFilesWriter> motion;
  std::unique_ptr<run::MotionTruthWriter> truth;
  FrameWriter write;
  if (opt.format == "fakenect") {
    settings.depth_map_factor = 1000.0;  // OpenNI2 serves depth in mm
    // A Kinect has no gyroscope and no wheels, and its accelerometer is not
    // the robot's IMU: pvbench camera supplies the Kinect's description.
    settings.robot.reset();
    settings.sensors.reset();
    dump = std::make_unique<FakenectDump>(opt.out, scenario, source);
    write = [&dump](const sensor::RgbdFrame& f, const geom::StampedPose& p) { dump->write(f, p); };
  } else {
    tum = std::make_unique<dataset::TumSequenceWriter>(opt.out, sensor::kTumDepthFactor,
                                                       std::string("pvbench ") + pvb::version());
    motion = std::make_unique<dataset::MotionFilesWriter>(opt.out, run::robot_calibration_for(scenario));
    truth = std::make_unique<run::MotionTruthWriter>(opt.out);
    run::write_robot_truth(opt.out, scenario, source.simulator().kinematics());
    write = [&](const sensor::RgbdFrame& f, const geom::StampedPose& p) {
      tum->write(f, p.T_w_c);
      motion->write(f);
      truth->write(source.last_imu_truth(), source.last_wheel_truth());
    };
  }
  dataset::write_orbslam_settings(opt.out + "/camera.yaml", settings);
  const RecordLoop loop = record_frames(source, gt, write, scenario.name, n, every);
  if (loop.interrupted)
    std::printf("record: stopped by a signal after %d of %d frames; writing meta.json for them\n",
                loop.frames, n);

  write_meta(opt.out + "/meta.json", opt, scenario, source, loop, ms_since(t_start) / 1000.0, setup_ms, every);
  plot::write_rgb_png(plot::make_contact_sheet(loop.thumbs, 4, 320), opt.out + "/contact_sheet.png");
  std::printf("recorded %d frames of %s to %s (%s; %.1f frames/s, capture %.1f ms/frame)\n", loop.frames,
              scenario.name.c_str(), opt.out.c_str(), source.camera().description().c_str(),
              loop.loop_s > 0 ? loop.frames / loop.loop_s : 0.0,
              loop.frames > 0 ? loop.capture_ms / loop.frames : 0.0);
  return loop.interrupted ? 130 : 0;
}

}  // namespace

Command add_record_command(CLI::App& app) {
  auto opt = std::make_shared<RecordOptions>();
  CLI::App* sub = app.add_subcommand("record", "Render a scenario into a TUM RGB-D sequence folder");
  sub->add_option("--scenario", opt->scenario, "scenario YAML file")
      ->required()
      ->check(path_check("record", "--scenario"));
  sub->add_option("--out", opt->out, "output folder (created; refused when not empty)")
      ->required()
      ->check(path_check("record", "--out"));
  sub->add_flag("--overwrite", opt->overwrite, "empty an earlier pvbench output in --out first");
  CLI::Option* frames =
      sub->add_option("--frames", opt->frames, "record at most N frames (default: the scenario's duration)");
  sub->add_option("--every", opt->every,
                  "record every Nth frame of the scenario's camera (a long drive at a lower rate; the "
                  "frames between are simulated, not drawn, and their motion readings kept)")
      ->capture_default_str();
  sub->add_option("--seed", opt->seed, "override the scenario's seed")
      ->check(seed_check("record", "--seed", std::numeric_limits<std::uint64_t>::max()));
  sub->add_option("--gl", opt->gl, "rendering backend")->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  sub->add_option("--format", opt->format,
                  "tum: a TUM RGB-D folder; fakenect: a Kinect v1 dump for libfreenect's fakenect "
                  "(docs/openni.md)")
      ->capture_default_str()
      ->check(CLI::IsMember({"tum", "fakenect"}));
  return {sub, [opt, frames] { return run_record(*opt, frames->count() > 0); }};
}

}  // namespace pvb::cli
