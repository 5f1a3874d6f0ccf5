// Campaign files: the sessions, their modes and maps, and every mistake as
// one error naming the file, the line and the key.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/run/campaign.hpp"

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
  for (const char* name : {"daily", "trackers", "same_day"}) {
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

// A session may not take the name of what the campaign writes beside the
// sessions' folders: a session "maps" would run in the maps folder.
TEST(Campaign, ANameTheCampaignWritesItselfIsRefused) {
  const std::string e = error_of("name: c\nsessions:\n  - {name: noon, scenario: STATION, mode: map}\n"
                                 "  - {name: maps, scenario: STATION, mode: localise, map: noon}\n");
  EXPECT_NE(e.find("c.yaml:4: sessions[1].name: expected a name other than those the campaign writes beside the "
                   "sessions' folders (maps, campaign.json, campaign.md, matrix.svg, matrix.png, index.html, "
                   "stdout.log), got maps"),
            std::string::npos)
      << e;
  EXPECT_EQ(run::campaign_top_level_names().front(), "maps");
}

// Every session's scenario is loaded with the file: a later session's bad
// scenario or start beyond its route fails before any session runs.
TEST(Campaign, EverySessionsScenarioAndStartAreCheckedWithTheFile) {
  std::string e = error_of("name: c\nsessions:\n  - {name: a, scenario: STATION, mode: map}\n"
                           "  - {name: b, scenario: STATION, mode: localise, map: a, start_m: 500}\n");
  EXPECT_NE(e.find("c.yaml:4: sessions[1].start_m: expected a distance from 0 to 1 m before the route's end (the "
                   "route of "),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("/scenes/pv_station.yaml is "), std::string::npos) << e;
  EXPECT_NE(e.find(" m long), got 500"), std::string::npos) << e;
  const std::string dir = ::testing::TempDir() + "pvb_campaign_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  write_file(dir + "/bad_day.yaml", "base: " + std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml\nspeed: 3\n");
  e = error_of("name: c\nsessions:\n  - {name: a, scenario: STATION, mode: map}\n"
               "  - {name: b, scenario: bad_day.yaml, mode: localise, map: a}\n");
  EXPECT_NE(e.find("bad_day.yaml:2: speed"), std::string::npos) << e;
  // The scenario's own seed is kept for a campaign run without --seed.
  const run::Campaign daily = run::load_campaign(kCampaigns + "daily.yaml");
  EXPECT_EQ(daily.sessions[0].scenario_seed, 71200u);
}
