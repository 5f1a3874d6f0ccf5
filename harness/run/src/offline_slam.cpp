#include "pvb/run/offline_slam.hpp"

#include <cstdarg>
#include <ctime>

#include "offline_slam_impl.hpp"

namespace pvb::run {
namespace offline_detail {

const char* stop_name(StopReason r) {
  switch (r) {
    case StopReason::kEnd:
      return "end";
    case StopReason::kSignal:
      return "signal";
    case StopReason::kTooManyMissing:
      return "missing_frames";
    case StopReason::kImageSize:
      return "image_size";
    case StopReason::kSystemError:
      return "system_error";
  }
  return "?";
}

/// printf into a string.
__attribute__((format(printf, 1, 2))) std::string strf(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string out(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, format, again);
  va_end(again);
  return out;
}

}  // namespace offline_detail

namespace {

using eval::mean_of;
using eval::percentile;

/// CPU time of the calling thread in ms (unlike wall time, not inflated
/// when other processes share the cores).
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

/// Missing frames always allowed, whatever max_missing says.
constexpr std::size_t kMinMissingAllowed = 5;

void write_tum_file(const std::string& path, const std::vector<geom::StampedPose>& poses) {
  write_file(path, geom::format_tum(poses, "# timestamp tx ty tz qx qy qz qw (T_w_c)\n"));
}

/// What slam reads and writes, checked before any work: no output lands on
/// a file of the sequence, the settings, their vocabulary or the map.
void check_slam_paths(const OfflineSlamOptions& a, const slam::Settings& settings) {
  IoPlan plan;
  if (!a.sequence.empty())
    plan.inputs("a file of the --sequence folder", dataset::sequence_files(a.sequence))
        .input_folder("the --sequence folder", a.sequence);
  plan.input("the --settings file", a.settings).input("the --map file", a.map.load_path);
  if (settings.vocabulary_path != "none")
    plan.input("the vocabulary of the --settings file", settings.vocabulary_path);
  plan.output_folder("--out", a.out, offline_slam_output_names()).output_file("--save-map", a.map.save_path);
  plan.check();
  check_output_folder(a.out, a.overwrite);
  reserve_output(a.map.save_path, "--save-map");
}

}  // namespace

void resolve_offline_seed(std::optional<std::uint32_t> flag, OfflineSlamOptions* o) {
  if (flag) {
    o->seed = *flag;
    o->seed_source = "--seed";
  } else if (const auto id = suite::read_folder_identity(o->sequence); id && id->seed) {
    o->seed = static_cast<std::uint32_t>(*id->seed);  // as pvbench run and record seed PE-match
    o->seed_source = id->file;
  } else {
    o->seed = kDefaultOfflineSeed;
    o->seed_source = "default";
  }
}

void check_offline_options(const OfflineSlamOptions& a) {
  if (a.max_frames < 0)
    throw ConfigError("command line", "--max-frames", "a number of frames >= 0 (0: all)",
                      std::to_string(a.max_frames));
  if (!(a.max_missing >= 0.0 && a.max_missing <= 1.0))  // NaN fails too
    throw ConfigError("command line", "--max-missing", "a share of the frames in [0, 1]",
                      format_g(a.max_missing));
}


slam::Settings OfflineSlam::Impl::read_settings() {
  slam::Settings settings = slam::read_settings(a_.settings);
  for (const std::string& w : settings.warnings) warn("warning: " + w);
  if (a_.no_pe_match) settings.pe_match.enabled = false;
  if (a_.no_dense) settings.dense.enabled = false;
  if (a_.sensors) settings.motion.setup = *a_.sensors;
  imu_supplied_ = settings.motion.setup == sensor::SensorSetup::kCameraAccel &&
                  supply_kinect_accelerometer(&settings, a_.sequence);
  if (imu_supplied_)
    warn(std::string("note: sensors ") + sensor::to_string(settings.motion.setup) +
         ": the settings have no IMU.* keys; the Kinect v1 accelerometer's description is used "
         "(docs/sensors.md)");
  apply_sensor_setup(&settings, settings.motion.setup);
  return settings;
}

OfflineSlam::Impl::Impl(const OfflineSlamOptions& a)
    : a_(a),
      settings_((check_offline_options(a), read_settings())),
      reader_(a.sequence, settings_.depth_map_factor, 0.02, motion_needs(settings_.motion.setup)) {
  check_motion();
  // One rule for missing frames (docs/slam.md): more than max_missing of
  // the sequence's frames, and more than 5, ends the run.
  reader_.set_max_skipped(std::max<std::size_t>(
      kMinMissingAllowed,
      static_cast<std::size_t>(std::floor(a.max_missing * static_cast<double>(reader_.size_hint())))));
  a.map.check();
  check_slam_paths(a, settings_);
  slam::SystemOptions options;
  options.synchronous = a.sync;
  options.seed = a.seed;
  system_ = std::make_unique<slam::System>(settings_, options);
  // The map is read (and refused when bad) before the folder is made.
  if (!a.map.load_path.empty() || !a.map.save_path.empty()) map_ = start_map(*system_, a.map);
  prepare_output_folder(a.out, a.overwrite, "slam");
  open_outputs();
}

void OfflineSlam::Impl::check_motion() {
  check_sequence_motion(reader_, static_cast<std::size_t>(a_.max_frames), settings_, a_.settings,
                        imu_supplied_);
  if (imu_supplied_) kinect_accelerometer_at(mean_rate_hz(reader_.motion().imu), &settings_.motion.imu);
}

void OfflineSlam::Impl::open_outputs() {
  cam_traj_ = OutputFile(a_.out + "/CameraTrajectory.txt");
  kf_traj_ = OutputFile(a_.out + "/KeyFrameTrajectory.txt");
  timing_ = OutputFile(a_.out + "/timing.csv");
  costs_.open(a_.out + "/costs.csv");
  cam_traj_.append("# timestamp tx ty tz qx qy qz qw (T_w_c)\n");
  kf_traj_.append("# timestamp tx ty tz qx qy qz qw (T_w_c)\n");
  timing_.append(
      "frame,t_s,state,method,features,tracking_ms,orb_ms,pe_match_ms,coarse_matches,matches_kept,"
      "inliers,keyframe,mapping_ms,cpu_ms,align_tried,aligned,align_ms,"
      "kf_tracked_close,kf_untracked_close,kf_ref_points,kf_ref_all,kf_ref_shared,features_with_depth,depth_valid,"
      "local_keyframes,local_points\n");
  if (a_.dump_matches) {
    const std::string gt = a_.sequence + "/groundtruth.txt";
    if (!std::ifstream(gt)) throw IoError(gt, "--dump-matches needs the sequence's ground truth");
    scorer_ = std::make_unique<MotionMatchScorer>(a_.out, gt, settings_);
  }
}

StopReason OfflineSlam::Impl::track_frames() {
  const std::size_t n = reader_.size_hint();
  const std::size_t total = a_.max_frames > 0 ? std::min(static_cast<std::size_t>(a_.max_frames), n) : n;
  if (a_.on_progress_begin)
    a_.on_progress_begin(std::string("slam") + (settings_.pe_match.enabled ? " (PE-match)" : " (baseline)"),
                         total);
  StopReason stop = StopReason::kEnd;
  while (tally_.frames < total) {
    if (stop_requested()) {
      stop = StopReason::kSignal;
      break;
    }
    const std::optional<sensor::RgbdFrame> frame = reader_.next();
    if (!frame) {
      if (reader_.skip_limit_reached()) stop = StopReason::kTooManyMissing;
      break;
    }
    if (frame->rgb.cols != settings_.K.width || frame->rgb.rows != settings_.K.height) {
      image_size_error_ = std::to_string(frame->rgb.cols) + "x" + std::to_string(frame->rgb.rows) +
                          " (the images, " + frame->rgb_name + ")";
      if (tally_.frames == 0) fail_if_incomplete(StopReason::kImageSize);  // nothing tracked to keep
      stop = StopReason::kImageSize;
      break;
    }
    const std::optional<slam::TrackingState> state = track_one(*frame);
    if (!state) {
      stop = StopReason::kSystemError;
      break;
    }
    if (a_.on_progress) a_.on_progress(tally_.frames, slam::to_string(*state));
  }
  if (stop == StopReason::kEnd && stop_requested()) stop = StopReason::kSignal;
  if (a_.on_progress_end) a_.on_progress_end();
  return stop;
}

std::optional<slam::TrackingState> OfflineSlam::Impl::track_one(const sensor::RgbdFrame& frame) {
  const double cpu0_ms = thread_cpu_ms();
  slam::FrameResult r;
  try {
    r = system_->track(frame);
  } catch (const IoError& e) {  // a worker's full disk, passed on by the next keyframe's hand-over
    system_error_ = e.what();
    return std::nullopt;
  }
  const double cpu_ms = thread_cpu_ms() - cpu0_ms;
  tally_.cpu_ms.push_back(cpu_ms);
  tally_.frame_t_ns.push_back(frame.t_ns);
  ++tally_.frames;
  if (r.state == slam::TrackingState::kLost) ++tally_.lost;
  if (r.state == slam::TrackingState::kDeadReckoning) ++tally_.dead_reckoned;
  if (r.state == slam::TrackingState::kNotInitialized) {
    ++tally_.not_init;
    tally_.init_failure = r.tracking.failure;
  }
  tally_.tracking_ms.push_back(r.tracking_ms);
  if (settings_.pe_match.enabled && r.tracking.method == slam::TrackingMethod::kMotionModel)
    tally_.pe_ms.push_back(r.tracking.pe_match_ms);
  eval::record_gravity(&tally_.gravity, r.t_ns, r.g_w);
  if (r.T_w_c) {
    cam_traj_.append(geom::format_tum_line({r.t_ns, *r.T_w_c}) + "\n");
    ++tally_.poses;
  }
  if (r.tracking.new_keyframe && r.T_w_c) {
    kf_traj_.append(geom::format_tum_line({r.t_ns, *r.T_w_c}) + "\n");
    tally_.keyframe_t_ns.push_back(r.t_ns);
  }
  write_timing_line(frame, r, cpu_ms);
  costs_.frame(*system_, static_cast<int>(frame.index), geom::ns_to_seconds(frame.t_ns), r.tracking_ms);
  if (scorer_) scorer_->add(frame, r);
  return r.state;
}

void OfflineSlam::Impl::write_timing_line(const sensor::RgbdFrame& frame, const slam::FrameResult& r,
                                          double cpu_ms) {
  std::ostringstream line;
  line << frame.index << "," << geom::format_tum_time(r.t_ns) << "," << slam::to_string(r.state) << ","
       << slam::to_string(r.tracking.method) << "," << r.num_features << ","
       << format_g(r.tracking_ms) << "," << format_g(r.orb_ms) << "," << format_g(r.tracking.pe_match_ms)
       << "," << r.tracking.coarse_matches << "," << r.tracking.matches_kept << "," << r.tracking.inliers
       << "," << (r.tracking.new_keyframe ? 1 : 0) << "," << format_g(r.mapping_ms) << "," << format_g(cpu_ms)
       << "," << r.tracking.align_tried << "," << r.tracking.aligned << "," << format_g(r.tracking.align_ms)
       << "," << r.tracking.kf_tracked_close << "," << r.tracking.kf_untracked_close << ","
       << r.tracking.kf_ref_points << "," << r.tracking.kf_ref_all << "," << r.tracking.kf_ref_shared << ","
       << r.features_with_depth << "," << format_fixed(r.depth_valid, 4) << "," << r.tracking.local_keyframes << ","
       << r.tracking.local_points << "\n";
  timing_.append(line.str());
}

/// Stops the workers and writes the outputs that exist only at the end (the
/// refined keyframe and frame trajectories, Map.txt, PointCloud.ply).
/// Returns the "dense" part of stats.json (empty when dense mapping is off).
std::string OfflineSlam::Impl::write_final_outputs() {
  costs_.finish(*system_);
  shutdown_system();
  kf_traj_.close();
  // Rewrite the keyframe trajectory with the poses refined by local BA
  // (culled keyframes are left out, as ORB-SLAM2 does).
  write_tum_file(a_.out + "/KeyFrameTrajectory.txt", system_->keyframe_trajectory());
  // ORB-SLAM2's way of saving: each frame relative to its (refined) reference keyframe.
  write_tum_file(a_.out + "/CameraTrajectoryRefined.txt", system_->refined_trajectory());
  if (a_.dump_map) {
    std::ostringstream map_text;
    slam::write_map_snapshot(system_->map_snapshot(), map_text, a_.out + "/Map.txt");
    write_file(a_.out + "/Map.txt", map_text.str());
  }
  cam_traj_.close();
  if (!system_->dense_enabled()) return {};
  // The corrected map, the map as built and, after a loop, the corrected map around it.
  const std::vector<DenseMapFile> maps = write_dense_maps(*system_, a_.out);
  return dense_json(maps.front().points);
}

void OfflineSlam::Impl::shutdown_system() {
  try {
    system_->shutdown();
  } catch (const IoError& e) {  // the trajectories so far are still written
    if (system_error_.empty()) system_error_ = e.what();
  }
}

/// The "dense" part of stats.json, printing the dense map's line on the way.
std::string OfflineSlam::Impl::dense_json(std::size_t cloud_points) {
  const slam::dense::DenseMapperStats dense = system_->dense_stats();
  const double per_kf_ms = dense.keyframes ? dense.total_ms / static_cast<double>(dense.keyframes) : 0.0;
  text(strf("dense map: %zu points from %zu keyframes (%.1f ms per keyframe) -> %s/PointCloud.ply\n",
            cloud_points, dense.keyframes, per_kf_ms, a_.out.c_str()));
  std::ostringstream js;
  js << ",\n  \"dense\": {\"keyframes\": " << dense.keyframes << ", \"points\": " << cloud_points
     << ", \"keyframe_points\": " << dense.points << ", \"ms_per_keyframe\": " << format_g(per_kf_ms)
     << ", \"resolution_m\": " << format_g(settings_.dense.resolution_m)
     << ", \"pose_updates\": " << dense.pose_updates << ", \"keyframes_moved\": " << dense.keyframes_moved
     << ", \"loop_update_ms\": [";
  for (std::size_t i = 0; i < dense.loop_update_ms.size(); ++i)
    js << (i ? ", " : "") << format_g(dense.loop_update_ms[i]);
  js << "]}";
  return js.str();
}

/// The run's counts, timings and mapping statistics for stats.json (without
/// the closing brace), printing the summary lines on the way.
std::string OfflineSlam::Impl::stats_json(StopReason stop, const std::string& dense_json) {
  const Tally& t = tally_;
  std::ostringstream js;
  js << "{\n  \"sequence\": \"" << json_escape(a_.sequence)
     << "\",\n  \"pe_match\": " << (settings_.pe_match.enabled ? "true" : "false")
     << ",\n  \"sensors\": \"" << sensor::to_string(settings_.motion.setup) << "\""
     << ",\n  \"sync\": " << (a_.sync ? "true" : "false") << ",\n  \"seed\": " << a_.seed
     << ",\n  \"seed_source\": \"" << json_escape(a_.seed_source) << "\""
     << ",\n  \"interrupted\": " << (stop == StopReason::kSignal ? "true" : "false") << ",\n  \"stop\": \""
     << stop_name(stop) << "\""
     << (system_error_.empty() ? "" : ",\n  \"failure\": \"" + json_escape(system_error_) + "\"")
     << ",\n  \"frames\": " << t.frames << ",\n  \"lost_frames\": " << t.lost
     << ",\n  \"not_initialized_frames\": " << t.not_init
     << ",\n  \"dead_reckoned_frames\": " << t.dead_reckoned
     << ",\n  \"skipped_frames\": " << reader_.skipped()
     << ",\n  \"keyframes\": " << system_->num_keyframes()
     << ",\n  \"map_points\": " << system_->num_map_points()
     << ",\n  \"tracking_ms\": {\"median\": " << format_g(percentile(t.tracking_ms, 0.5))
     << ", \"mean\": " << format_g(mean_of(t.tracking_ms))
     << ", \"p95\": " << format_g(percentile(t.tracking_ms, 0.95))
     << "},\n  \"pe_match_ms\": {\"median\": " << format_g(percentile(t.pe_ms, 0.5))
     << ", \"p95\": " << format_g(percentile(t.pe_ms, 0.95)) << "}"
     << ",\n  \"cpu_ms\": {\"median\": " << format_g(percentile(t.cpu_ms, 0.5))
     << ", \"mean\": " << format_g(mean_of(t.cpu_ms)) << ", \"p95\": " << format_g(percentile(t.cpu_ms, 0.95))
     << "}"
     << ",\n  \"local_mapping\": " << slam::to_json(system_->mapping_stats()) << dense_json
     << ",\n  \"memory\": " << slam::to_json(system_->memory())
     << ",\n  \"costs\": " << costs_json(costs_.samples(), costs_.every_frames(), "  ");
  const slam::LocalMappingStats mapping = system_->mapping_stats();
  text(strf("frames %zu, lost %zu, keyframes %zu, map points %zu; local BA %lld (%lld stopped by a keyframe)\n",
            t.frames, t.lost, system_->num_keyframes(), system_->num_map_points(),
            static_cast<long long>(mapping.local_ba), static_cast<long long>(mapping.local_ba_stopped)));
  print_loop_closing(&js);
  text(strf("tracking ms: median %.2f, mean %.2f, p95 %.2f; PE-match ms: median %.2f\n",
            percentile(t.tracking_ms, 0.5), mean_of(t.tracking_ms), percentile(t.tracking_ms, 0.95),
            percentile(t.pe_ms, 0.5)));
  return js.str();
}

/// With loop closing on: stats.json's "loop_closing" and its summary lines.
void OfflineSlam::Impl::print_loop_closing(std::ostringstream* js) {
  if (!system_->loop_closing_enabled()) return;
  const slam::LoopClosingStats loops = system_->loop_stats();
  *js << ",\n  \"loop_closing\": " << slam::to_json(loops);
  text(strf("loop closing: %zu loops closed (%d consistent detections, %d refused: %d by the drift bound, "
            "%d as ambiguous); detection %.2f ms median per keyframe\n",
            loops.loops.size(), loops.consistent, loops.rejected, loops.refused_drift, loops.refused_ambiguous,
            loops.detect_ms.quantile(0.5)));
  text(strf(
      "  %d candidates verified: refused %d at the descriptor matches, %d at RANSAC, %d after the guided "
      "search, %d by the correction bound; %d on their first pose, without the guided search; "
      "verification %.0f of %.0f ms\n",
      loops.verified, loops.refused_matches, loops.refused_ransac, loops.refused_inliers,
      loops.refused_correction, loops.refused_first_pose, loops.verify_ms_total, loops.detect_ms_total));
  for (const slam::LoopEvent& e : loops.loops)
    text(strf("  frame %llu (keyframe %llu) -> frame %llu (keyframe %llu): %d inliers, moved %.3f m / %.2f deg, "
              "%.0f ms\n",
              static_cast<unsigned long long>(e.frame_id), static_cast<unsigned long long>(e.keyframe_id),
              static_cast<unsigned long long>(e.loop_frame_id),
              static_cast<unsigned long long>(e.loop_keyframe_id), e.inliers, e.correction_m, e.correction_deg,
              e.detect_ms + e.correct_ms));
}

/// After everything is written: a run that stopped on bad input or never
/// initialised is an error (one line, exit 1).
void OfflineSlam::Impl::fail_if_incomplete(StopReason stop) const {
  const std::string kept = "; what was tracked is in " + a_.out;
  if (stop == StopReason::kSystemError)
    throw IoError(a_.sequence, "the SLAM core stopped after " + std::to_string(tally_.frames) + " frames: " +
                                   system_error_ + kept +
                                   (a_.map.save_path.empty() ? ""
                                                             : "; the map is not saved (" + a_.map.save_path +
                                                                   " is as it was)"));
  if (stop == StopReason::kImageSize)
    throw ConfigError(a_.settings, "Camera.width/height", image_size_error_,
                      std::to_string(settings_.K.width) + "x" + std::to_string(settings_.K.height));
  if (stop == StopReason::kTooManyMissing)
    throw IoError(a_.sequence, std::to_string(reader_.skipped()) + " frames missing or corrupt (more than " +
                                   std::to_string(reader_.max_skipped()) + ", --max-missing " +
                                   format_g(a_.max_missing) + ")" + kept);
  if (stop != StopReason::kSignal && tally_.frames > 0 && tally_.not_init == tally_.frames)
    throw IoError(a_.sequence, "tracking never initialised in " + std::to_string(tally_.frames) + " frames (" +
                                   tally_.init_failure + ")" + kept);
}

int OfflineSlam::Impl::run() {
  StopReason stop = track_frames();
  if (stop == StopReason::kSignal)
    text(strf("slam: stopped by a signal after %zu frames; writing what was tracked\n", tally_.frames));
  const std::string dense = write_final_outputs();
  if (!system_error_.empty()) stop = StopReason::kSystemError;  // also when stopping the workers failed
  std::ostringstream js;
  js << stats_json(stop, dense);
  place_ = collect_place_recognition(*system_, tally_.keyframe_t_ns);
  evaluate(&js);
  evaluate_inertial(&js);
  if (stop != StopReason::kSystemError) finish_map(&js);  // a failed core's map is not saved
  js << ",\n  \"place_recognition\": " << place_json(place_);
  if (scorer_) js << ",\n  " << scorer_->json();
  js << "\n}\n";
  write_file(a_.out + "/stats.json", js.str());
  text(strf("PE-match seed %u (%s)\n", a_.seed, a_.seed_source.c_str()));
  text(strf("wrote %s/{CameraTrajectory.txt,CameraTrajectoryRefined.txt,KeyFrameTrajectory.txt,timing.csv,costs.csv,"
            "stats.json}\n",
            a_.out.c_str()));
  fail_if_incomplete(stop);
  if (stop != StopReason::kSignal && stop_requested()) {
    // Every frame was tracked; the stop request came while the outputs
    // (the map among them) were being written, and each was finished whole.
    text("slam: stopped by a signal after the last frame; the outputs are whole\n");
    return 130;
  }
  return stop == StopReason::kSignal ? 130 : 0;
}

OfflineSlam::OfflineSlam(const OfflineSlamOptions& options) : impl_(std::make_unique<Impl>(options)) {}
OfflineSlam::~OfflineSlam() = default;
const slam::Settings& OfflineSlam::settings() const { return impl_->settings(); }
int OfflineSlam::run() { return impl_->run(); }

}  // namespace pvb::run
