#pragma once
// The parts of a run's metrics.json (written by `pvbench run`, see
// docs/sweeps.md for the keys) that the checker and the sweep aggregation
// read.  JSON is read with yaml-cpp, which parses JSON.
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace pvb::suite {

struct LossEvent {
  int frame = -1;
  double t_s = 0.0;
  std::string reason;
  std::optional<int> recovered_frame;  ///< absent when never recovered
};

/// metrics.json's "place_recognition" (loop closing on).  The true/false
/// counts are there only when the run had ground truth.
struct PlaceMetrics {
  int loops_proposed = 0, loops_accepted = 0, relocalisations = 0;
  std::optional<int> loops_true, loops_false, loops_missed, revisits;
  std::optional<int> relocalisations_true, relocalisations_false;
};

/// One scored dense map of metrics.json's "dense_map.maps" (corrected,
/// live, before_loop, after_loop), over the whole map.
struct MapMetrics {
  std::string name;
  std::optional<double> accuracy_median_m;  ///< absent when the map had no points ("accuracy_m": null)
  double completeness_2cm = 0;  ///< share of the true surface within 2 cm
  double completeness_5cm = 0;  ///< within 5 cm
  double ghosting = 0;          ///< share of the judged surface mapped twice
};

/// metrics.json's "blind": the stretch the camera was covered (a cover or
/// a kidnap) as the run came through it.
struct BlindMetrics {
  int first_covered = 0, last_covered = 0;  ///< "covered_frames"
  int covered_with_pose = 0;                ///< covered frames with a pose
  int relocalised_frames = 0;               ///< of the cover and the first frame after it
  std::optional<int> first_after;           ///< absent when the run ended before it
  bool first_after_tracked = false;
  std::string first_after_method;  ///< "" when the run ended before it
  std::string first_after_state;
  /// The motion across the stretch against the truth ("first_after_error"),
  /// absent when it could not be measured.
  std::optional<double> first_after_error_m, first_after_error_deg;
  int covered_frames() const { return last_covered - first_covered + 1; }
};

/// One SLAM run's figures (the top level, or the "baseline" object).
struct RunMetrics {
  std::string mode;    ///< "pe-slam" or "baseline" ("orb-slam2" in version 1 files is read as "baseline")
  std::string sensors = "camera";  ///< the sensor setup the run fused (absent in older files: camera)
  std::string status;  ///< "completed", "interrupted" or "aborted"
  int frames = 0;
  int lost_frames = 0;
  std::optional<int> keyframes;            ///< the final map's; absent in files without it
  std::optional<double> ate_rmse_m;        ///< absent when "ate" is null
  std::optional<double> rpe_trans_rmse_m;  ///< absent when "rpe" is null
  std::optional<double> refined_ate_rmse_m;  ///< "refined.ate_rmse", absent when not evaluated
  std::optional<PlaceMetrics> place;       ///< absent when loop closing was off
  /// "camera_covered_frames": [first, last] of a scenario's camera cover.
  std::optional<std::pair<int, int>> camera_covered_frames;
  std::optional<BlindMetrics> blind;  ///< absent in runs whose camera was never covered
  std::optional<double> tracking_ms_median;
  std::optional<double> realtime_factor;
  std::vector<LossEvent> loss_events;
  std::vector<MapMetrics> maps;  ///< empty when the dense maps were not scored
  /// The scores of map `name` (e.g. "corrected"), or null.
  const MapMetrics* map(const std::string& name) const;
};

struct MetricsFile {
  std::string path;
  int version = 1;  ///< "metrics_version" (absent in version 1 files)
  std::string scenario;
  std::optional<unsigned long long> seed;
  /// The station a day's run was made at ("world": "station_seed" and the
  /// first of "base_files"); absent in runs of a scenario without a station.
  std::optional<unsigned long long> station_seed;
  std::string station_file;
  RunMetrics primary;                  ///< the top-level run (PE-SLAM with --compare)
  std::optional<RunMetrics> baseline;  ///< only with --compare
};

/// Refuses the metrics of another run: throws ConfigError naming the file
/// and the key when its "scenario" is not `scenario` (unless that is empty;
/// `scenario_source` says where the expected name comes from, e.g. the
/// scenario file) or its "seed" is not `seed` (unless nullopt).
void expect_run_identity(const MetricsFile& m, const std::string& scenario, const std::string& scenario_source,
                         std::optional<unsigned long long> seed, const std::string& seed_source = "");

/// The scenario name and seed a run or recording folder says it was made
/// from: its metrics.json ("scenario", "seed") or else its meta.json
/// ("scenario": {"name"}, "seed").  nullopt when the folder holds neither.
struct FolderIdentity {
  std::string file;      ///< the file read
  std::string scenario;  ///< "" when the file names none
  std::optional<unsigned long long> seed;
  std::optional<unsigned long long> station_seed;  ///< metrics.json's "world", when there
  std::string station_file;
};
std::optional<FolderIdentity> read_folder_identity(const std::string& dir);

/// Reads and checks the shape of a metrics.json.  Throws IoError naming the
/// file and the key when the file is missing, is not JSON, or a required key
/// (status, frames, lost_frames, ate, rpe) is missing or of the wrong type.
MetricsFile read_metrics_file(const std::string& path);

}  // namespace pvb::suite
