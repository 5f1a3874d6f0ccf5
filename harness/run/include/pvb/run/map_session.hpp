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
#include "pvb/report/map_report.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/slam/core/system.hpp"

namespace pvb::run {

/// "localise" or "extend"; anything else throws ConfigError naming `option`.
MapUse parse_map_use(const std::string& text, const std::string& option);

/// The station of a scenario (its last base file, else its own file).
MapStation station_of(const scenes::Scenario& s);
/// The station of a recording by `pvbench record`, from its meta.json
/// ("world": station_seed, base_files; "scenario": file); unknown when the
/// file is not there or does not say.
MapStation recording_station(const std::string& meta_json_path);

struct MapOptions {
  std::string load_path;           ///< the saved map to start from (empty: a fresh map)
  MapUse use = MapUse::kFresh;     ///< kLocalise or kExtend with load_path
  std::string save_path;           ///< where to save the final map (empty: not saved)
  /// The run's station, when known: written into a new map's META, and a
  /// loaded map that shows another is refused (ConfigError) or, with
  /// allow_other_station, used after a warning.
  MapStation station;
  bool allow_other_station = false;  ///< --allow-other-station; slam and camera only warn
  /// Checks the combination: a use needs a map and a map a use, and a map
  /// only localised in is not saved again.  Throws ConfigError.
  void check() const;
};

/// The application data of a map file (its META section): the scenario it
/// was made from (name and, when known, file), the station it shows and
/// T_world_map (null: not known).
std::string map_app_json(const std::string& scenario, const MapStation& station,
                         const std::optional<geom::SE3d>& T_world_map, const std::string& scenario_file = "");
/// The scenario file a map was made from, when its data names one.
std::string map_scenario_file(const std::string& app_json);

/// A map file's META as pvbench reads it.
struct MapMeta {
  std::optional<geom::SE3d> T_world_map;  ///< null in the file: made without ground truth
  MapStation station;
};
/// Reads a map file's META: a JSON object whose T_world_map is null or 12
/// finite numbers (a 3x4 matrix, row by row: a rotation, and a
/// translation within slam::kMaxMapCoordinateM), whose station_seed, when
/// there, is a whole number or null and whose station a string or null.
/// Throws IoError "FILE: META section: what is wrong".
MapMeta read_map_meta(const std::string& app_json, const std::string& file);

/// Ground truth at the camera's frame times (within 1 ms, or interpolated
/// between poses at most 50 ms apart), for sequences whose ground truth
/// runs at its own rate (TUM's motion capture); frames without are left out.
eval::Trajectory ground_truth_at(const eval::Trajectory& gt, const std::vector<std::int64_t>& t_ns);

/// This session's keyframes in its own clock, from a keyframe trajectory as
/// the tools write it (KeyFrameTrajectory.txt: every session of the map,
/// this one's stamps plus System::session_clock_offset_ns()): the poses
/// from the session's first frame on, moved back by the offset.  A map's
/// earlier sessions have no ground truth in this recording.
eval::Trajectory session_keyframes(const eval::Trajectory& written, const slam::System& system);

/// The pose of a new map's frame in the world: from the first pose of the
/// run's trajectory that has ground truth (the map's frame is SLAM's first
/// camera; in a simulated run that pose is the first one, at identity).
std::optional<geom::SE3d> T_world_new_map(const eval::Trajectory& gt, const eval::Trajectory& est);

/// Loads the map into `system` when the options name one, and reads its
/// META; a map of another station than options.station is refused
/// (ConfigError) unless options.allow_other_station, which prints a
/// "pvbench: warning:" line instead.
MapReport start_map(slam::System& system, const MapOptions& options);
/// Scores localisation in the loaded map against ground truth.
void score_map_localisation(MapReport* report, const eval::Trajectory& gt, const eval::Trajectory& est);
/// Saves the final map when the options say so (after System::shutdown()),
/// with the station of the loaded map, else options.station.
void save_map(slam::System& system, const MapOptions& options, const std::string& scenario, MapReport* report,
              const std::string& scenario_file = "");

/// After a run (System::shutdown() done): the localisation in a loaded map
/// scored against `gt` (may be empty: no ground truth), then the map saved
/// when the options say so, with its frame in the world (the loaded map's,
/// or the ground truth at the first pose of `est`).
void finish_map(slam::System& system, const MapOptions& options, const eval::Trajectory& gt,
                const eval::Trajectory& est, const std::string& name, MapReport* report,
                const std::string& scenario_file = "");

}  // namespace pvb::run
