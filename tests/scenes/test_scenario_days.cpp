// The station and the day: derived files (base:), the sun from the site and
// time, single-axis trackers, and the errors of each, by file, line and key.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/scenes/solar_position.hpp"
#include "pvb/scenes/tracker.hpp"

using namespace pvb::scenes;
namespace fs = std::filesystem;

namespace {

const std::string kScenes = std::string(PVB_SOURCE_DIR) + "/scenes/";

/// A folder of scenario files written by a test.
class Folder {
 public:
  explicit Folder(const std::string& name)
      : dir_(::testing::TempDir() + "pvb_days_" + name + "_" + std::to_string(::getpid())) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string write(const std::string& file, const std::string& text) const {
    const std::string path = dir_ + "/" + file;
    pvb::write_file(path, text);
    return path;
  }
  std::string error_of(const std::string& file, const std::string& text) const {
    const std::string path = write(file, text);
    try {
      load_scenario(path);
    } catch (const pvb::Error& e) {
      return e.what();
    }
    return "";
  }
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
};

const char* kStation =
    "name: station\nseed: 7\n"
    "pv_arrays:\n  - {rows: 2, tables_per_row: 2, panels_per_table: 4, dirt: 0.2}\n"
    "  - {origin_m: [0, 20], rows: 1, tables_per_row: 1, panels_per_table: 4}\n"
    "light: {sun_azimuth_deg: 150, sun_elevation_deg: 50, intensity: 0.75, ambient: 0.38}\n"
    "route: {pattern: along_row, aisle: 1}\n";

const char* kSite = "site: {latitude_deg: 48.1, longitude_deg: 11.6, date: 2026-06-21, time: \"12:00\", utc_offset_h: 2}\n";

}  // namespace

// NOAA's position for the site and time becomes the scene's sun; the light
// follows its elevation unless the file sets it.
TEST(ScenarioDays, SiteGivesTheSunAndItsLight) {
  const Scenario s = parse_scenario("route: {waypoints_m: [[0, 0], [5, 0]]}\n" + std::string(kSite), "site.yaml");
  CivilTime t;
  t.year = 2026, t.month = 6, t.day = 21, t.hour = 12, t.utc_offset_h = 2;
  const SolarPosition p = *solar_position(48.1, 11.6, t);
  EXPECT_EQ(s.sun.source, SunPosition::Source::kSite);
  EXPECT_NEAR(s.light.sun_elevation_deg, p.elevation_deg, 1e-9);
  EXPECT_NEAR(s.light.sun_azimuth_deg, scene_sun_azimuth_deg(p.azimuth_deg), 1e-9);
  EXPECT_NEAR(s.sun.solar_azimuth_deg, p.azimuth_deg, 1e-9);
  EXPECT_NEAR(s.light.intensity, sun_intensity_for(p.elevation_deg), 1e-12);
  EXPECT_NEAR(s.light.ambient, sky_ambient_for(p.elevation_deg), 1e-12);
  // 12:00 summer time in June in Germany is 10:44 solar time: the sun is
  // high in the south-east.
  EXPECT_GT(p.elevation_deg, 55.0);
  EXPECT_GT(p.azimuth_deg, 110.0);
  EXPECT_LT(p.azimuth_deg, 180.0);
  // The light model is anchored on the defaults at 45 degrees and grows with the sun.
  EXPECT_NEAR(sun_intensity_for(45.0), 0.8, 1e-12);
  EXPECT_NEAR(sky_ambient_for(45.0), 0.35, 1e-12);
  EXPECT_LT(sun_intensity_for(10.0), sun_intensity_for(30.0));
  EXPECT_LT(sky_ambient_for(10.0), sky_ambient_for(60.0));
  // A light key in the same file takes priority.
  const Scenario lit = parse_scenario(
      "route: {waypoints_m: [[0, 0], [5, 0]]}\n" + std::string(kSite) + "light: {sun_elevation_deg: 20, ambient: 0.5}\n",
      "lit.yaml");
  EXPECT_DOUBLE_EQ(lit.light.sun_elevation_deg, 20.0);
  EXPECT_DOUBLE_EQ(lit.light.ambient, 0.5);
  EXPECT_NEAR(lit.light.sun_azimuth_deg, scene_sun_azimuth_deg(p.azimuth_deg), 1e-9);
  EXPECT_NEAR(lit.light.intensity, sun_intensity_for(20.0), 1e-12);
}

