// pvbench slam: runs PE-SLAM (or its ORB-SLAM2 baseline) on a TUM RGB-D
// folder and writes trajectories, per-frame timing and run statistics; with
// a groundtruth.txt in the folder it also evaluates ATE and RPE.  Unless
// disabled, the dense map goes to PointCloud.ply.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "command.hpp"
#include "count_option.hpp"
#include "io_plan.hpp"
#include "map_options.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/progress.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/harness/matching/ground_truth.hpp"
#include "pvb/run/map_eval.hpp"
#include "pvb/run/place_recognition.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"
#include "pvb/slam/dense/point_cloud.hpp"
#include "pvb/suite/metrics_file.hpp"
#include "stop_signals.hpp"
#include "trajectory_output.hpp"

namespace pvb::cli {
namespace {

constexpr std::uint32_t kDefaultSeed = 1;  ///< a sequence that names no seed (a TUM download)

struct SlamArgs {
  std::string sequence;
  std::string settings;
  std::string out;
  bool overwrite = false;
  bool no_pe_match = false;
  bool sync = false;
  bool no_dense = false;
  std::optional<std::uint32_t> seed;  ///< --seed; else the recording's own, else kDefaultSeed
  std::string seed_source;            ///< where the seed used came from, for the log and stats.json
  long long max_frames = 0;           ///< frames to track, 0: all (a negative count is an error, not a wrap)
  double max_missing = 0.1;
  bool dump_matches = false;
  bool dump_map = false;
  run::MapOptions map;
  std::string map_mode;
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
    csv_.append("frame,octave1,octave2,u1,v1,u2,v2,label,pe_keep,pose_inlier\n");
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
    std::ostringstream rows;
    for (std::size_t k = 0; k < labels.size(); ++k) {
      const int label = static_cast<int>(labels[k]);
      const int keep = m.pe_keep[k];
      const int inlier = k < m.pose_inlier.size() ? m.pose_inlier[k] : 0;
      rows << frame.index << "," << m.octaves[k][0] << "," << m.octaves[k][1] << ","
           << m.undistorted[k].p1.x() << "," << m.undistorted[k].p1.y() << "," << m.undistorted[k].p2.x()
           << "," << m.undistorted[k].p2.y() << "," << label << "," << keep << "," << inlier << "\n";
      if (labels[k] == harness::MatchLabel::kUnknown) continue;
      const bool correct = labels[k] == harness::MatchLabel::kCorrect;
      (correct ? correct_ : wrong_) += 1;
      if (keep) (correct ? kept_correct_ : kept_wrong_) += 1;
      if (inlier) (correct ? inlier_correct_ : inlier_wrong_) += 1;
    }
    csv_.append(rows.str());
    remember(frame, T_w_c);
  }

  /// "motion_matches": {...} for stats.json.
  std::string json() const {
    const auto ratio = [](long a, long b) {
      return b > 0 ? static_cast<double>(a) / static_cast<double>(b) : 0.0;
    };
    std::ostringstream js;
    js << "\"motion_matches\": {\"threshold_px\": " << kThresholdPx << ", \"correct\": " << correct_
       << ", \"wrong\": " << wrong_ << ", \"kept_correct\": " << kept_correct_
       << ", \"kept_wrong\": " << kept_wrong_
       << ", \"pe_precision\": " << format_g(ratio(kept_correct_, kept_correct_ + kept_wrong_))
       << ", \"pe_recall\": " << format_g(ratio(kept_correct_, correct_))
       << ", \"pose_inlier_correct\": " << inlier_correct_ << ", \"pose_inlier_wrong\": " << inlier_wrong_
       << "}";
    return js.str();
  }

 private:
  static constexpr double kThresholdPx = 4.0;  ///< reprojection error of a correct match
  void remember(const sensor::RgbdFrame& frame, const geom::SE3d& T_w_c) {
    prev_depth_m_ = frame.depth_m.clone();
    prev_T_w_c_ = T_w_c;
  }

  std::string gt_path_;
  OutputFile csv_;
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

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = p * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

/// Why the frame loop ended.
enum class StopReason {
  kEnd,             ///< every frame of the sequence (or --max-frames of them)
  kSignal,          ///< Ctrl-C or SIGTERM
  kTooManyMissing,  ///< more than --max-missing of the frames skipped
  kImageSize,       ///< an image differs from Camera.width x Camera.height
};

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
  }
  return "?";
}

