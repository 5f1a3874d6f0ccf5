// Starting a run from a saved map (harness/run/src/map_session.cpp): the
// map's META is read strictly (a damaged one is refused with what is
// wrong, a null T_world_map is a map made without ground truth), and a map
// of another station is refused unless allowed, then used with a warning.
#include <gtest/gtest.h>

#include <cstdlib>

#include "map_file_edit.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/run/map_session.hpp"
#include "pvb/scenes/scenario.hpp"

namespace pvb::run {
namespace {

const std::string kTum3 = std::string(PVB_SOURCE_DIR) + "/configs/tum/TUM3.yaml";

const char* kRotation = "[1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0]";

std::string meta(const std::string& T_world_map, const std::string& station = "\"pv_station\"",
                 const std::string& seed = "7") {
  return "{\"scenario\": \"pv_station_1200\", \"scenario_file\": null, \"station\": " + station +
         ", \"station_seed\": " + seed + ", \"T_world_map\": " + T_world_map + "}";
}

slam::SystemOptions sync_options() {
  slam::SystemOptions o;
  o.synchronous = true;
  return o;
}

/// A tiny map with `app_json` as its META, started from with `options`
/// (load_path and use filled in).
MapReport start(const std::string& app_json, MapOptions options, const std::string& name = "meta.pvbmap") {
  slam::System system(slam::read_settings(kTum3), sync_options());
  options.load_path = ::testing::TempDir() + "map_session_" + name;
  options.use = MapUse::kLocalise;
  write_file(options.load_path, test::tiny_map(system.map_settings(), app_json));
  return start_map(system, options);
}

/// The error of starting from a map with `app_json` ("" when none).
std::string start_error(const std::string& app_json, const MapOptions& options = {}) {
  try {
    start(app_json, options);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(MapSession, ADamagedMetaIsRefusedNamingTheFileMetaAndTheDamage) {
  const std::string file = ::testing::TempDir() + "map_session_meta.pvbmap: META section: ";
  const std::vector<std::pair<std::string, std::string>> damaged = {
      {"{\"T_world_map\": [1, 0", "not JSON"},
      {"", "empty, expected a JSON object"},
      {"[1, 2, 3]", "not a JSON object"},
      {"T_world_map: null", "not a JSON object"},  // YAML, not JSON
      {"{\"scenario\": \"x\"}", "no T_world_map"},
      {meta("[NaN, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0]"), "T_world_map number 1 is not a finite number (NaN)"},
      {meta("[1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1]"), "T_world_map has 11 numbers, expected 12"},
      {meta("[2, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0]"),
       "T_world_map's first three columns are not a rotation"},
      {meta("[-1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0]"),
       "T_world_map's first three columns are not a rotation"},  // a reflection
      {meta("[1, 0, 0, 1e300, 0, 1, 0, 0, 0, 0, 1, 0]"), "T_world_map's translation lies beyond 1e+06 m"},
      {meta(kRotation, "\"pv_station\"", "-7"), "station_seed is not a whole number from 0 (-7)"},
      {meta(kRotation, "[1]"), "station is not a name"},
  };
  for (const auto& [json, damage] : damaged) {
    const std::string what = start_error(json);
    EXPECT_NE(what.find(file + damage), std::string::npos) << json << " -> " << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// META is read by the common JSON reader: a key given twice (yaml-cpp would
// keep both and find the first) is refused, naming it and both lines.
TEST(MapSession, AMetaKeyGivenTwiceIsRefusedNamingBothLines) {
  const std::string what = start_error("{\"T_world_map\": null,\n \"T_world_map\": " + std::string(kRotation) + "}");
  EXPECT_NE(what.find(::testing::TempDir() +
                      "map_session_meta.pvbmap: META section: T_world_map: expected each key once in its section "
                      "(first given at line 1), got a second T_world_map (line 2 of the section)"),
            std::string::npos)
      << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
}

TEST(MapSession, AMapMadeWithoutGroundTruthIsUsedAndLeftUnscored) {
  const MapReport r = start(meta("null"), {});
  EXPECT_FALSE(r.T_world_map);
  const MapReport with = start(meta(kRotation), {});
  ASSERT_TRUE(with.T_world_map);
  EXPECT_DOUBLE_EQ(with.T_world_map->translation().x(), 0.5);
}

TEST(MapSession, AMapOfAnotherStationIsRefusedUnlessAllowedThenUsedWithAWarning) {
  MapOptions o;
  o.station = MapStation{"tracker_station", 11};
  const std::string refused = start_error(meta(kRotation), o);
  EXPECT_NE(
      refused.find("META station: expected a map of this run's station, tracker_station, station seed 11 "
                   "(--allow-other-station uses it all the same), got pv_station, station seed 7"),
      std::string::npos)
      << refused;
  o.station = MapStation{"pv_station", 8};  // the seed alone differs
  EXPECT_NE(start_error(meta(kRotation), o).find("got pv_station, station seed 7"), std::string::npos);
  o.allow_other_station = true;
  const MapReport allowed = start(meta(kRotation), o);
  EXPECT_NE(allowed.station_warning.find(
                "shows pv_station, station seed 7, this run is on pv_station, station seed 8"),
            std::string::npos)
      << allowed.station_warning;
  EXPECT_EQ(map_log_lines(allowed).front(), "warning: " + allowed.station_warning);
}

TEST(MapSession, TheSameStationOrOneNotKnownIsUsedWithoutAWord) {
  MapOptions o;
  o.station = MapStation{"pv_station", 7};
  EXPECT_EQ(start(meta(kRotation), o).station_warning, "");
  EXPECT_EQ(start(meta(kRotation, "null", "null"), o).station_warning, "");  // a map that does not say
  EXPECT_EQ(start(meta(kRotation), {}).station_warning, "");                 // a run that does not know
}

TEST(MapSession, EveryDayOfAStationIsThatStation) {
  const scenes::Scenario day =
      scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/days/pv_station_0800.yaml");
  const scenes::Scenario station =
      scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml");
  const scenes::Scenario trackers =
      scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/days/tracker_station_1200.yaml");
  EXPECT_EQ(station_of(day).describe(), "pv_station, station seed 7");
  EXPECT_FALSE(station_of(day).differs_from(station_of(station)));
  EXPECT_TRUE(station_of(day).differs_from(station_of(trackers)));
  // What a map saved on a day says is what a run of another day is on.
  const MapMeta m = read_map_meta(map_app_json(day.name, station_of(day), std::nullopt), "m.pvbmap");
  EXPECT_FALSE(m.station.differs_from(station_of(station)));
  EXPECT_EQ(m.station.name, "pv_station");
  // A recording says so in its meta.json.
  const std::string rec = ::testing::TempDir() + "map_session_meta.json";
  write_file(
      rec,
      "{\"scenario\": {\"name\": \"pv_station_0800\", \"file\": \"scenes/days/pv_station_0800.yaml\"}, "
      "\"seed\": 70800, \"world\": {\"station_seed\": 7, \"base_files\": [\"scenes/pv_station.yaml\"]}}");
  EXPECT_EQ(recording_station(rec).describe(), "pv_station, station seed 7");
  EXPECT_FALSE(recording_station(rec + ".missing").known());
}

}  // namespace
}  // namespace pvb::run
