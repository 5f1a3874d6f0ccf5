#pragma once
// A campaign: the same station over several days, as sessions run in
// order.  A session drives a day's scenario and makes a map (map), finds
// itself in an earlier session's map without changing it (localise), or
// adds to it (extend); the maps are passed along, and every session is
// judged against ground truth in the map's frame (docs/map_reuse.md).
//
// The file (YAML):
//   name: daily
//   description: map at noon, localise at other hours
//   sessions:
//     - {name: noon, scenario: ../scenes/days/pv_station_1200.yaml, mode: map}
//     - {name: h0800, scenario: ../scenes/days/pv_station_0800.yaml, mode: localise, map: noon, start_m: 3}
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pvb::run {

enum class SessionMode { kMap, kLocalise, kExtend };
const char* to_string(SessionMode m);

struct CampaignSession {
  std::string name;           ///< unique in the campaign; names its folder
  std::string scenario_file;  ///< relative paths are taken from the campaign file's folder
  SessionMode mode = SessionMode::kMap;
  /// The earlier session whose saved map it starts from (localise, extend);
  /// empty for a map session.
  std::string map;
  std::optional<double> start_m;  ///< overrides the scenario's route.start_m
  std::uint64_t scenario_seed = 0;  ///< the scenario's own seed (a campaign without --seed runs with it)
};

/// What a campaign writes at the top of its folder beside the sessions'
/// folders: the maps folder and the reports.  No session may take one of
/// these names.
const std::vector<std::string>& campaign_top_level_names();

struct Campaign {
  std::string file;
  std::string name;
  std::string description;
  std::vector<CampaignSession> sessions;
  /// The index of the session named `name`, or -1.
  int index_of(const std::string& name) const;
};

/// Reads and checks a campaign file: every key known and given once, names
/// unique and none of campaign_top_level_names(), a map session names no
/// map, a localise or extend session names an earlier session that leaves a
/// map (map or extend).  Every session's scenario is loaded (a bad one
/// fails before any session runs) and its start_m checked against the
/// route.  Throws ConfigError naming the file, the line and the key (a
/// scenario's own mistakes name the scenario file).
Campaign load_campaign(const std::string& path);

}  // namespace pvb::run