TEST(ScenarioDays, BadSitesAreOneLineNamingTheKey) {
  const Folder f("site");
  const std::string route = "route: {waypoints_m: [[0, 0], [5, 0]]}\n";
  std::string e = f.error_of("night.yaml", route +
                                               "site:\n  latitude_deg: 48.1\n  longitude_deg: 11.6\n  date: 2026-06-21\n"
                                               "  time: \"03:00\"\n  utc_offset_h: 2\n");
  EXPECT_NE(e.find("night.yaml:6: site.time: expected a time when the sun is up (at least 1 deg above the horizon at "
                   "the site), got the sun -"),
            std::string::npos)
      << e;
  // A derived file that moves the site into the polar night is named, with
  // the keys it gives, not the base whose time it keeps.
  f.write("noon.yaml", route +
                           "site:\n  latitude_deg: 48.1\n  longitude_deg: 11.6\n  date: 2026-06-21\n"
                           "  time: \"12:00\"\n  utc_offset_h: 2\n");
  e = f.error_of("south.yaml", "base: noon.yaml\nsite:\n  latitude_deg: -80\n");
  EXPECT_NE(
      e.find("south.yaml:3: site.latitude_deg: expected a place and date where the sun is up at the site's "
             "time (at least 1 deg above the horizon), got the sun -"),
      std::string::npos)
      << e;
  EXPECT_NE(e.find("above the horizon at -80 deg N, 11.6 deg E on 2026-06-21 at 12:00 (UTC+2)"),
            std::string::npos)
      << e;
  e = f.error_of("winter.yaml", "base: noon.yaml\nsite:\n  latitude_deg: -80\n  date: 2026-06-22\n");
  EXPECT_NE(e.find("winter.yaml:3: site.latitude_deg, site.date: expected a place and date"),
            std::string::npos)
      << e;
  e = f.error_of("early.yaml", "base: noon.yaml\nsite:\n  latitude_deg: -80\n  time: \"11:00\"\n");
  EXPECT_NE(e.find("early.yaml:4: site.time: expected a time when the sun is up"), std::string::npos) << e;
  e = f.error_of("date.yaml", route + "site:\n  latitude_deg: 48\n  longitude_deg: 11\n  date: 2026-02-30\n"
                                      "  time: \"12:00\"\n  utc_offset_h: 1\n");
  EXPECT_NE(e.find("date.yaml:5: site.date: expected a date YYYY-MM-DD (years 1901-2099), got date 2026-02-30: day 30 "
                   "is outside February 2026 (1..28)"),
            std::string::npos)
      << e;
  e = f.error_of("time.yaml", route + "site:\n  latitude_deg: 48\n  longitude_deg: 11\n  date: 2026-02-03\n"
                                      "  time: \"25:00\"\n  utc_offset_h: 1\n");
  EXPECT_NE(e.find("time.yaml:6: site.time: expected a local time HH:MM or HH:MM:SS"), std::string::npos) << e;
  e = f.error_of("lat.yaml", route + "site:\n  latitude_deg: 91\n  longitude_deg: 11\n  date: 2026-02-03\n"
                                     "  time: \"12:00\"\n  utc_offset_h: 1\n");
  EXPECT_NE(e.find("lat.yaml:3: site.latitude_deg: expected a value in [-90, 90], got 91"), std::string::npos) << e;
  e = f.error_of("missing.yaml", route + "site: {latitude_deg: 48, longitude_deg: 11, date: 2026-02-03}\n");
  EXPECT_NE(e.find("site.time: expected a value (required in site)"), std::string::npos) << e;
}

