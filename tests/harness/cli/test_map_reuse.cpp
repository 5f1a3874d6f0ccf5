// Map reuse end to end: a short campaign (a map at noon, the same drive
// again with another noise seed localised in it from part-way along, and a
// session that extends the map), judged against ground truth in the map's
// frame; and the map options' bad input.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <optional>

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

// Ctrl-C during the first session: that session is reported as
// interrupted, the sessions after it as not run, in campaign.json,
// campaign.md and index.html; the campaign exits 130.
TEST(MapReuse, ACampaignStoppedByCtrlCListsEverySessionWithItsStatus) {
  const std::string d = fresh("campaign_sigint");
  write_file(d + "/three.yaml", "name: three\nsessions:\n"
                                "  - {name: noon, scenario: " + kNoon + ", mode: map}\n"
                                "  - {name: again, scenario: " + kNoon + ", mode: localise, map: noon}\n"
                                "  - {name: more, scenario: " + kNoon + ", mode: extend, map: noon}\n");
  const std::string log = d + "/stdout.txt";
  const pid_t pid = test::spawn_pvbench({"campaign", "--campaign", d + "/three.yaml", "--frames", "600", "--sync",
                                         "--no-map-eval", "--seed", "2", "--out", d + "/out"},
                                        log);
  ASSERT_GE(pid, 0);
  const auto lines = [](const std::string& path) {
    std::ifstream in(path);
    int n = 0;
    for (std::string line; std::getline(in, line);) n += !line.empty() && line[0] != '#';
    return n;
  };
  ASSERT_TRUE(test::wait_until(pid, [&] { return lines(d + "/out/noon/CameraTrajectory.txt") >= 5; }, 300))
      << read_file(log);
  const std::optional<int> ended = test::interrupt_and_wait(pid, 120);
  ASSERT_TRUE(ended.has_value()) << read_file(log);
  EXPECT_TRUE(WIFEXITED(*ended) && WEXITSTATUS(*ended) == 130) << read_file(log);
  const YAML::Node c = YAML::Load(read_file(d + "/out/campaign.json"));
  ASSERT_EQ(c["sessions"].size(), 3u);
  EXPECT_EQ(c["sessions"][0]["status"].as<std::string>(), "interrupted");
  EXPECT_GE(c["sessions"][0]["frames"].as<int>(), 5);
  EXPECT_LT(c["sessions"][0]["frames"].as<int>(), 600);
  for (int i : {1, 2}) {
    EXPECT_EQ(c["sessions"][i]["status"].as<std::string>(), "not_run") << i;
    EXPECT_TRUE(c["sessions"][i]["frames"].IsNull()) << i;
  }
  const std::string md = read_file(d + "/out/campaign.md");
  EXPECT_NE(md.find("| noon | map | - | interrupted | "), std::string::npos) << md;
  EXPECT_NE(md.find("| again | localise | noon | not run (the campaign was stopped) | - |"), std::string::npos) << md;
  EXPECT_NE(md.find("| more | extend | noon | not run (the campaign was stopped) | - |"), std::string::npos) << md;
  const std::string html = read_file(d + "/out/index.html");
  EXPECT_NE(html.find("<a href=\"noon/index.html\">noon</a> (interrupted)"), std::string::npos) << html;
  EXPECT_NE(html.find("<li>more: not run (the campaign was stopped)</li>"), std::string::npos) << html;
}

TEST(MapReuse, MapOptionsThatDoNotFitAreOneErrorLine) {
  const std::string d = fresh("options");
  const std::string run = "run --scenario " + kNoon + " --frames 5 --sync --no-map-eval --out " + d + "/x";
  const auto no_map = test::run_pvbench(run + " --map-mode localise");
  EXPECT_EQ(no_map.code, 1);
  EXPECT_EQ(
      no_map.output,
      "pvbench: error: command line: --map: expected the saved map to localise (--map-mode needs it)\n");
  write_file(d + "/junk.pvbmap", "not a map at all");
  const auto save_loc = test::run_pvbench(run + " --map " + d + "/junk.pvbmap --map-mode localise --save-map " + d + "/y");
  EXPECT_NE(save_loc.code, 0);
  EXPECT_NE(save_loc.output.find("--save-map"), std::string::npos) << save_loc.output;
  const auto bad_mode = test::run_pvbench(run + " --map " + d + "/junk.pvbmap --map-mode relocate");
  EXPECT_EQ(bad_mode.code, 1);
  EXPECT_EQ(bad_mode.output,
            "pvbench: error: command line: --map-mode: expected localise or extend, got relocate\n");
  // A start beyond the route is named by its option, with the route's length.
  const auto far = test::run_pvbench(run + " --start-m 500");
  EXPECT_EQ(far.code, 1);
  EXPECT_EQ(far.output.rfind(
                "pvbench: error: command line: --start-m: expected a distance from 0 to 1 m before the "
                "route's end (",
                0),
            0u)
      << far.output;
  EXPECT_NE(far.output.find(" m long), got 500\n"), std::string::npos) << far.output;
  EXPECT_FALSE(exists(d + "/x/metrics.json"));
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
