// Map reuse end to end: a short campaign (a map at noon, the same drive
// again with another noise seed localised in it from part-way along, and a
// session that extends the map), judged against ground truth in the map's
// frame; and the map options' bad input.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <fstream>

#include "pvb/common/text.hpp"
#include "campaign_session.hpp"
#include "run_pvbench.hpp"

using namespace pvb;

namespace {

const std::string kNoon = std::string(PVB_SOURCE_DIR) + "/scenes/days/pv_station_1200.yaml";

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_map_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + d + " && mkdir -p " + d).c_str());
  return d;
}

bool exists(const std::string& path) { return std::ifstream(path).good(); }

using test::campaign_session;

TEST(MapReuse, ACampaignMapsLocalisesAndExtendsJudgedInTheMapsFrame) {
  const std::string d = fresh("campaign");
  write_file(d + "/short.yaml", "name: short\nsessions:\n"
                                "  - {name: noon, scenario: " + kNoon + ", mode: map}\n"
                                "  - {name: again, scenario: " + kNoon + ", mode: localise, map: noon, start_m: 0.4}\n"
                                "  - {name: more, scenario: " + kNoon + ", mode: extend, map: noon, start_m: 0.6}\n");
  const auto r = test::run_pvbench("campaign --campaign " + d + "/short.yaml --frames 90 --sync --no-map-eval --seed 3 --out " +
                                   d + "/out");
  ASSERT_EQ(r.code, 0) << r.output;
  const YAML::Node c = YAML::Load(read_file(d + "/out/campaign.json"));
  EXPECT_EQ(c["seed"].as<int>(), 3);
  const YAML::Node noon = campaign_session(c, "noon"), again = campaign_session(c, "again"),
                   more = campaign_session(c, "more");
  EXPECT_EQ(noon["seed"].as<int>(), 3000);
  EXPECT_EQ(again["seed"].as<int>(), 3001);
  // The same conditions with other noise, from 0.4 m along: found at once,
  // in the right place, and the map is not changed.
  const YAML::Node loc = again["map_report"]["localisation"];
  ASSERT_TRUE(loc.IsMap()) << r.output;
  EXPECT_EQ(loc["wrong_place"].as<int>(), 0);
  EXPECT_LE(loc["first_pose_frame"].as<int>(), 30);
  EXPECT_GE(loc["within"]["high"]["share"].as<double>(), 0.9);
  EXPECT_EQ(again["keyframes"].as<int>(), again["keyframes_loaded"].as<int>());
  EXPECT_EQ(again["keyframes_loaded"].as<int>(), noon["keyframes"].as<int>());
  // Extending adds keyframes beyond the mapped ground and saves both sessions.
  EXPECT_GT(more["keyframes"].as<int>(), more["keyframes_loaded"].as<int>());
  EXPECT_EQ(more["map_report"]["saved"]["sessions"].as<int>(), 2);
  EXPECT_EQ(more["map_report"]["localisation"]["wrong_place"].as<int>(), 0);
  for (const char* f : {"/out/maps/noon.pvbmap", "/out/maps/more.pvbmap", "/out/matrix.png", "/out/matrix.svg",
                        "/out/campaign.md", "/out/index.html", "/out/again/metrics.json"})
    EXPECT_TRUE(exists(d + f)) << f;
  // The localise run's own report carries the same scores.
  const YAML::Node m = YAML::Load(read_file(d + "/out/again/metrics.json"));
  EXPECT_EQ(m["map"]["use"].as<std::string>(), "localise");
  EXPECT_EQ(m["map"]["localisation"]["wrong_place"].as<int>(), 0);
}

TEST(MapReuse, MapOptionsThatDoNotFitAreOneErrorLine) {
  const std::string d = fresh("options");
  const std::string run = "run --scenario " + kNoon + " --frames 5 --sync --no-map-eval --out " + d + "/x";
  const auto no_map = test::run_pvbench(run + " --map-mode localise");
  EXPECT_NE(no_map.code, 0);
  EXPECT_NE(no_map.output.find("--map"), std::string::npos) << no_map.output;
  write_file(d + "/junk.pvbmap", "not a map at all");
  const auto save_loc = test::run_pvbench(run + " --map " + d + "/junk.pvbmap --map-mode localise --save-map " + d + "/y");
  EXPECT_NE(save_loc.code, 0);
  EXPECT_NE(save_loc.output.find("--save-map"), std::string::npos) << save_loc.output;
  const auto bad_mode = test::run_pvbench(run + " --map " + d + "/junk.pvbmap --map-mode relocate");
  EXPECT_NE(bad_mode.code, 0);
  EXPECT_NE(bad_mode.output.find("localise or extend"), std::string::npos) << bad_mode.output;
  const auto junk = test::run_pvbench(run + " --map " + d + "/junk.pvbmap --map-mode localise");
  EXPECT_NE(junk.code, 0);
  EXPECT_NE(junk.output.find(d + "/junk.pvbmap: not a map file"), std::string::npos) << junk.output;
}

// A map shows its station (META): pvbench run on another station (here
// the station seed) refuses it, unless --allow-other-station, which uses it
// after a warning.
TEST(MapReuse, RunRefusesAMapOfAnotherStationUnlessAllowed) {
  const std::string d = fresh("station");
  const std::string station = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  const std::string run = "run --scenario " + station + " --frames 3 --sync --no-map-eval";
  const auto made = test::run_pvbench(run + " --save-map " + d + "/seed7.pvbmap --out " + d + "/made");
  ASSERT_EQ(made.code, 0) << made.output;
  const std::string other = run + " --seed 8 --map " + d + "/seed7.pvbmap --map-mode localise";
  const auto refused = test::run_pvbench(other + " --out " + d + "/refused");
  EXPECT_NE(refused.code, 0);
  EXPECT_NE(refused.output.find(
                d + "/seed7.pvbmap: META station: expected a map of this run's station, pv_station, "
                    "station seed 8 (--allow-other-station uses it all the same), got pv_station, "
                    "station seed 7"),
            std::string::npos)
      << refused.output;
  const auto allowed = test::run_pvbench(other + " --allow-other-station --out " + d + "/allowed");
  EXPECT_EQ(allowed.code, 0) << allowed.output;
  EXPECT_NE(allowed.output.find("pvbench: warning: the map " + d +
                                "/seed7.pvbmap shows pv_station, station seed 7"),
            std::string::npos)
      << allowed.output;
}

}  // namespace
