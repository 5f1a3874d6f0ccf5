// pvbench slam: runs PE-SLAM (or its ORB-SLAM2 baseline) on a TUM RGB-D
// folder and writes trajectories, per-frame timing and run statistics; with
// a groundtruth.txt in the folder it also evaluates ATE and RPE.  Unless
// disabled, the dense map goes to PointCloud.ply.
#include <algorithm>
#include <ctime>
#include <cstdio>
#include <fstream>
#include <memory>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "command.hpp"
#include "stop_signals.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/progress.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/harness/matching/ground_truth.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"
#include "pvb/slam/dense/point_cloud.hpp"

namespace pvb::cli {
namespace {

struct SlamArgs {
  std::string sequence;
  std::string settings;
  std::string out;
  bool no_pe_match = false;
  bool sync = false;
  bool no_dense = false;
  std::uint32_t seed = 1;
  std::size_t max_frames = 0;
  double max_missing = 0.1;
  bool dump_matches = false;
  bool dump_map = false;
};

/// Ground-truth scoring of the motion model's coarse matches (--dump-matches):
/// each match (last frame -> this frame) is labelled by harness/matching's
/// label_by_rgbd from the last frame's depth and the ground-truth motion
/// between the two frames; written per match to motion_matches.csv and
/// summed for stats.json.
class MotionMatchScorer {
 public:
  MotionMatchScorer(const std::string& out_dir, const std::string& gt_path, const slam::Settings& s)
      : gt_path_(gt_path), csv_(out_dir + "/motion_matches.csv") {
    if (!csv_) throw IoError(out_dir + "/motion_matches.csv", "cannot open for writing");
    csv_ << "frame,octave1,octave2,u1,v1,u2,v2,label,pe_keep,pose_inlier\n";
    gt_.K = s.K;
    if (s.has_distortion()) gt_.dist_coeffs = (cv::Mat_<double>(1, 5) << s.k1, s.k2, s.p1, s.p2, s.k3);
    gt_.threshold_px = kThresholdPx;
  }

  /// Scores the motion matches of `frame` (tracked as `r`) against the previous frame.
  void add(const sensor::RgbdFrame& frame, const slam::FrameResult& r) {
    const geom::SE3d T_w_c = harness::tum_pose_at(gt_path_, static_cast<double>(frame.t_ns) * 1e-9);
    const auto& m = r.tracking.motion;
    if (prev_depth_m_.empty() || m.undistorted.empty()) {
      remember(frame, T_w_c);
      return;
    }
    gt_.depth1_m = prev_depth_m_;
    gt_.depth2_m = frame.depth_m;
    gt_.T_c2_c1 = T_w_c.inverse() * prev_T_w_c_;
    const std::vector<harness::MatchLabel> labels = harness::label_by_rgbd(m.raw, m.undistorted, gt_);
    for (std::size_t k = 0; k < labels.size(); ++k) {
      const int label = static_cast<int>(labels[k]);
      const int keep = m.pe_keep[k];
      const int inlier = k < m.pose_inlier.size() ? m.pose_inlier[k] : 0;
      csv_ << frame.index << "," << m.octaves[k][0] << "," << m.octaves[k][1] << "," << m.undistorted[k].p1.x()
           << "," << m.undistorted[k].p1.y() << "," << m.undistorted[k].p2.x() << "," << m.undistorted[k].p2.y()
           << "," << label << "," << keep << "," << inlier << "\n";
      if (labels[k] == harness::MatchLabel::kUnknown) continue;
      const bool correct = labels[k] == harness::MatchLabel::kCorrect;
      (correct ? correct_ : wrong_) += 1;
      if (keep) (correct ? kept_correct_ : kept_wrong_) += 1;
      if (inlier) (correct ? inlier_correct_ : inlier_wrong_) += 1;
    }
    csv_.flush();
    remember(frame, T_w_c);
  }

