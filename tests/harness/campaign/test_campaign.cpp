// Campaign files: the sessions, their modes and maps, and every mistake as
// one error naming the file, the line and the key.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <atomic>
#include <filesystem>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/campaign/campaign.hpp"
#include "pvb/campaign/campaign_run.hpp"
#include "pvb/suite/campaign_aggregate.hpp"

using namespace pvb;

namespace {

const std::string kCampaigns = std::string(PVB_SOURCE_DIR) + "/campaigns/";

std::string error_of(const std::string& text) {
  const std::string dir = ::testing::TempDir() + "pvb_campaign_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const std::string station = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  std::string body = text;
  for (std::size_t at; (at = body.find("STATION")) != std::string::npos;) body.replace(at, 7, station);
  write_file(dir + "/c.yaml", body);
  try {
    run::load_campaign(dir + "/c.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Campaign, ShippedCampaignsLoad) {
  for (const char* name : {"daily", "trackers", "same_day", "plant_10mw_fixed_daily",
                           "plant_10mw_tracker_daily", "plant_10mw_tracker_rough_daily"}) {
    const run::Campaign c = run::load_campaign(kCampaigns + name + ".yaml");
    EXPECT_EQ(c.name, name);
    ASSERT_GE(c.sessions.size(), 3u) << name;
    EXPECT_EQ(c.sessions[0].mode, run::SessionMode::kMap) << name;
    for (std::size_t i = 1; i < c.sessions.size(); ++i) {
      EXPECT_EQ(c.sessions[i].mode, run::SessionMode::kLocalise) << name;
      EXPECT_EQ(c.sessions[i].map, c.sessions[0].name) << name;
      EXPECT_TRUE(std::filesystem::exists(c.sessions[i].scenario_file)) << c.sessions[i].scenario_file;
    }
  }
  // A growing map: each day extends the map of the day before.
  for (const char* name : {"growing", "plant_10mw_fixed_growing", "plant_10mw_tracker_growing",
                           "plant_10mw_tracker_rough_growing"}) {
    const run::Campaign c = run::load_campaign(kCampaigns + name + ".yaml");
    ASSERT_GE(c.sessions.size(), 5u) << name;
    EXPECT_EQ(c.sessions[0].mode, run::SessionMode::kMap) << name;
    for (std::size_t i = 1; i < c.sessions.size(); ++i) {
      EXPECT_EQ(c.sessions[i].mode, run::SessionMode::kExtend) << name;
      EXPECT_EQ(c.sessions[i].map, c.sessions[i - 1].name) << name;
      EXPECT_TRUE(c.sessions[i].start_m.has_value()) << name;
    }
  }
  const run::Campaign same = run::load_campaign(kCampaigns + "same_day.yaml");
  EXPECT_FALSE(same.sessions[1].start_m.has_value());
  EXPECT_DOUBLE_EQ(same.sessions[2].start_m.value_or(-1), 3.0);
}

TEST(Campaign, MistakesAreOneLineNamingFileLineAndKey) {
  std::string e = error_of("name: c\nsessions:\n  - {name: a, scenario: STATION, mode: fly}\n");
  EXPECT_NE(e.find("c.yaml:3: sessions[0].mode: expected one of map, localise, extend, got fly"), std::string::npos) << e;
  e = error_of("name: c\nsessions:\n  - {name: a, scenario: STATION, mode: localise}\n");
  EXPECT_NE(e.find("c.yaml:3: sessions[0].map: expected the earlier session whose map it starts from"), std::string::npos)
      << e;
  e = error_of("name: c\nsessions:\n  - {name: a, scenario: STATION, mode: localise, map: b}\n"
               "  - {name: b, scenario: STATION, mode: map}\n");
  EXPECT_NE(e.find("sessions[0].map: expected the name of an earlier session, got b"), std::string::npos) << e;
  e = error_of("name: c\nsessions:\n  - {name: a, scenario: STATION, mode: map}\n"
               "  - {name: b, scenario: STATION, mode: localise, map: a}\n"
               "  - {name: c, scenario: STATION, mode: localise, map: b}\n");
  EXPECT_NE(e.find("c.yaml:5: sessions[2].map: expected a session that leaves a map (map or extend), got b (localise)"),
            std::string::npos)
      << e;
  e = error_of("name: c\nsessions:\n  - {name: a, scenario: STATION, mode: map}\n  - {name: a, scenario: STATION, mode: map}\n");
  EXPECT_NE(e.find("c.yaml:4: sessions[1].name: expected a name no other session has, got a"), std::string::npos) << e;
  e = error_of("name: c\nsessions:\n  - {name: a, scenario: nowhere.yaml, mode: map}\n");
  EXPECT_NE(e.find("sessions[0].scenario: expected an existing scenario file"), std::string::npos) << e;
  e = error_of("name: c\nsessions:\n  - {name: a, scenario: STATION, mode: map, speed: 3}\n");
  EXPECT_NE(e.find("sessions[0].speed: expected a known key"), std::string::npos) << e;
  e = error_of("name: c\nname: d\nsessions: []\n");
  EXPECT_NE(e.find("c.yaml:2: name: expected each key once"), std::string::npos) << e;
  e = error_of("name: c\nsessions: []\n");
  EXPECT_NE(e.find("sessions: expected a list of at least one session"), std::string::npos) << e;
}

// A campaign is read by the scenarios' strict reader: a key given twice in
// a session, an unknown key and a wrong type each name the line and the key.
TEST(Campaign, SessionsAreReadStrictly) {
  std::string e = error_of("name: c\nsessions:\n  - {name: a, scenario: STATION, mode: map, name: b}\n");
  EXPECT_NE(e.find("c.yaml:3: sessions[0].name: expected each key once in its section (first given at line 3), got a "
                   "second name"),
            std::string::npos)
      << e;
  e = error_of("name: c\nsessions:\n  - name: a\n    scenario: STATION\n    mode: map\n    mode: extend\n");
  EXPECT_NE(e.find("c.yaml:6: sessions[0].mode: expected each key once in its section (first given at line 5)"),
            std::string::npos)
      << e;
  e = error_of("name: c\nsessions:\n  - name: a\n    scenario: STATION\n    mode: map\n    start: 3\n");
  EXPECT_NE(e.find("c.yaml:6: sessions[0].start: expected a known key (map, mode, name, scenario, start_m), got unknown "
                   "key"),
            std::string::npos)
      << e;
  e = error_of("name: c\nsessions:\n  - name: a\n    scenario: STATION\n    mode: [map]\n");
  EXPECT_NE(e.find("c.yaml:5: sessions[0].mode: expected a non-empty string"), std::string::npos) << e;
  e = error_of("name: c\nsessions:\n  - name: a\n    scenario: STATION\n    mode: map\n    start_m: near\n");
  EXPECT_NE(e.find("c.yaml:6: sessions[0].start_m: expected a distance along the route in metres, >= 0, got near"),
            std::string::npos)
      << e;
  e = error_of("description: d\nsessions:\n  - {name: a, scenario: STATION, mode: map}\n");
  EXPECT_NE(e.find("c.yaml:1: name: expected a value (required)"), std::string::npos) << e;
}

// A session may not take the name of what the campaign writes beside the
// sessions' folders: a session "maps" would run in the maps folder.
TEST(Campaign, ANameTheCampaignWritesItselfIsRefused) {
  const std::string e = error_of(
      "name: c\nsessions:\n  - {name: noon, scenario: STATION, mode: map}\n"
      "  - {name: maps, scenario: STATION, mode: localise, map: noon}\n");
  EXPECT_NE(
      e.find("c.yaml:4: sessions[1].name: expected a name other than those the campaign writes beside the "
             "sessions' folders (maps, campaign.json, campaign.md, matrix.svg, matrix.png, index.html, "
             "stdout.log), got maps"),
      std::string::npos)
      << e;
  EXPECT_EQ(run::campaign_top_level_names().front(), "maps");
}

// Every session's scenario is loaded with the file: a later session's bad
// scenario or start beyond its route fails before any session runs.
TEST(Campaign, EverySessionsScenarioAndStartAreCheckedWithTheFile) {
  std::string e = error_of(
      "name: c\nsessions:\n  - {name: a, scenario: STATION, mode: map}\n"
      "  - {name: b, scenario: STATION, mode: localise, map: a, start_m: 500}\n");
  EXPECT_NE(
      e.find("c.yaml:4: sessions[1].start_m: expected a distance from 0 to 1 m before the route's end (the "
             "route of "),
      std::string::npos)
      << e;
  EXPECT_NE(e.find("/scenes/pv_station.yaml is "), std::string::npos) << e;
  EXPECT_NE(e.find(" m long), got 500"), std::string::npos) << e;
  const std::string dir = ::testing::TempDir() + "pvb_campaign_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  write_file(dir + "/bad_day.yaml",
             "base: " + std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml\nspeed: 3\n");
  e = error_of(
      "name: c\nsessions:\n  - {name: a, scenario: STATION, mode: map}\n"
      "  - {name: b, scenario: bad_day.yaml, mode: localise, map: a}\n");
  EXPECT_NE(e.find("bad_day.yaml:2: speed"), std::string::npos) << e;
  // The scenario's own seed is kept for a campaign run without --seed.
  const run::Campaign daily = run::load_campaign(kCampaigns + "daily.yaml");
  EXPECT_EQ(daily.sessions[0].scenario_seed, 71200u);
}

namespace {

/// A campaign of five sessions on the default station (every status a
/// session can end with).
run::Campaign five_sessions() {
  const std::string dir = ::testing::TempDir() + "pvb_campaign_five_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const std::string station = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  write_file(dir + "/five.yaml",
             "name: five\nsessions:\n"
             "  - {name: noon, scenario: " +
                 station +
                 ", mode: map}\n"
                 "  - {name: again, scenario: " +
                 station +
                 ", mode: localise, map: noon}\n"
                 "  - {name: more, scenario: " +
                 station +
                 ", mode: extend, map: noon}\n"
                 "  - {name: after, scenario: " +
                 station +
                 ", mode: localise, map: more}\n"
                 "  - {name: last, scenario: " +
                 station + ", mode: localise, map: noon}\n");
  return run::load_campaign(dir + "/five.yaml");
}

std::vector<std::string> table_rows(const std::string& md) {
  std::vector<std::string> rows;
  std::size_t at = 0;
  for (std::size_t nl; (nl = md.find('\n', at)) != std::string::npos; at = nl + 1)
    if (md.compare(at, 2, "| ") == 0) rows.push_back(md.substr(at, nl - at));
  return rows;
}

}  // namespace

// A session that did not complete is shown with its status, and a figure
// it lacks is null in campaign.json and "-" in campaign.md, never 0.
TEST(CampaignReport, EverySessionHasARowWithItsStatusAndNoInventedFigures) {
  run::CampaignReport r;
  r.campaign = five_sessions();
  r.seed = 4;
  r.stopped = true;
  const run::SessionStatus statuses[] = {run::SessionStatus::kCompleted, run::SessionStatus::kInterrupted,
                                         run::SessionStatus::kFailed, run::SessionStatus::kSkipped,
                                         run::SessionStatus::kNotRun};
  for (std::size_t i = 0; i < 5; ++i) {
    run::SessionResult s;
    s.session = r.campaign.sessions[i];
    s.seed = 4000 + i;
    s.status = statuses[i];
    if (s.ran()) s.frames = 90, s.lost_frames = 2, s.keyframes = 12, s.tracking_ms_median = 9.5;
    if (s.status == run::SessionStatus::kFailed) s.error = "out/more/metrics.json: cannot write";
    if (s.status == run::SessionStatus::kSkipped) s.error = "session more left no map (out/maps/more.pvbmap)";
    r.sessions.push_back(s);
  }
  const YAML::Node j = YAML::Load(run::campaign_json(r));
  EXPECT_EQ(j["campaign_version"].as<int>(), 2);
  ASSERT_EQ(j["sessions"].size(), 5u);
  const char* expected[] = {"completed", "interrupted", "failed", "skipped", "not_run"};
  for (std::size_t i = 0; i < 5; ++i) {
    const YAML::Node s = j["sessions"][i];
    EXPECT_EQ(s["status"].as<std::string>(), expected[i]);
    EXPECT_EQ(s["seed"].as<int>(), 4000 + static_cast<int>(i));
    EXPECT_EQ(s["tracking_ms_median"].IsNull(), i >= 2) << i;
    EXPECT_EQ(s["frames"].IsNull(), i >= 2) << i;
    EXPECT_EQ(s["keyframes"].IsNull(), i >= 2) << i;
  }
  EXPECT_EQ(j["sessions"][2]["error"].as<std::string>(), "out/more/metrics.json: cannot write");

  const std::vector<std::string> rows = table_rows(run::campaign_markdown(r));
  ASSERT_EQ(rows.size(), 6u);  // the header and a row per session
  EXPECT_EQ(rows[1].rfind("| noon | map | - | completed | 90 | 2 | 12 (0) |", 0), 0u) << rows[1];
  EXPECT_NE(rows[1].find("| 9.50 |"), std::string::npos) << rows[1];
  EXPECT_EQ(rows[2].rfind("| again | localise | noon | interrupted | 90 |", 0), 0u) << rows[2];
  EXPECT_EQ(
      rows[3].rfind("| more | extend | noon | failed: out/more/metrics.json: cannot write | - | - | - |", 0),
      0u)
      << rows[3];
  EXPECT_EQ(rows[3].find("0.00"), std::string::npos) << rows[3];
  EXPECT_EQ(rows[4].rfind("| after | localise | more | skipped: session more left no map", 0), 0u) << rows[4];
  EXPECT_EQ(rows[5].rfind("| last | localise | noon | not run (the campaign was stopped) | - | - | - |", 0),
            0u)
      << rows[5];

  // The page links the reports that exist and names the sessions without one.
  const std::string html = run::campaign_html(r, run::campaign_markdown(r));
  EXPECT_NE(html.find("<a href=\"again/index.html\">again</a> (interrupted)"), std::string::npos) << html;
  EXPECT_EQ(html.find("href=\"last/index.html\""), std::string::npos) << html;
  EXPECT_NE(html.find("<li>last: not run (the campaign was stopped)</li>"), std::string::npos) << html;
  EXPECT_EQ(run::campaign_exit_code(r), 130);
  r.stopped = false;
  EXPECT_EQ(run::campaign_exit_code(r), 3);
}

// A campaign stopped before its first session lists every session as not
// run, in campaign.json and in campaign.md.
TEST(CampaignReport, AStoppedCampaignListsTheSessionsItDidNotRun) {
  const std::string out = ::testing::TempDir() + "pvb_campaign_stopped_" + std::to_string(::getpid());
  std::filesystem::remove_all(out);
  const run::Campaign c = five_sessions();
  std::atomic<bool> stop{true};
  run::CampaignOptions o;
  o.campaign_file = c.file;
  o.out_dir = out;
  o.seed = 2;
  o.stop = &stop;
  const run::CampaignReport r = run::run_campaign(o);
  EXPECT_TRUE(r.stopped);
  ASSERT_EQ(r.sessions.size(), 5u);
  const YAML::Node j = YAML::Load(read_file(out + "/campaign.json"));
  ASSERT_EQ(j["sessions"].size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(j["sessions"][i]["name"].as<std::string>(), c.sessions[i].name);
    EXPECT_EQ(j["sessions"][i]["status"].as<std::string>(), "not_run");
    EXPECT_EQ(j["sessions"][i]["seed"].as<int>(), 2000 + static_cast<int>(i));
  }
  const std::vector<std::string> rows = table_rows(read_file(out + "/campaign.md"));
  ASSERT_EQ(rows.size(), 6u);
  for (std::size_t i = 1; i < rows.size(); ++i)
    EXPECT_NE(rows[i].find(" | not run (the campaign was stopped) | "), std::string::npos) << rows[i];
  EXPECT_NE(read_file(out + "/index.html").find("<li>noon: not run (the campaign was stopped)</li>"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(out + "/noon"));
  // The sweep's aggregate reads what the campaign writes, as this campaign's file of seed 2.
  EXPECT_EQ(run::kCampaignJsonVersion, suite::kCampaignVersionRead);
  const suite::CampaignSeed read = suite::read_campaign_seed(2, out + "/campaign.json");
  EXPECT_EQ(read.error, "");
  suite::ExpectedCampaign expected{c.file, c.name, {}};
  for (const run::CampaignSession& s : c.sessions)
    expected.sessions.push_back({s.name, run::to_string(s.mode), s.map});
  EXPECT_NO_THROW(suite::expect_campaign_identity(read, expected));
  ASSERT_EQ(read.sessions.size(), 5u);
  EXPECT_EQ(read.sessions[4].status, "not_run");
  EXPECT_FALSE(read.sessions[4].frames.has_value());
  std::filesystem::remove_all(out);
}

// Sessions that fail are stored with their real status and no figures: the
// first run cannot start (an unknown GL backend), so the second, which
// needs its map, is skipped.  A stop that comes during the last session
// stops the campaign (exit 130).
TEST(CampaignReport, FailedAndSkippedSessionsKeepTheirStatusAndNoFigures) {
  const std::string out = ::testing::TempDir() + "pvb_campaign_failed_" + std::to_string(::getpid());
  std::filesystem::remove_all(out);
  const run::Campaign c = five_sessions();
  std::atomic<bool> stop{false};
  run::CampaignOptions o;
  o.campaign_file = c.file;
  o.out_dir = out;
  o.gl = "vulkan";
  o.stop = &stop;
  o.on_log = [&](const std::string& line) {
    if (line.rfind("[last] ", 0) == 0) stop = true;
  };
  const run::CampaignReport r = run::run_campaign(o);
  const YAML::Node j = YAML::Load(read_file(out + "/campaign.json"));
  ASSERT_EQ(j["sessions"].size(), 5u);
  EXPECT_EQ(j["sessions"][0]["status"].as<std::string>(), "failed");
  EXPECT_NE(j["sessions"][0]["error"].as<std::string>().find("vulkan"), std::string::npos);
  EXPECT_TRUE(j["sessions"][0]["tracking_ms_median"].IsNull());
  EXPECT_TRUE(j["sessions"][0]["frames"].IsNull());
  EXPECT_EQ(j["sessions"][0]["seed"].as<std::uint64_t>(), c.sessions[0].scenario_seed);  // no --seed
  for (std::size_t i = 1; i < 5; ++i) {
    EXPECT_EQ(j["sessions"][i]["status"].as<std::string>(), "skipped") << i;
    EXPECT_TRUE(j["sessions"][i]["tracking_ms_median"].IsNull()) << i;
  }
  const std::vector<std::string> rows = table_rows(read_file(out + "/campaign.md"));
  ASSERT_EQ(rows.size(), 6u);
  EXPECT_NE(rows[1].find("| noon | map | - | failed: "), std::string::npos) << rows[1];
  EXPECT_EQ(rows[1].find("0.00"), std::string::npos) << rows[1];
  EXPECT_TRUE(r.stopped);
  EXPECT_EQ(run::campaign_exit_code(r), 130);
  std::filesystem::remove_all(out);
}