// A derived file takes its base and changes the day: the items of pv_arrays
// merge by position, maps key by key; the station seed is the base's.
TEST(ScenarioDays, DerivedFileChangesTheDayAndKeepsTheStation) {
  const Folder f("derive");
  const std::string base = f.write("station.yaml", kStation);
  const std::string day = f.write("day.yaml", "base: station.yaml\nname: day\nseed: 42\n" + std::string(kSite) +
                                                  "pv_arrays:\n  - dirt: 0.8\nvegetation: {growth: 1.5}\n"
                                                  "camera: {rgb: {sigma: 3}}\n");
  const Scenario b = load_scenario(base), d = load_scenario(day);
  EXPECT_EQ(d.name, "day");
  EXPECT_EQ(d.seed, 42u);
  ASSERT_TRUE(d.station_seed.has_value());
  EXPECT_EQ(*d.station_seed, 7u);  // the base's seed
  EXPECT_FALSE(b.station_seed.has_value());
  EXPECT_EQ(b.station_seed_or_seed(), d.station_seed_or_seed());
  ASSERT_EQ(d.base_files.size(), 1u);
  EXPECT_EQ(d.base_files[0], f.dir() + "/station.yaml");
  ASSERT_EQ(d.pv_arrays.size(), 2u);
  EXPECT_DOUBLE_EQ(d.pv_arrays[0].dirt, 0.8);
  EXPECT_EQ(d.pv_arrays[0].rows, 2);  // the rest of the item is the base's
  EXPECT_DOUBLE_EQ(d.pv_arrays[1].dirt, b.pv_arrays[1].dirt);
  EXPECT_DOUBLE_EQ(d.vegetation.growth, 1.5);
  EXPECT_DOUBLE_EQ(d.camera.rgb.sigma, 3.0);
  EXPECT_EQ(d.camera.depth_noise.model, b.camera.depth_noise.model);
  // The base's light was the base's day: the site's sun replaces it.
  EXPECT_EQ(d.sun.source, SunPosition::Source::kSite);
  EXPECT_NE(d.light.sun_elevation_deg, b.light.sun_elevation_deg);
  EXPECT_NE(d.light.intensity, 0.75);
  // Pinning the same station seed is allowed; another is refused.
  EXPECT_EQ(load_scenario(f.write("pinned.yaml", "base: station.yaml\nstation_seed: 7\nseed: 3\n")).station_seed, 7u);
  const std::string e = f.error_of("other.yaml", "base: station.yaml\nseed: 3\nstation_seed: 8\n");
  EXPECT_NE(e.find("other.yaml:3: station_seed: expected the station seed of its base, 7 ("), std::string::npos) << e;
}

TEST(ScenarioDays, DerivedFileMayNotChangeTheStation) {
  const Folder f("station_keys");
  f.write("station.yaml", kStation);
  std::string e = f.error_of("walls.yaml", "base: station.yaml\nname: d\nwalls:\n  - {start_m: [0, 0], end_m: [3, 0]}\n");
  EXPECT_NE(e.find("walls.yaml:3: walls: expected a key a derived file may change ("), std::string::npos) << e;
  EXPECT_NE(e.find("got a key of the station, which stays as its base has it"), std::string::npos) << e;
  e = f.error_of("rows.yaml", "base: station.yaml\npv_arrays:\n  - rows: 3\n");
  EXPECT_NE(e.find("rows.yaml:3: pv_arrays[0].rows: expected a key a derived file may change"), std::string::npos)
      << e;
  e = f.error_of("route.yaml", "base: station.yaml\nroute:\n  aisle: 2\n");
  EXPECT_NE(e.find("route.yaml:3: route.aisle: expected a key a derived file may change"), std::string::npos) << e;
  e = f.error_of("more.yaml", "base: station.yaml\npv_arrays:\n  - dirt: 0.1\n  - dirt: 0.1\n  - dirt: 0.1\n");
  EXPECT_NE(e.find("more.yaml:5: pv_arrays: expected at most the station's 2 arrays"), std::string::npos) << e;
  // A key no scenario knows is named as unknown, not as the station's.
  e = f.error_of("typo.yaml", "base: station.yaml\nlihgt: {ambient: 0.3}\n");
  EXPECT_NE(e.find("typo.yaml:2: lihgt: expected a known key ("), std::string::npos) << e;
  EXPECT_NE(e.find("got unknown key"), std::string::npos) << e;
  e = f.error_of("deep.yaml", "base: station.yaml\nground: {colour: red}\n");
  EXPECT_NE(e.find("deep.yaml:2: ground.colour: expected a known key ("), std::string::npos) << e;
  e = f.error_of("plants.yaml", "base: station.yaml\nvegetation: {shrubs: 40}\n");
  EXPECT_NE(e.find("plants.yaml:2: vegetation.shrubs: expected a key a derived file may change"), std::string::npos)
      << e;
}