/// Counts and per-frame series of one run.
struct Tally {
  std::size_t frames = 0, lost = 0, not_init = 0, poses = 0;
  std::vector<double> tracking_ms, pe_ms;
  std::vector<double> cpu_ms;  ///< caller-thread CPU per frame: tracking, plus inline mapping in sync mode
  std::string init_failure;    ///< why the last frame failed to initialise
  std::vector<std::int64_t> keyframe_t_ns;  ///< every keyframe made
  std::vector<std::int64_t> frame_t_ns;     ///< every frame tracked
};

double mean_of(const std::vector<double>& v) {
  return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

/// One `pvbench slam` run, in stages: inputs and outputs are opened by the
/// constructor, run() tracks, writes the final outputs and stats.json, and
/// then reports a run that stopped early or never initialised as an error
/// (after everything is written).
class SlamRun {
 public:
  explicit SlamRun(const SlamArgs& a);
  int run();

 private:
  void open_outputs();
  StopReason track_frames();
  slam::TrackingState track_one(const sensor::RgbdFrame& frame);
  std::string write_final_outputs();
  std::string stats_json(StopReason stop, const std::string& dense_json);
  void evaluate(std::ostringstream* js);
  /// Labels the loops and relocalisations against `gt` and prints them.
  void label_places(const eval::Trajectory& gt);
  void fail_if_incomplete(StopReason stop) const;
  /// Scores localisation in a loaded map and saves the final map; appends stats.json's "map".
  void finish_map(std::ostringstream* js);

  const SlamArgs& a_;
  slam::Settings settings_;
  dataset::TumSequenceReader reader_;
  std::unique_ptr<slam::System> system_;
  OutputFile cam_traj_, kf_traj_, timing_;
  std::unique_ptr<MotionMatchScorer> scorer_;
  Tally tally_;
  run::PlaceRecognition place_;        ///< collected after the run, labelled when there is ground truth
  std::string image_size_error_;       ///< set when the loop stopped on an image of the wrong size
  std::optional<run::MapReport> map_;  ///< with --map or --save-map
};

/// Missing frames always allowed, whatever --max-missing says.
constexpr std::size_t kMinMissingAllowed = 5;

slam::Settings settings_for(const SlamArgs& a) {
  if (a.max_frames < 0)
    throw ConfigError("command line", "--max-frames", "a number of frames >= 0 (0: all)",
                      std::to_string(a.max_frames));
  if (!(a.max_missing >= 0.0 && a.max_missing <= 1.0))  // NaN fails too
    throw ConfigError("command line", "--max-missing", "a share of the frames in [0, 1]",
                      format_g(a.max_missing));
  slam::Settings settings = slam::read_settings(a.settings);
  for (const std::string& w : settings.warnings)
    std::fprintf(stderr, "pvbench slam: warning: %s\n", w.c_str());
  if (a.no_pe_match) settings.pe_match.enabled = false;
  if (a.no_dense) settings.dense.enabled = false;
  return settings;
}

/// What slam reads and writes, checked before any work: no output lands on
/// a file of the sequence, the settings, their vocabulary or the map.
void check_slam_paths(const SlamArgs& a, const slam::Settings& settings) {
  IoPlan plan;
  add_sequence_inputs(&plan, "--sequence", a.sequence);
  plan.input("the --settings file", a.settings).input("the --map file", a.map.load_path);
  if (settings.vocabulary_path != "none")
    plan.input("the vocabulary of the --settings file", settings.vocabulary_path);
  plan.output_folder("--out", a.out).output_file("--save-map", a.map.save_path);
  plan.check();
  check_output_folder(a.out, a.overwrite);
}

SlamRun::SlamRun(const SlamArgs& a)
    : a_(a), settings_(settings_for(a)), reader_(a.sequence, settings_.depth_map_factor) {
  // One rule for missing frames (docs/slam.md): more than --max-missing of
  // the sequence's frames, and more than 5, ends the run.
  reader_.set_max_skipped(std::max<std::size_t>(
      kMinMissingAllowed,
      static_cast<std::size_t>(std::floor(a.max_missing * static_cast<double>(reader_.size_hint())))));
  a.map.check();
  check_slam_paths(a, settings_);
  slam::SystemOptions options;
  options.synchronous = a.sync;
  options.seed = *a.seed;
  system_ = std::make_unique<slam::System>(settings_, options);
  // The map is read (and refused when bad) before the folder is made.
  if (!a.map.load_path.empty() || !a.map.save_path.empty()) map_ = run::start_map(*system_, a.map);
  prepare_output_folder(a.out, a.overwrite, "slam");
  open_outputs();
}

void SlamRun::open_outputs() {
  cam_traj_ = OutputFile(a_.out + "/CameraTrajectory.txt");
  kf_traj_ = OutputFile(a_.out + "/KeyFrameTrajectory.txt");
  timing_ = OutputFile(a_.out + "/timing.csv");
  cam_traj_.append("# timestamp tx ty tz qx qy qz qw (T_w_c)\n");
  kf_traj_.append("# timestamp tx ty tz qx qy qz qw (T_w_c)\n");
  timing_.append(
      "frame,t_s,state,method,features,tracking_ms,orb_ms,pe_match_ms,coarse_matches,matches_kept,"
      "inliers,keyframe,mapping_ms,cpu_ms,align_tried,aligned,align_ms,"
      "kf_tracked_close,kf_untracked_close,kf_ref_points,kf_ref_all,kf_ref_shared\n");
  if (a_.dump_matches) {
    const std::string gt = a_.sequence + "/groundtruth.txt";
    if (!std::ifstream(gt)) throw IoError(gt, "--dump-matches needs the sequence's ground truth");
    scorer_ = std::make_unique<MotionMatchScorer>(a_.out, gt, settings_);
  }
}

StopReason SlamRun::track_frames() {
  const std::size_t n = reader_.size_hint();
  const std::size_t total = a_.max_frames > 0 ? std::min(static_cast<std::size_t>(a_.max_frames), n) : n;
  ProgressBar bar(std::string("slam") + (settings_.pe_match.enabled ? " (PE-match)" : " (baseline)"), total);
  StopReason stop = StopReason::kEnd;
  while (tally_.frames < total) {
    if (StopSignals::requested()) {
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
    const slam::TrackingState state = track_one(*frame);
    bar.update(tally_.frames, slam::to_string(state));
  }
  if (stop == StopReason::kEnd && StopSignals::requested()) stop = StopReason::kSignal;
  bar.finish();
  return stop;
}

slam::TrackingState SlamRun::track_one(const sensor::RgbdFrame& frame) {
  const double cpu0_ms = thread_cpu_ms();
  const slam::FrameResult r = system_->track(frame);
  const double cpu_ms = thread_cpu_ms() - cpu0_ms;
  tally_.cpu_ms.push_back(cpu_ms);
  tally_.frame_t_ns.push_back(frame.t_ns);
  ++tally_.frames;
  if (r.state == slam::TrackingState::kLost) ++tally_.lost;
  if (r.state == slam::TrackingState::kNotInitialized) {
    ++tally_.not_init;
    tally_.init_failure = r.tracking.failure;
  }
  tally_.tracking_ms.push_back(r.tracking_ms);
  if (settings_.pe_match.enabled && r.tracking.method == slam::TrackingMethod::kMotionModel)
    tally_.pe_ms.push_back(r.tracking.pe_match_ms);
  if (r.T_w_c) {
    cam_traj_.append(geom::format_tum_line({r.t_ns, *r.T_w_c}) + "\n");
    ++tally_.poses;
  }
  if (r.tracking.new_keyframe && r.T_w_c) {
    kf_traj_.append(geom::format_tum_line({r.t_ns, *r.T_w_c}) + "\n");
    tally_.keyframe_t_ns.push_back(r.t_ns);
  }
  static const char* kMethods[] = {"none", "init", "motion", "refkf", "reloc"};
  std::ostringstream line;
  line << frame.index << "," << geom::format_tum_time(r.t_ns) << "," << slam::to_string(r.state) << ","
       << kMethods[static_cast<int>(r.tracking.method)] << "," << r.num_features << ","
       << format_g(r.tracking_ms) << "," << format_g(r.orb_ms) << "," << format_g(r.tracking.pe_match_ms)
       << "," << r.tracking.coarse_matches << "," << r.tracking.matches_kept << "," << r.tracking.inliers
       << "," << (r.tracking.new_keyframe ? 1 : 0) << "," << format_g(r.mapping_ms) << "," << format_g(cpu_ms)
       << "," << r.tracking.align_tried << "," << r.tracking.aligned << "," << format_g(r.tracking.align_ms)
       << "," << r.tracking.kf_tracked_close << "," << r.tracking.kf_untracked_close << ","
       << r.tracking.kf_ref_points << "," << r.tracking.kf_ref_all << "," << r.tracking.kf_ref_shared << "\n";
  timing_.append(line.str());
  if (scorer_) scorer_->add(frame, r);
  return r.state;
}

/// Stops the workers and writes the outputs that exist only at the end (the
/// refined keyframe and frame trajectories, Map.txt, PointCloud.ply).
/// Returns the "dense" part of stats.json (empty when dense mapping is off).
std::string SlamRun::write_final_outputs() {
  system_->shutdown();
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
  const run::NamedClouds maps = run::dense_maps(*system_);
  run::write_dense_maps(maps, a_.out);
  const std::size_t cloud_points = maps.front().second.size();
  const slam::dense::DenseMapperStats dense = system_->dense_stats();
  const double per_kf_ms = dense.keyframes ? dense.total_ms / static_cast<double>(dense.keyframes) : 0.0;
  std::printf("dense map: %zu points from %zu keyframes (%.1f ms per keyframe) -> %s/PointCloud.ply\n",
              cloud_points, dense.keyframes, per_kf_ms, a_.out.c_str());
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

/// Evaluates CameraTrajectory.txt (and the refined one) against the
/// sequence's groundtruth.txt, when there is one; prints the report and
/// appends its fields to stats.json.  A failed evaluation is a warning.
void SlamRun::evaluate(std::ostringstream* js) {
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
      // moved, fewer than 3 poses); nearly straight drives align with se3.
      // The SLAM estimate starts at its first frame, so align that instead.
      std::fprintf(stderr, "pvbench slam: note: se3 alignment impossible (%s); using origin alignment\n",
                   e.what());
      eo.alignment = eval::Alignment::kOrigin;
      res = eval::evaluate(gt, est, eo);
    }
    std::printf("\n%s", eval::format_report(res).c_str());
    label_places(gt);
    std::string ev = eval::format_json(res);
    const std::size_t open = ev.find('{'), close = ev.rfind('}');
    ev = ev.substr(open + 1, close - open - 1);
    while (!ev.empty() && (ev.back() == '\n' || ev.back() == ' ')) ev.pop_back();
    *js << "," << ev;
    try {
      const eval::EvalResult ref =
          eval::evaluate(gt, eval::read_tum(a_.out + "/CameraTrajectoryRefined.txt"), eo);
      std::printf("refined trajectory (frames re-anchored to bundle-adjusted keyframes): ATE RMSE %.4f m\n",
                  ref.ate.rmse);
      *js << ",\n  \"refined\": {\"ate_rmse\": " << format_g(ref.ate.rmse)
          << ", \"rpe_trans_rmse\": " << format_g(ref.rpe_trans_m.rmse) << "}";
    } catch (const Error& e) {
      std::fprintf(stderr, "pvbench slam: warning: refined trajectory not evaluated: %s\n", e.what());
    }
  } catch (const Error& e) {
    std::fprintf(stderr, "pvbench slam: warning: no evaluation: %s\n", e.what());
  }
}

void SlamRun::finish_map(std::ostringstream* js) {
  if (!map_) return;
  const std::string gt_path = a_.sequence + "/groundtruth.txt";
  // The ground truth at the frames' times: every frame counts once.
  const eval::Trajectory gt = std::ifstream(gt_path)
                                  ? run::ground_truth_at(eval::read_tum(gt_path), tally_.frame_t_ns)
                                  : eval::Trajectory{};
  const eval::Trajectory est =
      tally_.poses > 0 ? eval::read_tum(a_.out + "/CameraTrajectory.txt") : eval::Trajectory{};
  run::finish_map(*system_, a_.map, gt, est, a_.sequence, &*map_);
  for (const std::string& line : run::map_log_lines(*map_)) std::printf("%s\n", line.c_str());
  *js << ",\n  \"map\": " << run::map_report_json(*map_);
}

void SlamRun::label_places(const eval::Trajectory& gt) {
  run::label_place_recognition(&place_, gt);
  const eval::PlaceLabels& l = *place_.labels;
  std::printf(
      "place recognition: loops %d true, %d false, %d missed of %zu true revisits; "
      "relocalisations %d true, %d false\n",
      l.loops_true, l.loops_false, l.loops_missed, l.revisits.size(), l.relocalisations_true,
      l.relocalisations_false);
}

/// The run's counts, timings and mapping statistics for stats.json (without
/// the closing brace), printing the summary lines on the way.
std::string SlamRun::stats_json(StopReason stop, const std::string& dense_json) {
  const Tally& t = tally_;
  std::ostringstream js;
  js << "{\n  \"sequence\": \"" << json_escape(a_.sequence)
     << "\",\n  \"pe_match\": " << (settings_.pe_match.enabled ? "true" : "false")
     << ",\n  \"sync\": " << (a_.sync ? "true" : "false") << ",\n  \"seed\": " << *a_.seed
     << ",\n  \"seed_source\": \"" << json_escape(a_.seed_source) << "\""
     << ",\n  \"interrupted\": " << (stop == StopReason::kSignal ? "true" : "false") << ",\n  \"stop\": \""
     << stop_name(stop) << "\",\n  \"frames\": " << t.frames << ",\n  \"lost_frames\": " << t.lost
     << ",\n  \"not_initialized_frames\": " << t.not_init << ",\n  \"skipped_frames\": " << reader_.skipped()
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
     << ",\n  \"memory\": " << slam::to_json(system_->memory());
  const slam::LocalMappingStats mapping = system_->mapping_stats();
  std::printf(
      "frames %zu, lost %zu, keyframes %zu, map points %zu; local BA %lld (%lld stopped by a keyframe)\n",
      t.frames, t.lost, system_->num_keyframes(), system_->num_map_points(),
      static_cast<long long>(mapping.local_ba), static_cast<long long>(mapping.local_ba_stopped));
  if (system_->loop_closing_enabled()) {
    const slam::LoopClosingStats loops = system_->loop_stats();
    js << ",\n  \"loop_closing\": " << slam::to_json(loops);
    std::printf(
        "loop closing: %zu loops closed (%d consistent detections, %d refused: %d by the drift bound, "
        "%d as ambiguous); detection %.2f ms median per keyframe\n",
        loops.loops.size(), loops.consistent, loops.rejected, loops.refused_drift, loops.refused_ambiguous,
        percentile(loops.detect_ms, 0.5));
    std::printf(
        "  %d candidates verified: refused %d at the descriptor matches, %d at RANSAC, %d after the guided "
        "search, %d by the correction bound; verification %.0f of %.0f ms\n",
        loops.verified, loops.refused_matches, loops.refused_ransac, loops.refused_inliers,
        loops.refused_correction, loops.verify_ms_total, loops.detect_ms_total);
    for (const slam::LoopEvent& e : loops.loops)
      std::printf(
          "  frame %llu (keyframe %llu) -> frame %llu (keyframe %llu): %d inliers, moved %.3f m / %.2f deg, "
          "%.0f ms\n",
          static_cast<unsigned long long>(e.frame_id), static_cast<unsigned long long>(e.keyframe_id),
          static_cast<unsigned long long>(e.loop_frame_id),
          static_cast<unsigned long long>(e.loop_keyframe_id), e.inliers, e.correction_m, e.correction_deg,
          e.detect_ms + e.correct_ms);
  }
  std::printf("tracking ms: median %.2f, mean %.2f, p95 %.2f; PE-match ms: median %.2f\n",
              percentile(t.tracking_ms, 0.5), mean_of(t.tracking_ms), percentile(t.tracking_ms, 0.95),
              percentile(t.pe_ms, 0.5));
  return js.str();
}

/// After everything is written: a run that stopped on bad input or never
/// initialised is an error (one line, exit 1).
void SlamRun::fail_if_incomplete(StopReason stop) const {
  const std::string kept = "; what was tracked is in " + a_.out;
  if (stop == StopReason::kImageSize)
    throw ConfigError(a_.settings, "Camera.width/height", image_size_error_,
                      std::to_string(settings_.K.width) + "x" + std::to_string(settings_.K.height));
  if (stop == StopReason::kTooManyMissing)
    throw IoError(a_.sequence, std::to_string(reader_.skipped()) + " frames missing or corrupt (more than " +
                                   std::to_string(reader_.max_skipped()) + ", --max-missing " +
                                   format_g(a_.max_missing) + ")" + kept);
  if (stop != StopReason::kSignal && tally_.frames > 0 && tally_.not_init == tally_.frames)
    throw IoError(a_.sequence, "tracking never initialised in " + std::to_string(tally_.frames) +
                                   " frames (" + tally_.init_failure + ")" + kept);
}

int SlamRun::run() {
  // Ctrl-C (or SIGTERM) stops taking frames; everything tracked so far is
  // still written and evaluated, and the exit code is 130.
  const StopSignals stop_signals;
  const StopReason stop = track_frames();
  if (stop == StopReason::kSignal)
    std::printf("slam: stopped by a signal after %zu frames; writing what was tracked\n", tally_.frames);
  const std::string dense_json = write_final_outputs();
  std::ostringstream js;
  js << stats_json(stop, dense_json);
  place_ = run::collect_place_recognition(*system_, tally_.keyframe_t_ns);
  evaluate(&js);
  finish_map(&js);
  js << ",\n  \"place_recognition\": " << run::place_json(place_);
  if (scorer_) js << ",\n  " << scorer_->json();
  js << "\n}\n";
  write_file(a_.out + "/stats.json", js.str());
  std::printf("PE-match seed %u (%s)\n", *a_.seed, a_.seed_source.c_str());
  std::printf(
      "wrote "
      "%s/{CameraTrajectory.txt,CameraTrajectoryRefined.txt,KeyFrameTrajectory.txt,timing.csv,stats.json}\n",
      a_.out.c_str());
  fail_if_incomplete(stop);
  if (stop != StopReason::kSignal && StopSignals::requested()) {
    // Every frame was tracked; the signal came while the outputs (the map
    // among them) were being written, and each was finished whole.
    std::printf("slam: stopped by a signal after the last frame; the outputs are whole\n");
    return 130;
  }
  return stop == StopReason::kSignal ? 130 : 0;
}

/// PE-match's seed: --seed, else the seed the recording was made with (its
/// meta.json, as pvbench record writes it, or a run folder's metrics.json),
/// so that a replay is the run it recorded; else kDefaultSeed.
void resolve_seed(SlamArgs* a) {
  if (a->seed) {
    a->seed_source = "--seed";
  } else if (const auto id = suite::read_folder_identity(a->sequence); id && id->seed) {
    a->seed = static_cast<std::uint32_t>(*id->seed);  // as pvbench run and record seed PE-match
    a->seed_source = id->file;
  } else {
    a->seed = kDefaultSeed;
    a->seed_source = "default";
  }
}

int run_slam(SlamArgs a) {
  if (!a.map_mode.empty()) a.map.use = run::parse_map_use(a.map_mode, "--map-mode");
  resolve_seed(&a);
  // A map of another station than the recording's is used after a warning.
  a.map.station = run::recording_station(a.sequence + "/meta.json");
  a.map.allow_other_station = true;
  SlamRun run(a);
  return run.run();
}

}  // namespace

