// `pvbench slam`'s evaluation: the trajectories against the sequence's
// ground truth (ATE, RPE, gravity, the inertial state), the localisation in
// a loaded map and the map saved, and place recognition's labels.
#include <fstream>
#include <sstream>

#include "offline_slam_impl.hpp"

namespace pvb::run {

/// Evaluates CameraTrajectory.txt (and the refined one) against the
/// sequence's groundtruth.txt, when there is one; prints the report and
/// appends its fields to stats.json.  A failed evaluation is a warning.
void OfflineSlam::Impl::evaluate(std::ostringstream* js) {
  const std::string gt_path = a_.sequence + "/groundtruth.txt";
  if (!std::ifstream(gt_path) || tally_.poses == 0) return;
  try {
    const eval::Trajectory gt = eval::read_tum(gt_path);
    const eval::Trajectory est = eval::read_tum(a_.out + "/CameraTrajectory.txt");
    eval::EvalOptions eo;
    eval::EvalResult res;
    try {
      res = eval::evaluate(gt, est, eo);
    } catch (const eval::EvalError& e) {
      // Only a numerically degenerate set lands here (a robot that never
      // moved, fewer than 3 poses); straight drives align with se3.
      // The SLAM estimate starts at its first frame, so align that instead.
      warn(std::string("note: se3 alignment impossible (") + e.what() + "); using origin alignment");
      eo.alignment = eval::Alignment::kOrigin;
      res = eval::evaluate(gt, est, eo);
    }
    text("\n" + eval::format_report(res));
    label_places(gt);
    std::string ev = eval::format_json(res);
    const std::size_t open = ev.find('{'), close = ev.rfind('}');
    ev = ev.substr(open + 1, close - open - 1);
    while (!ev.empty() && (ev.back() == '\n' || ev.back() == ' ')) ev.pop_back();
    *js << "," << ev;
    evaluate_refined(gt, eo, js);
    evaluate_gravity(gt, est, res.alignment, js);
  } catch (const Error& e) {
    warn(std::string("warning: no evaluation: ") + e.what());
  }
}

void OfflineSlam::Impl::evaluate_refined(const eval::Trajectory& gt, const eval::EvalOptions& eo,
                                         std::ostringstream* js) {
  try {
    const eval::EvalResult ref = eval::evaluate(gt, eval::read_tum(a_.out + "/CameraTrajectoryRefined.txt"), eo);
    text(strf("refined trajectory (frames re-anchored to bundle-adjusted keyframes): ATE RMSE %.4f m\n",
              ref.ate.rmse));
    *js << ",\n  \"refined\": {\"ate_rmse\": " << format_g(ref.ate.rmse)
        << ", \"rpe_trans_rmse\": " << format_g(ref.rpe_trans_m.rmse) << "}";
  } catch (const Error& e) {
    warn(std::string("warning: refined trajectory not evaluated: ") + e.what());
  }
}

void OfflineSlam::Impl::evaluate_gravity(const eval::Trajectory& gt, const eval::Trajectory& est,
                                         const eval::Sim3Transform& alignment, std::ostringstream* js) {
  // A pvbench recording's world is the site frame (z up); a TUM download's
  // the mocap world, whose up was measured from the Kinect's accelerometer.
  const bool site = std::ifstream(a_.sequence + "/meta.json").good();
  const geom::Vec3d down_w = site ? geom::Vec3d(0, 0, -1) : geom::Vec3d(-dataset::tum_world_up());
  const eval::GravityError g =
      eval::gravity_error(gt, est, down_w, gravity_map_frame(settings_.motion.setup), tally_.gravity);
  const eval::TiltDrift t =
      eval::tilt_drift(gt, session_keyframes(eval::read_tum(a_.out + "/KeyFrameTrajectory.txt"), *system_), alignment);
  const slam::MapGravity core = system_->gravity();
  if (core.ready) gravity_true_deg_ = gravity_error_at_deg(gt, est, down_w, tally_.gravity, core.ready_t_ns);
  // Without an accelerometer the map's frame is the first camera's: its -z
  // is no estimate of gravity, and the angle is that camera's tilt.
  const bool aligned = sensor::uses_accel(settings_.motion.setup);
  text(strf("%s (map frame: %s): median %.2f deg, p95 %.2f, final %.2f; keyframe pitch error "
            "%+.4f deg/keyframe, roll %+.4f\n",
            aligned ? "gravity error" : "tilt of the first camera's frame, not a gravity error", g.map_frame.c_str(),
            g.median_deg, g.p95_deg, g.final_deg, t.pitch_slope_deg_per_kf, t.roll_slope_deg_per_kf));
  *js << ",\n  \"gravity\": " << eval::gravity_json(g) << ",\n  \"tilt\": " << eval::tilt_json(t);
}

void OfflineSlam::Impl::evaluate_inertial(std::ostringstream* js) {
  if (!sensor::uses_accel(settings_.motion.setup) || tally_.frame_t_ns.empty()) return;
  const std::int64_t t0_ns = tally_.frame_t_ns.front();
  InertialReport r = inertial_report(system_->gravity(), t0_ns);
  if (r.trusted) r.gravity_true_deg = gravity_true_deg_;
  std::vector<KeyframeBias> kfs;
  for (const slam::System::KeyFrameState& k : system_->keyframe_states())
    kfs.push_back({k.id, k.t_ns, k.bias});
  const std::string truth_path = a_.sequence + "/imu0/truth.csv";
  if (!kfs.empty() && std::ifstream(truth_path)) {
    try {
      const std::vector<BiasTruth> truth = read_bias_truth(truth_path);
      if (!truth.empty())
        r.biases = compare_biases(std::move(kfs), truth, t0_ns, sensor::uses_imu(settings_.motion.setup));
    } catch (const IoError& e) {
      warn(std::string("warning: biases not compared: ") + e.what());
    }
  }
  if (system_->calibrates_wheels()) {
    r.wheels = system_->wheels();
    const std::string robot_truth = a_.sequence + "/robot_truth.yaml";
    try {
      if (std::ifstream(robot_truth)) r.wheels_true = read_wheels_true(robot_truth);
    } catch (const IoError& e) {
      warn(std::string("warning: wheel calibration not compared: ") + e.what());
    }
    text(wheels_text(*r.wheels, r.wheels_true));
  }
  const std::string truth =
      r.gravity_true_deg ? strf(", %.2f deg off the true down (ground truth)", *r.gravity_true_deg) : "";
  text(
      r.trusted
          ? strf(
                "inertial state trusted at t = %.2f s (keyframe %llu): gravity %.2f deg off the map's -z%s\n",
                r.trusted_t_s, static_cast<unsigned long long>(r.trusted_keyframe), r.gravity_tilt_deg,
                truth.c_str())
          : std::string("inertial state not trusted by the end\n"));
  if (r.biases)
    text(strf("bias error RMS over %zu keyframes: gyro %.5f rad/s, accel %.4f m/s^2\n", r.biases->t_s.size(),
              r.biases->gyro_rms_radps, r.biases->accel_rms_mps2));
  *js << ",\n  \"inertial\": " << inertial_json(r);
}

void OfflineSlam::Impl::finish_map(std::ostringstream* js) {
  if (!map_) return;
  const std::string gt_path = a_.sequence + "/groundtruth.txt";
  // The ground truth at the frames' times: every frame counts once.
  const eval::Trajectory gt =
      std::ifstream(gt_path) ? ground_truth_at(eval::read_tum(gt_path), tally_.frame_t_ns) : eval::Trajectory{};
  const eval::Trajectory est =
      tally_.poses > 0 ? eval::read_tum(a_.out + "/CameraTrajectory.txt") : eval::Trajectory{};
  run::finish_map(*system_, a_.map, gt, est, a_.sequence, &*map_);
  for (const std::string& line : map_log_lines(*map_)) text(line + "\n");
  *js << ",\n  \"map\": " << map_report_json(*map_);
}

void OfflineSlam::Impl::label_places(const eval::Trajectory& gt) {
  label_place_recognition(&place_, gt);
  const eval::PlaceLabels& l = *place_.labels;
  text(strf("place recognition: loops %d true, %d false, %d missed of %zu true revisits; "
            "relocalisations %d true, %d false\n",
            l.loops_true, l.loops_false, l.loops_missed, l.revisits.size(), l.relocalisations_true,
            l.relocalisations_false));
}

}  // namespace pvb::run
