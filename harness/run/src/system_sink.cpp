#include "system_sink.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/gravity.hpp"
#include "pvb/eval/slam_mode.hpp"
#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/run/place_events.hpp"
#include "pvb/run/sensor_setup.hpp"

namespace pvb::run {
namespace {

/// Loss and recovery: a loss event when tracking is lost (from Ok or not
/// initialised), its recovery when it is Ok again, and the log lines of
/// those and of initialisation.
void record_state_change(SlamRun& run, slam::TrackingState prev_state, const slam::FrameResult& r, int index,
                         double t_s, RunLog& log) {
  char head_buf[96];
  std::snprintf(head_buf, sizeof head_buf, "frame %d (t = %.3f s): %s ", index, t_s, run.mode.c_str());
  const std::string head = head_buf;
  const std::string reason = r.tracking.failure.empty() ? "no reason given" : r.tracking.failure;
  const auto kDead = slam::TrackingState::kDeadReckoning;
  if (r.state == kDead && prev_state != kDead) {
    log.line(head + "vision lost, the motion sensors carry the pose: " + reason);
  } else if (r.state == slam::TrackingState::kOk && prev_state == kDead) {
    log.line(head + "vision back: tracking resumed against the local map");
  } else if (r.state == slam::TrackingState::kLost && prev_state != slam::TrackingState::kLost) {
    run.loss_events.push_back({index, t_s, reason, std::nullopt});
    log.line(head + std::string("lost tracking: ") + reason);
  } else if (r.state == slam::TrackingState::kOk && prev_state == slam::TrackingState::kLost) {
    if (!run.loss_events.empty()) run.loss_events.back().recovered_frame = index;
    const bool carried = r.tracking.method == slam::TrackingMethod::kCarriedRestart;
    log.line(head + std::string(r.tracking.method == slam::TrackingMethod::kInitialization
                                    ? "began a provisional map (lost in the loaded map for too long)"
                                : carried ? "tracking begun again at the pose the wheels carried (new points)"
                                          : "relocalised"));
  } else if (r.state == slam::TrackingState::kNotInitialized && run.frames == 1) {
    log.line(head + "not initialised: " + reason);
  } else if (r.state == slam::TrackingState::kOk && prev_state == slam::TrackingState::kNotInitialized) {
    log.line(head + (r.tracking.two_view_points > 0
                         ? "initialised from two views (" + std::to_string(r.tracking.two_view_points) +
                               " points, scaled by " + std::to_string(r.tracking.two_view_scale_points) +
                               " measured depths)"
                         : std::string("initialised")));
  }
}

void write_tum(const std::string& path, const std::string& header,
               const std::vector<geom::StampedPose>& poses) {
  write_file(path, geom::format_tum(poses, header));
}

}  // namespace

SystemSink::SystemSink(const std::string& mode, const slam::Settings& settings, bool sync, std::uint32_t seed,
                       const std::string& out_dir, const MapOptions& map)
    : map_options(map), dir(out_dir) {
  run.mode = mode;
  run.sensors = sensor::to_string(settings.motion.setup);
  run.label = eval::mode_label(mode);
  slam::SystemOptions options;
  options.synchronous = sync;
  options.seed = seed;
  system = std::make_unique<slam::System>(settings, options);
  if (!map.load_path.empty() || !map.save_path.empty()) run.map = start_map(*system, map);
  prev_state = system->state();  // lost in a loaded map until it relocalises
  loss_log = LossLog(mode, prev_state == slam::TrackingState::kLost);
}

void SystemSink::open_outputs() {
  dataset::make_dirs(dir);
  cam_traj = OutputFile(dir + "/CameraTrajectory.txt");
  kf_traj = OutputFile(dir + "/KeyFrameTrajectory.txt");
  timing = OutputFile(dir + "/timing.csv");
  cam_traj.append("# timestamp tx ty tz qx qy qz qw (T_w_c; w = camera frame of the first tracked frame)\n");
  kf_traj.append("# timestamp tx ty tz qx qy qz qw (T_w_c)\n");
  timing.append(
      "frame,t_s,state,method,features,tracking_ms,orb_ms,pe_match_ms,coarse_matches,matches_kept,inliers,"
      "keyframe,mapping_ms,features_with_depth,depth_valid,local_keyframes,local_points\n");
  est.source = dir + "/CameraTrajectory.txt";
  costs.open(dir + "/costs.csv");
}

slam::FrameResult SystemSink::track(const sensor::RgbdFrame& frame, RunLog& log) {
  const slam::FrameResult r = system->track(frame);
  if (!first_t_ns) first_t_ns = frame.t_ns;
  const int index = static_cast<int>(frame.index);
  const double t_s = geom::ns_to_seconds(frame.t_ns);
  count(r, index, t_s);
  costs.frame(*system, index, t_s, r.tracking_ms);
  if (r.tracking.new_keyframe) keyframe_t_ns.push_back(r.t_ns);
  eval::record_gravity(&gravity_estimates, r.t_ns, r.g_w);
  write_lines(r, index);
  for (const std::string& l : loss_log.frame(index, t_s, r.state == slam::TrackingState::kLost, r.tracking.failure,
                                             slam::to_string(r.tracking.reloc_failure)))
    log.line(l);
  record_state_change(run, prev_state, r, index, t_s, log);
  if (prev_provisional && r.T_w_c)
    log.line("frame " + std::to_string(index) + ": the provisional map was merged into the loaded map");
  if (system->sensors() != sensor::SensorSetup::kCamera && !inertial_logged) log_inertial_state(index, log);
  prev_state = r.state;
  prev_provisional = r.provisional;
  return r;
}

void SystemSink::log_inertial_state(int index, RunLog& log) {
  const slam::MapGravity g = system->gravity();
  if (!g.ready) return;
  inertial_logged = true;
  const double tilt_deg = std::acos(std::clamp(-g.g_w.normalized().z(), -1.0, 1.0)) * 180.0 / M_PI;
  log.line("frame " + std::to_string(index) + ": inertial state trusted (" + sensor::to_string(system->sensors()) +
           ", keyframe " + std::to_string(g.ready_keyframe_id) + " at t = " +
           format_fixed(geom::ns_to_seconds(g.ready_t_ns), 3) + " s): gravity " + format_fixed(tilt_deg, 3) +
           " deg off the map's -z, gyro bias " + format_fixed(g.bias.gyro_radps.norm(), 5) + " rad/s, accel bias " +
           format_fixed(g.bias.accel_mps2.norm(), 4) + " m/s^2, whitened RMS " + format_fixed(g.init_rms, 2));
}

void SystemSink::count(const slam::FrameResult& r, int index, double t_s) {
  ++run.frames;
  if (r.state == slam::TrackingState::kLost) ++run.lost_frames;
  if (r.state == slam::TrackingState::kDeadReckoning) ++run.dead_reckoned_frames;
  if (r.state == slam::TrackingState::kNotInitialized) {
    ++run.not_initialized_frames;
    run.init_failure = r.tracking.failure;
  }
  tracking_ms += r.tracking_ms;
  orb_ms += r.orb_ms;
  inline_mapping_ms += r.mapping_ms;
  run.per_frame.push_back({index, t_s, r.T_w_c.has_value(), r.tracking_ms, r.tracking.coarse_matches,
                           r.tracking.matches_kept, slam::to_string(r.state),
                           slam::to_string(r.tracking.method)});
}

void SystemSink::write_lines(const slam::FrameResult& r, int index) {
  if (r.T_w_c) {
    cam_traj.append(geom::format_tum_line({r.t_ns, *r.T_w_c}) + "\n");
    est.poses.push_back({r.t_ns, *r.T_w_c});
    if (r.tracking.new_keyframe) kf_traj.append(geom::format_tum_line({r.t_ns, *r.T_w_c}) + "\n");
  }
  std::ostringstream line;
  line << index << "," << geom::format_tum_time(r.t_ns) << "," << slam::to_string(r.state) << ","
       << slam::to_string(r.tracking.method) << "," << r.num_features << ","
       << format_g(r.tracking_ms) << "," << format_g(r.orb_ms) << "," << format_g(r.tracking.pe_match_ms)
       << "," << r.tracking.coarse_matches << "," << r.tracking.matches_kept << "," << r.tracking.inliers
       << "," << (r.tracking.new_keyframe ? 1 : 0) << "," << format_g(r.mapping_ms) << ","
       << r.features_with_depth << "," << format_fixed(r.depth_valid, 4) << "," << r.tracking.local_keyframes
       << "," << r.tracking.local_points << "\n";
  timing.append(line.str());
}

void SystemSink::end_losses(RunLog& log) {
  for (const std::string& l : loss_log.finish()) log.line(l);
}

void SystemSink::finish() {
  costs.finish(*system);
  run.costs = costs.samples();
  run.cost_every_frames = costs.every_frames();
  try {
    system->shutdown();
  } catch (const IoError& e) {  // a worker's full disk: the trajectories so far are still written
    if (failure.empty()) failure = e.what();
  }
  kf_traj.close();
  keyframes.source = dir + "/KeyFrameTrajectory.txt";
  keyframes.poses = system->keyframe_trajectory();
  write_tum(keyframes.source,
            "# timestamp tx ty tz qx qy qz qw (T_w_c, refined by local BA; culled keyframes left out)\n",
            keyframes.poses);
  // Each frame re-anchored on its reference keyframe's final pose (local
  // BA, loop closing), as ORB-SLAM2 saves its trajectory.
  refined.source = dir + "/CameraTrajectoryRefined.txt";
  refined.poses = system->refined_trajectory();
  write_tum(refined.source,
            "# timestamp tx ty tz qx qy qz qw (T_w_c, re-anchored on the final keyframe poses)\n",
            refined.poses);
  if (system->loop_closing_enabled()) {
    const slam::LoopClosingStats loops = system->loop_stats();
    run.loop_closing_json = slam::to_json(loops);
    run.loops_closed = loops.loops.size();
  }
  run.place = collect_place_recognition(*system, keyframe_t_ns);
  cam_traj.close();
  timing.close();
  run.keyframes = system->num_keyframes();
  run.map_points = system->num_map_points();
  run.local_mapping = system->mapping_stats();
  if (system->dense_enabled()) save_dense_maps();
}

void SystemSink::save_dense_maps() {
  dense_files = write_dense_maps(*system, dir);
  const slam::dense::DenseMapperStats st = system->dense_stats();
  DenseMapReport d;
  d.keyframes = st.keyframes;
  d.points = dense_files[0].points;
  d.live_points = dense_files[1].points;
  d.pose_updates = st.pose_updates;
  d.keyframes_moved = st.keyframes_moved;
  d.update_ms_median = percentile(st.update_ms, 0.5);
  d.update_ms_max = st.update_ms.empty() ? 0.0 : *std::max_element(st.update_ms.begin(), st.update_ms.end());
  d.loop_update_ms = st.loop_update_ms;
  for (const DenseMapFile& f : dense_files) d.files.push_back(f.file);
  run.dense_map = std::move(d);
}

void SystemSink::finish_map(const eval::Trajectory& gt, const std::string& scenario,
                            const std::string& scenario_file) {
  if (run.map) run::finish_map(*system, map_options, gt, est, scenario, &*run.map, scenario_file);
}

void SystemSink::evaluate(const eval::Trajectory& gt) {
  if (run.place) label_place_recognition(&*run.place, gt);
  if (est.poses.size() < 3) {
    run.eval_note = "only " + std::to_string(est.poses.size()) + " tracked frames (need 3)";
    return;
  }
  eval::EvalOptions eo;
  try {
    run.eval = eval::evaluate(gt, est, eo);
  } catch (const eval::EvalError& e) {
    // A numerically degenerate set (a robot that did not move; straight
    // drives align with se3): the SLAM world is its first camera frame, so
    // align that instead.
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
  if (run.eval) evaluate_gravity(gt);
}

void SystemSink::evaluate_gravity(const eval::Trajectory& gt) {
  // The run's ground truth is in the site frame: z up.
  run.gravity = eval::gravity_error(gt, est, geom::Vec3d(0, 0, -1), gravity_map_frame(system->sensors()),
                                   gravity_estimates);
  run.tilt = eval::tilt_drift(gt, session_keyframes(keyframes, *system), run.eval->alignment);
  const slam::MapGravity g = system->gravity();
  if (g.ready)
    gravity_true_deg = gravity_error_at_deg(gt, est, geom::Vec3d(0, 0, -1), gravity_estimates, g.ready_t_ns);
}

void SystemSink::evaluate_inertial(const std::vector<BiasTruth>& truth,
                                   const std::optional<slam::WheelCalibration>& wheels_true) {
  const sensor::SensorSetup setup = system->sensors();
  if (!sensor::uses_accel(setup)) return;
  const std::int64_t t0_ns = first_t_ns.value_or(0);
  InertialReport r = inertial_report(system->gravity(), t0_ns);
  if (r.trusted) r.gravity_true_deg = gravity_true_deg;
  std::vector<KeyframeBias> kfs;
  for (const slam::System::KeyFrameState& k : system->keyframe_states())
    kfs.push_back({k.id, k.t_ns, k.bias});
  if (!truth.empty() && !kfs.empty())
    r.biases = compare_biases(std::move(kfs), truth, t0_ns, sensor::uses_imu(setup));
  if (system->calibrates_wheels()) {
    r.wheels = system->wheels();
    r.wheels_true = wheels_true;
  }
  run.inertial = std::move(r);
}

SystemSinks make_systems(const slam::Settings& settings, const RunOptions& opt, std::uint32_t seed,
                         const MapOptions& map) {
  SystemSinks sinks;
  slam::Settings s = settings;
  s.loop.enabled = s.loop.enabled && opt.loop_closing;
  s.pe_match.enabled = opt.mode != SlamMode::kBaseline;
  if (opt.compare_sensors) apply_sensor_setup(&s, opt.compare_sensors->second);
  sinks.push_back(std::make_unique<SystemSink>(s.pe_match.enabled ? eval::kPeSlamMode : eval::kBaselineMode,
                                               s, opt.sync, seed, opt.out_dir, map));
  if (opt.mode == SlamMode::kCompare) {
    s.pe_match.enabled = false;
    MapOptions baseline_map = map;  // starts from the same map; only the primary run saves
    baseline_map.save_path.clear();
    sinks.push_back(std::make_unique<SystemSink>(eval::kBaselineMode, s, opt.sync, seed,
                                                 opt.out_dir + "/baseline", baseline_map));
  } else if (opt.compare_sensors) {
    apply_sensor_setup(&s, opt.compare_sensors->first);  // the reference setup, same PE-match
    MapOptions reference_map = map;
    reference_map.save_path.clear();
    sinks.push_back(std::make_unique<SystemSink>(sinks.front()->run.mode, s, opt.sync, seed,
                                                 opt.out_dir + "/baseline", reference_map));
    for (auto& sink : sinks) {  // both runs have one mode: each is named by its sensors
      sink->run.label = sink->run.sensors;
      sink->loss_log = LossLog(sink->run.sensors, sink->prev_state == slam::TrackingState::kLost);
    }
  }
  return sinks;
}

}  // namespace pvb::run