  /// "motion_matches": {...} for stats.json.
  std::string json() const {
    const auto ratio = [](long a, long b) { return b > 0 ? static_cast<double>(a) / static_cast<double>(b) : 0.0; };
    std::ostringstream js;
    js << "\"motion_matches\": {\"threshold_px\": " << kThresholdPx << ", \"correct\": " << correct_
       << ", \"wrong\": " << wrong_ << ", \"kept_correct\": " << kept_correct_ << ", \"kept_wrong\": " << kept_wrong_
       << ", \"pe_precision\": " << fmt(ratio(kept_correct_, kept_correct_ + kept_wrong_))
       << ", \"pe_recall\": " << fmt(ratio(kept_correct_, correct_))
       << ", \"pose_inlier_correct\": " << inlier_correct_ << ", \"pose_inlier_wrong\": " << inlier_wrong_ << "}";
    return js.str();
  }

 private:
  static constexpr double kThresholdPx = 4.0;  ///< reprojection error of a correct match
  static std::string fmt(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
  }
  void remember(const sensor::RgbdFrame& frame, const geom::SE3d& T_w_c) {
    prev_depth_m_ = frame.depth_m.clone();
    prev_T_w_c_ = T_w_c;
  }

  std::string gt_path_;
  std::ofstream csv_;
  harness::RgbdGroundTruth gt_;
  cv::Mat prev_depth_m_;
  geom::SE3d prev_T_w_c_ = geom::SE3d::Identity();
  long correct_ = 0, wrong_ = 0, kept_correct_ = 0, kept_wrong_ = 0, inlier_correct_ = 0, inlier_wrong_ = 0;
};

/// CPU time of the calling thread in ms (unlike wall time, not inflated
/// when other processes share the cores).
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

std::ofstream open_out(const std::string& path) {
  std::ofstream f(path);
  if (!f) throw IoError(path, "cannot open for writing");
  return f;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = p * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

void write_tum_file(const std::string& path, const std::vector<geom::StampedPose>& poses) {
  std::string text = "# timestamp tx ty tz qx qy qz qw (T_w_c)\n";
  for (const auto& p : poses) text += geom::format_tum_line(p) + "\n";
  write_file(path, text);
}

int run_slam(const SlamArgs& a) {
  slam::Settings settings = slam::read_settings(a.settings);
  for (const std::string& w : settings.warnings) std::fprintf(stderr, "pvbench slam: warning: %s\n", w.c_str());
  if (a.no_pe_match) settings.pe_match.enabled = false;
  if (a.no_dense) settings.dense.enabled = false;
  dataset::TumSequenceReader reader(a.sequence, settings.depth_map_factor);
  dataset::make_dirs(a.out);

  slam::SystemOptions options;
  options.synchronous = a.sync;
  options.seed = a.seed;
  slam::System system(settings, options);

  std::ofstream cam_traj = open_out(a.out + "/CameraTrajectory.txt");
  std::ofstream kf_traj = open_out(a.out + "/KeyFrameTrajectory.txt");
  std::ofstream timing = open_out(a.out + "/timing.csv");
  cam_traj << "# timestamp tx ty tz qx qy qz qw (T_w_c)\n";
  kf_traj << "# timestamp tx ty tz qx qy qz qw (T_w_c)\n";
  timing << "frame,t_s,state,method,features,tracking_ms,orb_ms,pe_match_ms,coarse_matches,matches_kept,"
            "inliers,keyframe,mapping_ms,cpu_ms,align_tried,aligned,align_ms,"
            "kf_tracked_close,kf_untracked_close,kf_ref_points,kf_ref_all,kf_ref_shared\n";

  std::unique_ptr<MotionMatchScorer> scorer;
  if (a.dump_matches) {
    const std::string gt = a.sequence + "/groundtruth.txt";
    if (!std::ifstream(gt)) throw IoError(gt, "--dump-matches needs the sequence's ground truth");
    scorer = std::make_unique<MotionMatchScorer>(a.out, gt, settings);
  }

  const std::size_t total = a.max_frames ? std::min(a.max_frames, reader.size_hint()) : reader.size_hint();
  ProgressBar bar(std::string("slam") + (settings.pe_match.enabled ? " (PE-match)" : " (baseline)"), total);
  std::vector<double> tracking_ms, pe_ms;
  std::vector<double> cpu_ms_all;  ///< caller-thread CPU per frame: tracking, plus inline mapping in sync mode
  std::size_t frames = 0, lost = 0, not_init = 0;
  const std::size_t max_missing =
      std::max<std::size_t>(5, static_cast<std::size_t>(a.max_missing * static_cast<double>(reader.size_hint())));
  // Ctrl-C (or SIGTERM) stops taking frames; everything tracked so far is
  // still written and evaluated, and the exit code is 130.
  const StopSignals stop_signals;
  while ((frames < total || total == 0) && !StopSignals::requested()) {
    std::optional<sensor::RgbdFrame> frame = reader.next();
    if (!frame) break;
    if (reader.skipped() > max_missing) {
      system.shutdown();  // keep the partial dense map too
      if (system.dense_enabled()) system.write_point_cloud(a.out + "/PointCloud.ply");
      throw IoError(a.sequence, std::to_string(reader.skipped()) + " frames missing or corrupt (more than " +
                                    std::to_string(max_missing) + "); the trajectory so far is in " + a.out);
    }
    const double cpu0_ms = thread_cpu_ms();
    const slam::FrameResult r = system.track(*frame);
    const double cpu_ms = thread_cpu_ms() - cpu0_ms;
    cpu_ms_all.push_back(cpu_ms);
    ++frames;
    if (r.state == slam::TrackingState::kLost) ++lost;
    if (r.state == slam::TrackingState::kNotInitialized) ++not_init;
    tracking_ms.push_back(r.tracking_ms);
    if (settings.pe_match.enabled && r.tracking.method == slam::TrackingMethod::kMotionModel)
      pe_ms.push_back(r.tracking.pe_match_ms);
    if (r.T_w_c) cam_traj << geom::format_tum_line({r.t_ns, *r.T_w_c}) << "\n" << std::flush;
    if (r.tracking.new_keyframe && r.T_w_c)
      kf_traj << geom::format_tum_line({r.t_ns, *r.T_w_c}) << "\n" << std::flush;
    static const char* kMethods[] = {"none", "init", "motion", "refkf", "reloc"};
    timing << frame->index << "," << geom::format_tum_time(r.t_ns) << "," << slam::to_string(r.state) << ","
           << kMethods[static_cast<int>(r.tracking.method)] << "," << r.num_features << ","
           << fmt(r.tracking_ms) << "," << fmt(r.orb_ms) << "," << fmt(r.tracking.pe_match_ms) << ","
           << r.tracking.coarse_matches << "," << r.tracking.matches_kept << "," << r.tracking.inliers << ","
           << (r.tracking.new_keyframe ? 1 : 0) << "," << fmt(r.mapping_ms) << "," << fmt(cpu_ms) << ","
           << r.tracking.align_tried << "," << r.tracking.aligned << "," << fmt(r.tracking.align_ms) << ","
           << r.tracking.kf_tracked_close << "," << r.tracking.kf_untracked_close << ","
           << r.tracking.kf_ref_points << "," << r.tracking.kf_ref_all << "," << r.tracking.kf_ref_shared
           << "\n"
           << std::flush;
    if (scorer) scorer->add(*frame, r);
    bar.update(frames, slam::to_string(r.state));
  }
  bar.finish();
  const bool interrupted = StopSignals::requested();
  if (interrupted) std::printf("slam: stopped by a signal after %zu frames; writing what was tracked\n", frames);
  system.shutdown();
  kf_traj.close();
  // Rewrite the keyframe trajectory with the poses refined by local BA
  // (culled keyframes are left out, as ORB-SLAM2 does).
  write_tum_file(a.out + "/KeyFrameTrajectory.txt", system.keyframe_trajectory());
  // ORB-SLAM2's way of saving: each frame relative to its (refined) reference keyframe.
  write_tum_file(a.out + "/CameraTrajectoryRefined.txt", system.refined_trajectory());
  if (a.dump_map) {
    std::ofstream map_out = open_out(a.out + "/Map.txt");
    slam::write_map_snapshot(system.map_snapshot(), map_out, a.out + "/Map.txt");
  }
  cam_traj.close();
  std::size_t cloud_points = 0;
  if (system.dense_enabled()) cloud_points = system.write_point_cloud(a.out + "/PointCloud.ply");
  const slam::dense::DenseMapperStats dense_stats = system.dense_stats();

  const double mean = tracking_ms.empty() ? 0 : std::accumulate(tracking_ms.begin(), tracking_ms.end(), 0.0) /
                                                      static_cast<double>(tracking_ms.size());
  std::ostringstream js;
  js << "{\n  \"sequence\": \"" << json_escape(a.sequence)
     << "\",\n  \"pe_match\": " << (settings.pe_match.enabled ? "true" : "false")
     << ",\n  \"sync\": " << (a.sync ? "true" : "false") << ",\n  \"seed\": " << a.seed
     << ",\n  \"interrupted\": " << (interrupted ? "true" : "false") << ",\n  \"frames\": " << frames
     << ",\n  \"lost_frames\": " << lost << ",\n  \"not_initialized_frames\": " << not_init
     << ",\n  \"skipped_frames\": " << reader.skipped() << ",\n  \"keyframes\": " << system.num_keyframes()
     << ",\n  \"map_points\": " << system.num_map_points()
     << ",\n  \"tracking_ms\": {\"median\": " << fmt(percentile(tracking_ms, 0.5))
     << ", \"mean\": " << fmt(mean) << ", \"p95\": " << fmt(percentile(tracking_ms, 0.95))
     << "},\n  \"pe_match_ms\": {\"median\": " << fmt(percentile(pe_ms, 0.5))
     << ", \"p95\": " << fmt(percentile(pe_ms, 0.95)) << "}"
     << ",\n  \"cpu_ms\": {\"median\": " << fmt(percentile(cpu_ms_all, 0.5)) << ", \"mean\": "
     << fmt(cpu_ms_all.empty() ? 0.0
                               : std::accumulate(cpu_ms_all.begin(), cpu_ms_all.end(), 0.0) /
                                     static_cast<double>(cpu_ms_all.size()))
     << ", \"p95\": " << fmt(percentile(cpu_ms_all, 0.95)) << "}"
     << ",\n  \"local_mapping\": " << slam::to_json(system.mapping_stats());
  if (system.dense_enabled()) {
    const double per_kf_ms =
        dense_stats.keyframes ? dense_stats.total_ms / static_cast<double>(dense_stats.keyframes) : 0.0;
    js << ",\n  \"dense\": {\"keyframes\": " << dense_stats.keyframes << ", \"points\": " << cloud_points
       << ", \"keyframe_points\": " << dense_stats.points << ", \"ms_per_keyframe\": " << fmt(per_kf_ms)
       << ", \"resolution_m\": " << fmt(settings.dense.resolution_m) << "}";
    std::printf("dense map: %zu points from %zu keyframes (%.1f ms per keyframe) -> %s/PointCloud.ply\n",
                cloud_points, dense_stats.keyframes, per_kf_ms, a.out.c_str());
  }
  const slam::LocalMappingStats mapping = system.mapping_stats();
  std::printf(
      "frames %zu, lost %zu, keyframes %zu, map points %zu; local BA %lld (%lld stopped by a keyframe)\n",
      frames, lost, system.num_keyframes(), system.num_map_points(), static_cast<long long>(mapping.local_ba),
      static_cast<long long>(mapping.local_ba_stopped));
  if (system.loop_closing_enabled()) {
    const slam::LoopClosingStats loops = system.loop_stats();
    js << ",\n  \"loop_closing\": " << slam::to_json(loops);
    std::printf("loop closing: %zu loops closed (%d consistent detections, %d refused by geometry)\n",
                loops.loops.size(), loops.consistent, loops.rejected);
    for (const slam::LoopEvent& e : loops.loops)
      std::printf("  frame %llu (keyframe %llu) -> frame %llu (keyframe %llu): %d inliers, moved %.3f m / %.2f deg, "
                  "%.0f ms\n",
                  static_cast<unsigned long long>(e.frame_id), static_cast<unsigned long long>(e.keyframe_id),
                  static_cast<unsigned long long>(e.loop_frame_id), static_cast<unsigned long long>(e.loop_keyframe_id),
                  e.inliers, e.correction_m, e.correction_deg, e.detect_ms + e.correct_ms);
  }
  std::printf("tracking ms: median %.2f, mean %.2f, p95 %.2f; PE-match ms: median %.2f\n",
              percentile(tracking_ms, 0.5), mean, percentile(tracking_ms, 0.95), percentile(pe_ms, 0.5));

  const std::string gt_path = a.sequence + "/groundtruth.txt";
  if (std::ifstream(gt_path)) {
    try {
      const eval::Trajectory gt = eval::read_tum(gt_path);
      const eval::Trajectory est = eval::read_tum(a.out + "/CameraTrajectory.txt");
      eval::EvalOptions eo;
      eval::EvalResult res;
      try {
        res = eval::evaluate(gt, est, eo);
      } catch (const eval::EvalError& e) {
        // Only a numerically degenerate set lands here (a robot that never
        // moved, fewer than 3 poses); nearly straight drives align with se3.
        // The SLAM estimate starts at its first frame, so align that instead.
        std::fprintf(stderr, "pvbench slam: note: se3 alignment impossible (%s); using origin alignment\n", e.what());
        eo.alignment = eval::Alignment::kOrigin;
        res = eval::evaluate(gt, est, eo);
      }
      std::printf("\n%s", eval::format_report(res).c_str());
      std::string ev = eval::format_json(res);
      const std::size_t open = ev.find('{'), close = ev.rfind('}');
      ev = ev.substr(open + 1, close - open - 1);
      while (!ev.empty() && (ev.back() == '\n' || ev.back() == ' ')) ev.pop_back();
      js << "," << ev;
      try {
        const eval::EvalResult ref =
            eval::evaluate(gt, eval::read_tum(a.out + "/CameraTrajectoryRefined.txt"), eo);
        std::printf("refined trajectory (frames re-anchored to bundle-adjusted keyframes): ATE RMSE %.4f m\n",
                    ref.ate.rmse);
        js << ",\n  \"refined\": {\"ate_rmse\": " << fmt(ref.ate.rmse) << ", \"rpe_trans_rmse\": "
           << fmt(ref.rpe_trans_m.rmse) << "}";
      } catch (const Error& e) {
        std::fprintf(stderr, "pvbench slam: warning: refined trajectory not evaluated: %s\n", e.what());
      }
    } catch (const Error& e) {
      std::fprintf(stderr, "pvbench slam: warning: no evaluation: %s\n", e.what());
    }
  }
  if (scorer) js << ",\n  " << scorer->json();
  js << "\n}\n";
  write_file(a.out + "/stats.json", js.str());
  std::printf("wrote %s/{CameraTrajectory.txt,CameraTrajectoryRefined.txt,KeyFrameTrajectory.txt,timing.csv,stats.json}\n", a.out.c_str());
  return interrupted ? 130 : 0;
}

}  // namespace

Command add_slam_command(CLI::App& app) {
  auto args = std::make_shared<SlamArgs>();
  CLI::App* sub = app.add_subcommand("slam", "run PE-SLAM (RGB-D) on a TUM-format sequence folder");
  sub->add_option("--sequence", args->sequence, "TUM RGB-D sequence folder")->required();
  sub->add_option("--settings", args->settings, "ORB-SLAM2 RGB-D settings YAML (plus optional PEMatch.*)")
      ->required();
  sub->add_option("--out", args->out, "output folder")->required();
  sub->add_flag("--no-pe-match", args->no_pe_match, "baseline: ORB-SLAM2 motion model without PE-match");
  sub->add_flag("--no-dense", args->no_dense, "skip the dense point-cloud map (PointCloud.ply)");
  sub->add_flag("--sync", args->sync, "synchronous mode: no worker threads, bit-identical runs");
  sub->add_option("--seed", args->seed, "PE-match seed")->capture_default_str();
  sub->add_option("--max-frames", args->max_frames, "stop after this many frames (0: all)")->capture_default_str();
  sub->add_flag("--dump-matches", args->dump_matches,
                "score the motion model's coarse matches against groundtruth.txt: motion_matches.csv, "
                "stats.json motion_matches");
  sub->add_flag("--dump-map", args->dump_map,
                "write the final sparse map with every keypoint measurement to Map.txt (for pvbench map-check)");
  sub->add_option("--max-missing", args->max_missing, "stop when more than this share of frames is missing")
      ->capture_default_str();
  return {sub, [args] { return run_slam(*args); }};
}

}  // namespace pvb::cli
