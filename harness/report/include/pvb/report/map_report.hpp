#pragma once
// What a run did with saved maps (docs/map_reuse.md) as its report holds
// it: the map loaded and how it was used, the map saved, the localisation
// in it against ground truth; metrics.json's "map" object and the log's
// lines.  Loading and saving are harness/run's map_session.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pvb/eval/localisation.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/slam/core/system.hpp"

namespace pvb::run {

/// How a run uses a saved map.
enum class MapUse { kFresh, kLocalise, kExtend };
const char* to_string(MapUse u);
/// The station a map shows or a run is on: the name of its station file
/// (the file its days derive from, without folder and ".yaml";
/// "pv_station" for every scenes/days/pv_station_*.yaml) and its station
/// seed.  Either may be unknown.
struct MapStation {
  std::string name;  ///< "" when not known
  std::optional<std::uint64_t> seed;
  bool known() const { return !name.empty() || seed.has_value(); }
  /// True when both name a part (name, seed) and that part differs.
  bool differs_from(const MapStation& o) const;
  /// "pv_station, station seed 7" (the parts known).
  std::string describe() const;
};
/// What a run did with maps, for metrics.json and the report.
struct MapReport {
  std::string loaded_from;
  MapUse use = MapUse::kFresh;
  std::optional<slam::MapLoadInfo> load;
  MapStation loaded_station;    ///< what the loaded map's META says; an extended map keeps it
  std::string station_warning;  ///< the loaded map shows another station (allowed)
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

/// A pose as a map file's META and metrics.json write it: the 3x4 matrix
/// [R | t], row by row, as a JSON list of 12 numbers.
std::string pose_json(const geom::SE3d& T);

/// What the run did with maps, one line per loaded or saved map.
std::vector<std::string> map_log_lines(const MapReport& r);

/// The "map" object of metrics.json (one line).
std::string map_report_json(const MapReport& r);

}  // namespace pvb::run
