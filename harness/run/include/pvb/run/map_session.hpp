#pragma once
// A run that starts from a saved map or leaves one (docs/map_reuse.md):
// which map, how it is used (localise in it, extend it), where the result
// is saved, and the map's frame in the world, kept in the map file's
// application data so that a later session can be judged against ground
// truth in that frame without any alignment.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pvb/eval/localisation.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/slam/core/system.hpp"

namespace pvb::run {

/// How a run uses a saved map.
enum class MapUse { kFresh, kLocalise, kExtend };
const char* to_string(MapUse u);
/// "localise" or "extend"; anything else throws ConfigError naming `option`.
MapUse parse_map_use(const std::string& text, const std::string& option);

struct MapOptions {
  std::string load_path;           ///< the saved map to start from (empty: a fresh map)
  MapUse use = MapUse::kFresh;     ///< kLocalise or kExtend with load_path
  std::string save_path;           ///< where to save the final map (empty: not saved)
  /// Checks the combination: a use needs a map and a map a use, and a map
  /// only localised in is not saved again.  Throws ConfigError.
  void check() const;
};

/// What a run did with maps, for metrics.json and the report.
struct MapReport {
  std::string loaded_from;
  MapUse use = MapUse::kFresh;
  std::optional<slam::MapLoadInfo> load;
  /// The map's frame in the world (its first session's first camera), from
  /// the loaded map's data or, for a new map, the ground truth.
  std::optional<geom::SE3d> T_world_map;
  std::string saved_to;
  std::optional<slam::MapSaveInfo> save;
  std::string save_note;  ///< why a map to save was not saved (none: the run made no keyframe)
  std::size_t relocalisations = 0;                        ///< tracking found again (the first pose included)
  /// Provisional maps (begun while lost outside the loaded map) merged into it.
  std::size_t merges = 0;
  /// Times each loaded landmark had been matched when the map was loaded,
  /// by id: what this session matched is the difference at its end.
  std::map<std::uint64_t, int> found_at_load;
  /// The landmarks this session matched, by the surface they lie on in
  /// the map's own day (sim::SurfaceClass names, "unlabelled" beyond 5 cm
  /// of any); empty when not classified.
  std::vector<std::pair<std::string, int>> matched_landmarks;
  std::string matched_landmarks_note;  ///< why they were not classified
  std::optional<eval::LocalisationScores> localisation;  ///< with a loaded map and ground truth
  std::string localisation_note;                          ///< why there is none
};

/// The application data of a map file: the station it shows (its scenario
/// name and, when known, file) and T_world_map.
std::string map_app_json(const std::string& scenario, std::uint64_t station_seed,
                         const std::optional<geom::SE3d>& T_world_map, const std::string& scenario_file = "");
/// The scenario file a map was made from, when its data names one.
std::string map_scenario_file(const std::string& app_json);
/// T_world_map from a map file's application data, when it has one.
std::optional<geom::SE3d> T_world_map_of(const std::string& app_json);

/// Ground truth at the camera's frame times (within 1 ms, or interpolated
/// between poses at most 50 ms apart), for sequences whose ground truth
/// runs at its own rate (TUM's motion capture); frames without are left out.
eval::Trajectory ground_truth_at(const eval::Trajectory& gt, const std::vector<std::int64_t>& t_ns);

/// The pose of a new map's frame in the world: from the first pose of the
/// run's trajectory that has ground truth (the map's frame is SLAM's first
/// camera; in a simulated run that pose is the first one, at identity).
std::optional<geom::SE3d> T_world_new_map(const eval::Trajectory& gt, const eval::Trajectory& est);

/// Loads the map into `system` when the options name one.
MapReport start_map(slam::System& system, const MapOptions& options);
/// Scores localisation in the loaded map against ground truth.
void score_map_localisation(MapReport* report, const eval::Trajectory& gt, const eval::Trajectory& est);
/// Saves the final map when the options say so (after System::shutdown()).
void save_map(slam::System& system, const MapOptions& options, const std::string& scenario,
              std::uint64_t station_seed, MapReport* report, const std::string& scenario_file = "");

/// After a run (System::shutdown() done): the localisation in a loaded map
/// scored against `gt` (may be empty: no ground truth), then the map saved
/// when the options say so, with its frame in the world (the loaded map's,
/// or the ground truth at the first pose of `est`).
void finish_map(slam::System& system, const MapOptions& options, const eval::Trajectory& gt,
                const eval::Trajectory& est, const std::string& name, std::uint64_t station_seed, MapReport* report,
                const std::string& scenario_file = "");

/// What the run did with maps, one line per loaded or saved map.
std::vector<std::string> map_log_lines(const MapReport& r);

/// The "map" object of metrics.json (one line).
std::string map_report_json(const MapReport& r);

}  // namespace pvb::run
