#pragma once
// What a scenario run measured, and the report folder written from it:
// metrics.json (the contract in docs/run.md), plots (SVG and PNG), the
// contact sheet and index.html.  Everything here is a pure function of a
// RunReport, so tests build reports by hand and check the pieces.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pvb/eval/evaluate.hpp"
#include "pvb/eval/gravity.hpp"
#include "pvb/eval/metrics.hpp"
#include "pvb/eval/place_labels.hpp"
#include "pvb/plot/contact_sheet.hpp"
#include "pvb/report/inertial_report.hpp"
#include "pvb/report/map_report.hpp"
#include "pvb/report/map_scores.hpp"
#include "pvb/slam/core/reports.hpp"

namespace pvb::run {

/// How a run ended.
enum class RunStatus {
  kCompleted,    ///< every frame of the scenario (or of --frames) was processed
  kInterrupted,  ///< stopped by SIGINT/SIGTERM; the report is partial
  kAborted,      ///< closed loop, tracking lost and the scenario says on_loss: abort
  kFailed,       ///< tracking never initialised: nothing was tracked (the report is kept)
};
const char* to_string(RunStatus s);

/// Process exit code for a status: 0 completed, 130 interrupted (as a shell
/// reports SIGINT), 4 aborted, 1 failed.
int exit_code(RunStatus s);

/// Tracking was lost at `frame` (it was Ok, or not yet initialised, before).
struct LossEvent {
  int frame = 0;
  double t_s = 0;
  std::string reason;                  ///< from slam::TrackingStats::failure
  std::optional<int> recovered_frame;  ///< first frame tracked again (relocalised)
};

/// Per-frame record of one SLAM system.
struct FrameRecord {
  int frame = 0;
  double t_s = 0;
  bool tracked = false;
  double tracking_ms = 0;
  int coarse_matches = 0;
  int matches_kept = 0;
  std::string state;   ///< the tracking state, as timing.csv writes it ("ok", "lost", ...)
  std::string method;  ///< how the pose was found, as timing.csv writes it ("motion", "reloc", ...)
};

/// One pose against the truth: the distance between the positions and the
/// angle of the rotation between them.
struct PoseError {
  double trans_m = 0;
  double rot_deg = 0;
};

/// The stretch the camera was covered (a cover, or a kidnap's covered
/// frames) as one SLAM system came through it.
struct BlindStretch {
  int first_covered = 0, last_covered = 0;  ///< the covered frames
  int covered_processed = 0;                ///< covered frames the run processed (fewer when it ended early)
  int covered_with_pose = 0;                ///< covered frames with a pose in the trajectory
  /// Frames of the cover and the first frame after it tracked by a global
  /// relocalisation (method "reloc").
  int relocalised_frames = 0;
  std::optional<int> last_before;    ///< the last frame before the cover with a pose
  std::optional<int> first_after;    ///< the first frame after the cover, when the run processed it
  bool first_after_tracked = false;  ///< it has a pose
  std::string first_after_state, first_after_method;  ///< as timing.csv writes them
  /// The motion across the stretch, T_c(before)_c(after), estimated against
  /// true: with a pose of last_before and of first_after.
  std::optional<PoseError> first_after_error;
  /// The first frame after the cover in the ATE-aligned frame of the whole
  /// trajectory: with a pose of it and an evaluation.
  std::optional<PoseError> first_after_ate;
  int covered_frames() const { return last_covered - first_covered + 1; }
};

/// Place recognition of one run (loop closing on): what the detectors
/// did, and with ground truth, whether each match was right.
struct PlaceRecognition {
  int loops_proposed = 0;   ///< consistent detections sent to geometric verification
  int loops_accepted = 0;   ///< loops closed
  int relocalisations = 0;
  std::vector<eval::PlaceEvent> loops, relocalisation_events;  ///< as the system reported them
  /// Consistent detections the checks refused (the first ones kept by the
  /// system), each with the check; `verified` ones carry their pose and
  /// are judged like loops: a correct one is a true loop thrown away.
  struct Refusal {
    eval::PlaceEvent event;
    std::string reason;
    bool verified = false;
    double correction_m = 0, drift_bound_m = 0;
    std::optional<eval::LabelledPlaceEvent> label;  ///< verified refusals, with ground truth
  };
  std::vector<Refusal> refusals;
  int refusals_dropped = 0;
  std::vector<std::int64_t> keyframe_t_ns;                     ///< every keyframe made, in order
  eval::PlaceLabelOptions label_options;
  std::optional<eval::PlaceLabels> labels;  ///< with ground truth
};

/// The place-recognition object of metrics.json.
std::string place_json(const PlaceRecognition& p);

/// The blind object of metrics.json (docs/evaluation.md, "The blind stretch").
std::string blind_json(const BlindStretch& b);

/// One line of the run's log on the blind stretch: how many covered frames
/// have a pose and how tracking went on after it.
std::string blind_summary(const BlindStretch& b);

/// One SLAM system's dense map: how it was built and, with ground truth,
/// how each of its versions scored against the true surface.
struct DenseMapReport {
  std::size_t keyframes = 0;
  std::size_t points = 0;       ///< the corrected map, PointCloud.ply
  std::size_t live_points = 0;  ///< the live map, PointCloud_live.ply
  std::size_t pose_updates = 0;     ///< local BA and loop corrections posted to the map
  std::size_t keyframes_moved = 0;  ///< keyframes re-binned over those updates
  double update_ms_median = 0, update_ms_max = 0;
  std::vector<double> loop_update_ms;  ///< per loop correction: its re-binning time
  std::vector<std::string> files;      ///< the maps' PLY files, corrected first
  std::string alignment;               ///< how the maps went into the world (scored only)
  std::size_t surface_samples = 0;
  double truth_s = 0;            ///< sampling the true surface
  std::vector<MapResult> maps;   ///< scored maps: corrected, live, before_loop, after_loop
  std::string note;              ///< why the maps were not scored
  std::string top_view;          ///< the error figure's file name (PNG), if written
  /// The scores of map `name`, or null.
  const MapResult* find(const std::string& name) const;
};

/// The dense_map object of metrics.json.
std::string dense_map_json(const DenseMapReport& d, const std::string& in);

/// What the run costs as its map grows, sampled every CostLog::every_frames
/// frames and at the end (costs.csv; metrics.json "costs"): memory, and
/// each stage's time over the frames since the sample before.
struct CostSample {
  int frame = 0;
  double t_s = 0;
  std::size_t keyframes = 0, points = 0;  ///< in the map
  double rss_mb = 0;     ///< the whole process's resident set
  double sparse_mb = 0;  ///< keyframes (the map's and culled ones kept for the trajectory), points, bags of words
  double dense_mb = 0;   ///< the dense mapper's keyframe clouds and voxel maps
  double tracking_ms_median = 0, tracking_ms_p95 = 0;  ///< per frame, over the window
  double loop_detect_ms = 0;           ///< mean per detection over the window (0: none in it)
  double mapping_ms_per_keyframe = 0;  ///< local mapping's busy time per keyframe over the window (0: none)
  double local_ba_ms = 0;              ///< the local BAs' solver time per BA over the window (0: none)
  double dense_disk_mb = 0;  ///< what the dense mapper spilled to disk (compressed), over its memory budget
  double sparse_disk_mb = 0;  ///< far keyframes' features in the feature file (Map.spillFeatures)
};
/// The columns of costs.csv and of metrics.json's "costs" rows, in order.
const std::vector<std::string>& cost_columns();
/// A sample's values in cost_columns()' order.
std::vector<double> cost_values(const CostSample& c);
/// {"every_frames", "columns", "rows"}: the samples as rows, one a line
/// indented by `in` (metrics.json's and stats.json's "costs").
std::string costs_json(const std::vector<CostSample>& samples, int every_frames, const std::string& in);

/// One SLAM system's run (PE-SLAM, or the baseline: PE-match off, ORB-SLAM2's motion model).
struct SlamRun {
  std::string mode;  ///< eval::kPeSlamMode or eval::kBaselineMode ("pe-slam", "baseline")
  std::string sensors = "camera";  ///< slam::to_string(SensorSetup): the sensors the system fused
  /// Its name in the log: the mode's label, or with --compare-sensors its
  /// sensors (both runs share the mode there).
  std::string label;
  std::size_t frames = 0;
  std::size_t lost_frames = 0;  ///< frames in state Lost
  std::size_t not_initialized_frames = 0;
  /// Frames whose pose the motion sensors carried while vision failed
  /// (slam::TrackingState::kDeadReckoning).
  std::size_t dead_reckoned_frames = 0;
  std::string init_failure;  ///< why the last frame not initialised failed to initialise
  std::size_t keyframes = 0;
  std::size_t map_points = 0;
  std::vector<FrameRecord> per_frame;
  std::vector<LossEvent> loss_events;
  std::optional<eval::EvalResult> eval;  ///< nullopt when it could not be evaluated
  std::string eval_note;                 ///< why not, or which alignment fallback was used
  /// The trajectory re-anchored at the end on the final keyframe poses
  /// (local BA and loop closing), CameraTrajectoryRefined.txt; same alignment.
  std::optional<eval::EvalResult> refined_eval;
  std::string loop_closing_json;  ///< slam::to_json(LoopClosingStats); empty when loop closing is off
  std::optional<slam::LocalMappingStats> local_mapping;  ///< nullopt when not known
  std::size_t loops_closed = 0;
  std::optional<PlaceRecognition> place;  ///< nullopt when loop closing is off
  std::optional<DenseMapReport> dense_map;  ///< nullopt when dense mapping is off
  /// A saved map loaded or the final map saved (nullopt: neither).
  std::optional<MapReport> map;
  /// Gravity error per frame and the keyframes' pitch and roll error
  /// (docs/evaluation.md, "Gravity and tilt"); with an evaluation.
  std::optional<eval::GravityError> gravity;
  std::optional<eval::TiltDrift> tilt;
  std::optional<InertialReport> inertial;  ///< a setup with an IMU (not camera alone)
  std::optional<BlindStretch> blind;  ///< a scenario whose camera is covered for a while
  std::vector<CostSample> costs;      ///< as the map grew (empty: not sampled)
  int cost_every_frames = 0;          ///< the sampling period
};

/// Closed loop: distance of the ground-truth robot (axle centre) from the
/// route polyline, per frame.
struct ClosedLoopMetrics {
  std::vector<double> t_s;
  std::vector<double> path_error_m;
  double path_error_rmse_m = 0;
  double path_error_max_m = 0;
  int hold_frames = 0;  ///< frames the robot was held (not initialised or lost)
};

/// Where the time went: total milliseconds per stage over the run.
struct StageTime {
  std::string name;
  double total_ms = 0;
  std::size_t count = 0;  ///< how many times the stage ran (frames, keyframes, 1)
  std::string thread;     ///< "producer", "consumer", "mapping", "main"
};

/// The motion sensors against the truth: the gyroscope's yaw rate (base
/// z) and the wheel odometry alone, in the odometry frame (the base's
/// first pose), with its drift over the distance driven.
struct MotionSensorsReport {
  std::vector<double> imu_t_s, yaw_rate_measured, yaw_rate_true;  ///< rad/s
  std::vector<double> odo_t_s, odo_x_m, odo_y_m, true_x_m, true_y_m;
  std::vector<double> distance_m, drift_m;  ///< distance driven, odometry's position error
  double mean_abs_slip = 0;                 ///< over both wheels and every reading on the ground
  double end_drift_m() const { return drift_m.empty() ? 0.0 : drift_m.back(); }
  double distance_driven_m() const { return distance_m.empty() ? 0.0 : distance_m.back(); }
};

struct RunReport {
  std::string scenario;  ///< scenario name
  std::string scenario_file;
  std::uint64_t seed = 0;
  std::string world;  ///< the station and the day (world_json.hpp), a JSON object
  RunStatus status = RunStatus::kCompleted;
  std::string status_detail;  ///< one line: why interrupted or aborted
  bool sync = false;
  std::string renderer;  ///< GL backend description
  double fps = 30;
  double sim_s = 0;   ///< simulated time of the frames processed
  double wall_s = 0;  ///< wall time of the loop (setup, evaluation and report excluded)
  double cpu_s = 0;   ///< CPU time of the whole process over the same span (all threads)
  SlamRun primary;
  std::optional<SlamRun> baseline;  ///< --compare
  std::optional<ClosedLoopMetrics> closed_loop;
  std::optional<MotionSensorsReport> motion;  ///< simulated runs
  /// First and last frame of the scenario's camera cover (a kidnap), if any.
  std::optional<std::pair<int, int>> camera_covered_frames;
  std::vector<StageTime> profile;
  std::vector<plot::Thumbnail> thumbnails;  ///< for the contact sheet
  std::vector<std::string> log_lines;       ///< shown in index.html (run.log holds them too)
};

/// Distance from point p to the polyline (minimum over its segments); the
/// distance to the single point for a one-point line; +inf for an empty one.
double distance_to_polyline(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& polyline);

/// p-quantile (0..1) with linear interpolation; 0 for no values (eval/metrics.hpp).
using eval::percentile;

/// The realtime factor: simulated seconds per wall second (0 when wall_s is 0).
double realtime_factor(double sim_s, double wall_s);

/// The metrics.json document (plain JSON that yaml-cpp parses).
std::string metrics_json(const RunReport& report);

/// The two systems differ only in their sensor setup (--compare-sensors).
bool compares_sensors(const RunReport& report);

/// How the report names one of its systems: by its sensor setup when the
/// two systems differ only in it (--compare-sensors), else by its mode
/// ("PE-SLAM", "baseline (ORB-SLAM2 motion model)").
std::string system_label(const RunReport& report, const SlamRun& run);

/// The comparison's heading, the reference named second: "PE-SLAM against
/// the baseline (ORB-SLAM2 motion model)", or with --compare-sensors e.g.
/// "camera+imu+wheels against camera".
std::string comparison_heading(const RunReport& report);

/// The gravity, tilt, inertial and dead-reckoning keys of one system in
/// metrics.json, each line ending in ",\n" (as the other system keys).
std::string gravity_inertial_fields(const SlamRun& run, const std::string& indent);

/// The paper-style comparison table (PE-SLAM vs baseline, or the two
/// sensor setups, columns named by system_label): ATE and RPE statistics
/// with reductions, plus tracking time, lost and dead-reckoned frames.  Empty
/// when there is no baseline or either run has no evaluation.
std::string comparison_table(const RunReport& report);

/// Writes the figures (SVG and PNG) of one run into dir with file names
/// prefixed by `prefix`; returns the file names (without dir) written.
std::vector<std::string> write_figures(const RunReport& report, const std::string& dir);

/// index.html: summary, loss events, comparison, figures, files; relative
/// links only, no scripts.  `figures` are file names in the folder.
std::string index_html(const RunReport& report, const std::vector<std::string>& figures);

/// Writes metrics.json, the figures, contact_sheet.png and index.html into
/// dir; returns the figure names (as write_figures()).
std::vector<std::string> write_report(const RunReport& report, const std::string& dir);

}  // namespace pvb::run