Command add_slam_command(CLI::App& app) {
  auto args = std::make_shared<SlamArgs>();
  CLI::App* sub = app.add_subcommand("slam", "run PE-SLAM (RGB-D) on a TUM-format sequence folder");
  sub->add_option("--sequence", args->sequence, "TUM RGB-D sequence folder")
      ->required()
      ->check(path_check("slam", "--sequence"));
  sub->add_option("--settings", args->settings, "ORB-SLAM2 RGB-D settings YAML (plus optional PEMatch.*)")
      ->required()
      ->check(path_check("slam", "--settings"));
  sub->add_option("--out", args->out, "output folder (created; refused when not empty)")
      ->required()
      ->check(path_check("slam", "--out"));
  sub->add_flag("--overwrite", args->overwrite, "empty an earlier pvbench output in --out first");
  sub->add_flag("--no-pe-match", args->no_pe_match, "baseline: ORB-SLAM2 motion model without PE-match");
  sub->add_flag("--no-dense", args->no_dense, "skip the dense point-cloud map (PointCloud.ply)");
  sub->add_flag("--sync", args->sync, "synchronous mode: no worker threads, bit-identical runs");
  sub->add_option("--seed", args->seed,
                  "PE-match seed (default: the recording's own seed from its meta.json, else 1)")
      ->check(seed_check("slam", "--seed"));
  sub->add_option("--max-frames", args->max_frames, "stop after this many frames (0: all)")
      ->capture_default_str();
  sub->add_flag("--dump-matches", args->dump_matches,
                "score the motion model's coarse matches against groundtruth.txt: motion_matches.csv, "
                "stats.json motion_matches");
  sub->add_flag(
      "--dump-map", args->dump_map,
      "write the final sparse map with every keypoint measurement to Map.txt (for pvbench map-check)");
  sub->add_option(
         "--max-missing", args->max_missing,
         "stop (exit 1, outputs kept) when more than this share of the frames, 0 to 1, and more than 5 "
         "frames are missing or corrupt")
      ->capture_default_str();
  add_map_options(sub, &args->map, &args->map_mode);
  return {sub, [args] { return run_slam(*args); }};
}

}  // namespace pvb::cli