TEST(ScenarioDays, BasesThatAreMissingOrCircularAreRefused) {
  const Folder f("bases");
  std::string e = f.error_of("lost.yaml", "name: x\nbase: nowhere.yaml\n");
  EXPECT_NE(e.find("lost.yaml:2: base: expected an existing scenario file, got " + f.dir() + "/nowhere.yaml (no such file)"),
            std::string::npos)
      << e;
  e = f.error_of("self.yaml", "base: self.yaml\n");
  EXPECT_NE(e.find("self.yaml:1: base: expected a file that does not derive from itself"), std::string::npos) << e;
  f.write("a.yaml", "base: b.yaml\n");
  e = f.error_of("b.yaml", "base: a.yaml\n");
  EXPECT_NE(e.find("a.yaml:1: base: expected a file that does not derive from itself, got " + f.dir() + "/b.yaml"),
            std::string::npos)
      << e;
}

// An error in a value names the file it was written in: the base's line
// for a value of the base, the derived file's for one of its own.
TEST(ScenarioDays, ErrorsNameTheFileTheValueCameFrom) {
  const Folder f("origins");
  f.write("bad_base.yaml", std::string(kStation) + "camera: {fps: 500}\n");
  std::string e = f.error_of("day.yaml", "base: bad_base.yaml\nseed: 1\n");
  EXPECT_NE(e.find(f.dir() + "/bad_base.yaml:8: camera.fps: expected a value in [1, 240], got 500"), std::string::npos)
      << e;
  f.write("station.yaml", kStation);
  e = f.error_of("day2.yaml", "base: station.yaml\nseed: 1\ncamera:\n  rgb: {sigma: -1}\n");
  EXPECT_NE(e.find("day2.yaml:4: camera.rgb.sigma: expected a value in [0, 100], got -1"), std::string::npos) << e;
  e = f.error_of("dup.yaml", "base: station.yaml\nseed: 1\nseed: 2\n");
  EXPECT_NE(e.find("dup.yaml:3: seed: expected each key once in its section"), std::string::npos) << e;
  // A key given twice in a base is named at the base's line.
  f.write("dup_base.yaml", std::string(kStation) + "camera: {fps: 15, fps: 20}\n");
  e = f.error_of("day3.yaml", "base: dup_base.yaml\nseed: 1\n");
  EXPECT_NE(e.find(f.dir() + "/dup_base.yaml:8: camera.fps: expected each key once in its section (first given at "
                             "line 8), got a second fps"),
            std::string::npos)
      << e;
}

// Trackers: the angle of true tracking with backtracking for the day's sun,
// or a fixed one within the mount's limit.
TEST(ScenarioDays, TrackerRotationFollowsTheSun) {
  const std::string tracker_station = kScenes + "tracker_station.yaml";
  const Scenario s = load_scenario(tracker_station);
  ASSERT_EQ(s.pv_arrays.size(), 1u);
  const PvArray& a = s.pv_arrays[0];
  ASSERT_EQ(a.mount, Mount::kSingleAxis);
  SingleAxisTracker t;
  t.axis_azimuth_deg = 0.0;  // azimuth_deg 90: the tubes run north
  t.max_angle_deg = 55.0;
  t.gcr = a.table_depth_m() / a.row_pitch_m;
  const TrackerRotation expected = *tracker_rotation(90.0 - s.sun.elevation_deg, s.sun.solar_azimuth_deg, t);
  EXPECT_NEAR(a.rotation_deg, expected.rotation_deg, 1e-9);
  EXPECT_NEAR(a.ground_coverage_ratio(), 0.35, 1e-9);
  // Morning and afternoon: turned east, then west (a north-pointing tube
  // turns east for positive angles); the largest angle at the limit.
  const Scenario morning = load_scenario(kScenes + "days/tracker_station_0800.yaml");
  const Scenario afternoon = load_scenario(kScenes + "days/tracker_station_1600.yaml");
  EXPECT_GT(morning.pv_arrays[0].rotation_deg, 10.0);
  EXPECT_LT(afternoon.pv_arrays[0].rotation_deg, -10.0);
  EXPECT_LE(std::abs(morning.pv_arrays[0].rotation_deg), 55.0 + 1e-9);
  // The lowest panel edge is clearance_m above the ground at the limit.
  const double d = a.table_depth_m(), max_rad = 55.0 * M_PI / 180.0;
  EXPECT_NEAR(a.axis_height_m() - 0.5 * d * std::sin(max_rad) + kTrackerPanelAboveAxisM * std::cos(max_rad),
              a.clearance_m, 1e-12);
}

// A day keeps its station's ground, varied or repeated, and may not change
// it.  Varied is the default; a relief keeps the repeated image.
TEST(ScenarioDays, TheGroundsTilingIsTheStations) {
  EXPECT_EQ(load_scenario(kScenes + "days/loop_varied_part.yaml").ground.tiling, GroundTiling::kVaried);
  EXPECT_EQ(load_scenario(kScenes + "days/pv_station_1200.yaml").ground.tiling, GroundTiling::kVaried);
  EXPECT_EQ(load_scenario(kScenes + "days/rough_station_dry.yaml").ground.tiling, GroundTiling::kRepeat);
  EXPECT_EQ(load_scenario(kScenes + "aliasing.yaml").ground.tiling, GroundTiling::kRepeat);
  const Folder f("tiling");
  f.write("station.yaml", kStation);
  const std::string e = f.error_of("day.yaml", "base: station.yaml\nground: {tiling: varied}\n");
  EXPECT_NE(e.find("day.yaml:2: ground.tiling: expected a key a derived file may change"), std::string::npos) << e;
}

TEST(ScenarioDays, TrackerKeysAreCheckedWithFileAndLine) {
  const Folder f("tracker");
  const std::string route = "route: {pattern: along_row, aisle: 1}\n";
  const Scenario parked =
      load_scenario(f.write("parked.yaml", route + "pv_arrays:\n  - mount: single_axis\n    panel_lines: 1\n"
                                                   "    tracker: {rotation_deg: -30, max_angle_deg: 50}\n"));
  EXPECT_DOUBLE_EQ(parked.pv_arrays[0].rotation_deg, -30.0);
  std::string e = f.error_of("beyond.yaml", route + "pv_arrays:\n  - mount: single_axis\n    panel_lines: 1\n"
                                                    "    tracker:\n      rotation_deg: 60\n");
  EXPECT_NE(e.find("beyond.yaml:6: pv_arrays[0].tracker.rotation_deg: expected a rotation within the mount's limit of "
                   "+-55 deg, got 60"),
            std::string::npos)
      << e;
  // Just beyond the limit is printed with the digits that make it so.
  e = f.error_of("edge.yaml", route +
                                  "pv_arrays:\n  - mount: single_axis\n    panel_lines: 1\n"
                                  "    tracker:\n      rotation_deg: 55.0000001\n");
  EXPECT_NE(e.find("limit of +-55 deg, got 55.0000001"), std::string::npos) << e;
  e = f.error_of("tilt.yaml", route + "pv_arrays:\n  - mount: single_axis\n    tilt_deg: 20\n");
  EXPECT_NE(e.find("tilt.yaml:4: pv_arrays[0].tilt_deg: expected no tilt_deg for a single_axis mount"),
            std::string::npos)
      << e;
  e = f.error_of("fixed.yaml", route + "pv_arrays:\n  - tracker: {max_angle_deg: 50}\n");
  EXPECT_NE(e.find("fixed.yaml:3: pv_arrays[0].tracker: expected no tracker section unless mount is single_axis"),
            std::string::npos)
      << e;
}

// Every shipped day file loads, keeps its station's seed, and names it.
TEST(ScenarioDays, ShippedDaysKeepTheirStation) {
  for (const auto& entry : fs::directory_iterator(kScenes + "days")) {
    const Scenario d = load_scenario(entry.path().string());
    ASSERT_FALSE(d.base_files.empty()) << entry.path();
    const Scenario station = load_scenario(d.base_files.back());
    EXPECT_EQ(d.station_seed_or_seed(), station.station_seed_or_seed()) << entry.path();
    EXPECT_EQ(d.sun.source, SunPosition::Source::kSite) << entry.path();
    EXPECT_NE(d.name, station.name) << entry.path();
    EXPECT_NE(d.seed, station.seed) << entry.path();
  }
}

// A plant's days: the same plant (blocks, fence, dock, boxes) under the
// day's sun and dust.
TEST(PlantDays, KeepThePlantAndChangeTheDay) {
  for (const char* plant : {"plant_10mw_fixed", "plant_10mw_tracker", "plant_10mw_tracker_rough"}) {
    const Scenario base = load_scenario(kScenes + "plants/" + plant + ".yaml");
    for (const char* day : {"_0800", "_1200", "_1600", "_dusty"}) {
      const Scenario s = load_scenario(kScenes + "days/" + plant + day + ".yaml");
      EXPECT_EQ(s.station_seed_or_seed(), base.station_seed_or_seed()) << plant << day;
      EXPECT_NE(s.seed, base.seed) << plant << day;
      ASSERT_EQ(s.pv_arrays.size(), base.pv_arrays.size());
      EXPECT_EQ(s.pv_arrays[0].origin_m, base.pv_arrays[0].origin_m);
      ASSERT_TRUE(s.plant && s.plant->fence);
      EXPECT_EQ(s.plant->fence->corners_m, base.plant->fence->corners_m);
      EXPECT_EQ(s.plant->fixtures.size(), base.plant->fixtures.size());
      EXPECT_EQ(s.route.from_dock, true);
      EXPECT_NE(s.light.sun_azimuth_deg, base.light.sun_azimuth_deg) << plant << day;
    }
    const Scenario dusty = load_scenario(kScenes + "days/" + plant + "_dusty.yaml");
    EXPECT_DOUBLE_EQ(dusty.pv_arrays[0].dirt, 0.8);
    EXPECT_LT(base.pv_arrays[0].dirt, 0.5);
  }
  // The rough plant's day after rain: the same relief, wet soft earth.
  const Scenario rough = load_scenario(kScenes + "plants/plant_10mw_tracker_rough.yaml");
  const Scenario wet = load_scenario(kScenes + "days/plant_10mw_tracker_rough_wet.yaml");
  ASSERT_TRUE(wet.ground.relief && rough.ground.relief);
  EXPECT_EQ(wet.ground.relief->slope_percent, rough.ground.relief->slope_percent);
  EXPECT_EQ(wet.ground.friction, 0.4);
  EXPECT_FALSE(rough.ground.friction.has_value());
}
