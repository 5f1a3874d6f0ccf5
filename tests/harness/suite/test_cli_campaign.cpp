// pvbench campaign and sweep --campaign without a session run: a campaign
// file that cannot run is refused before any work, and --aggregate-only
// over seed folders of hand-written campaign.json files (fixtures/
// campaign.json, changed by each test) takes only this campaign's files,
// of the folder's seed, whole and in range.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <regex>
#include <string>

#include "pvb/common/text.hpp"
#include "run_pvbench.hpp"

namespace fs = std::filesystem;
using pvb::test::run_pvbench;

namespace {

const std::string kNoon = std::string(PVB_SOURCE_DIR) + "/scenes/days/pv_station_1200.yaml";

std::string scratch(const std::string& name) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("pvb_cli_campaign_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

/// The campaign of fixtures/campaign.json: noon (map), again (localise),
/// more (extend); `extra` is appended to the session list.
std::string campaign_file(const std::string& dir, const std::string& extra = "") {
  const std::string path = dir + "/short.yaml";
  pvb::write_file(path,
                  "name: short\nsessions:\n"
                  "  - {name: noon, scenario: " +
                      kNoon +
                      ", mode: map}\n"
                      "  - {name: again, scenario: " +
                      kNoon +
                      ", mode: localise, map: noon, start_m: 0.4}\n"
                      "  - {name: more, scenario: " +
                      kNoon + ", mode: extend, map: noon, start_m: 0.6}\n" + extra);
  return path;
}

/// fixtures/campaign.json as the campaign of seed `seed` wrote it.
std::string campaign_json(int seed) {
  std::string text =
      pvb::read_file(std::string(PVB_SOURCE_DIR) + "/tests/harness/suite/fixtures/campaign.json");
  text = std::regex_replace(text, std::regex("\"seed\": 1,"), "\"seed\": " + std::to_string(seed) + ",");
  for (int i = 0; i < 3; ++i)
    text = std::regex_replace(text, std::regex("\"seed\": 100" + std::to_string(i)),
                              "\"seed\": " + std::to_string(seed * 1000 + i));
  return text;
}

/// A sweep folder with seed_1 and seed_2 as their campaigns wrote them.
std::string sweep_folder(const std::string& name) {
  const std::string out = scratch(name);
  for (int seed : {1, 2}) {
    fs::create_directories(out + "/seed_" + std::to_string(seed));
    pvb::write_file(out + "/seed_" + std::to_string(seed) + "/campaign.json", campaign_json(seed));
  }
  return out;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

}  // namespace

TEST(CliCampaignSweep, AggregateOnlyCollectsEverySessionOverTheSeeds) {
  const std::string out = sweep_folder("good");
  const auto r =
      run_pvbench("sweep --campaign " + campaign_file(out) + " --out " + out + " --aggregate-only");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string md = pvb::read_file(out + "/aggregate.md");
  EXPECT_NE(md.find("# Campaign short over 2 seeds"), std::string::npos) << md;
  EXPECT_NE(md.find("| noon | map | - | 2 (0) | - | - | - | - | 20.0 | 10.50 |"), std::string::npos) << md;
  EXPECT_NE(
      md.find(
          "| again | localise | noon | 2 (0) | 95.0 ± 0.0 % (min 95.0 %) | 97.0 ± 0.0 % (min 97.0 %) | 0 |"),
      std::string::npos)
      << md;
  EXPECT_NE(md.find("| more | extend | noon | 2 (0) |"), std::string::npos) << md;
  EXPECT_TRUE(fs::exists(out + "/matrix.png"));
}

// Another campaign's file, another seed's, or one whose sessions are not
// the campaign file's: one error line naming the file and the key, exit 1.
TEST(CliCampaignSweep, AggregateOnlyRefusesTheFileOfAnotherCampaignOrSeed) {
  const std::string out = sweep_folder("identity");
  const std::string cmd = "sweep --campaign " + campaign_file(out) + " --out " + out + " --aggregate-only";
  const std::string file = out + "/seed_2/campaign.json";
  const std::string good = campaign_json(2);
  const auto refused = [&](const std::string& text, const std::string& line) {
    pvb::write_file(file, text);
    const auto r = run_pvbench(cmd);
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_EQ(count_lines(r.output), 1) << r.output;
    EXPECT_EQ(r.output, "pvbench: error: " + file + ": " + line + "\n");
  };
  refused(replaced(good, "\"campaign\": \"short\"", "\"campaign\": \"daily\""),
          "campaign: expected a run of short (" + out + "/short.yaml), got daily");
  refused(replaced(good, "\"seed\": 2,", "\"seed\": 7,"), "seed: expected 2 (the folder seed_2), got 7");
  refused(replaced(good, "\"name\": \"again\"", "\"name\": \"again2\""),
          "sessions[1].name: expected again (session 2 of " + out + "/short.yaml), got again2");
  refused(replaced(good, "\"mode\": \"localise\"", "\"mode\": \"extend\""),
          "sessions[1].mode: expected localise (session 2 of " + out + "/short.yaml), got extend");
  refused(replaced(good, "\"seed\": 2001", "\"seed\": 7001"),
          "sessions[1].seed: expected 2001 (the folder seed_2 x 1000 + 1), got 7001");
  const std::size_t third = good.find(",\n    {\"name\": \"more\"");
  ASSERT_NE(third, std::string::npos);
  refused(good.substr(0, third) + "\n  ]\n}\n",
          "sessions: expected 3 sessions (those of " + out + "/short.yaml), got 2");
}

// A file that is not whole, of a newer version, or with a value out of its
// range is that seed's failure, named with the file, the line and the key,
// and left out of the means (exit 3); a share of 7.5 is never averaged.
TEST(CliCampaignSweep, AggregateOnlyLeavesOutBrokenFilesNamingTheField) {
  const std::string out = sweep_folder("broken");
  const std::string cmd = "sweep --campaign " + campaign_file(out) + " --out " + out + " --aggregate-only";
  const std::string file = out + "/seed_2/campaign.json";
  const std::string good = campaign_json(2);
  const auto left_out = [&](const std::string& text, const std::string& line) {
    pvb::write_file(file, text);
    const auto r = run_pvbench(cmd);
    EXPECT_EQ(r.code, 3) << r.output;
    EXPECT_NE(r.output.find("- seed 2: " + file + ":" + line + "\n"), std::string::npos) << r.output;
    const std::string md = pvb::read_file(out + "/aggregate.md");
    EXPECT_NE(md.find("| again | localise | noon | 1 (0) | 95.0 ± 0.0 % (min 95.0 %) |"), std::string::npos)
        << md;
  };
  left_out(replaced(good, "\"campaign_version\": 2", "\"campaign_version\": 99"),
           "2: campaign_version: expected an integer in [1, 2], got 99");
  left_out(replaced(good, "\"share\": 0.95", "\"share\": 7.5"),
           "9: sessions[1].map_report.localisation.within.fine.share: expected a number in [0, 1], got 7.5");
  left_out(replaced(good, "\"share\": 0.95", "\"share\": NaN"),
           "9: sessions[1].map_report.localisation.within.fine.share: expected a number, got NaN");
  left_out(replaced(good, "\"frames\": 90, \"lost_frames\": 0, \"keyframes\": 20, \"keyframes_loaded\": 0",
                    "\"frames\": \"90\", \"lost_frames\": 0, \"keyframes\": 20, \"keyframes_loaded\": 0"),
           "7: sessions[0].frames: expected an integer, got the string \"90\"");
  left_out(replaced(good, "\"lost_frames\": 1", "\"lost_frames\": -1"),
           "10: sessions[2].lost_frames: expected an integer in [0, frames = 90], got -1");
  left_out(replaced(good, "\"status\": \"completed\"", "\"status\": \"done\""),
           "7: sessions[0].status: expected one of aborted, completed, interrupted, failed, not_run, "
           "skipped, got done");
  left_out(replaced(good, "\"status\": \"completed\"", "\"status\": \"not_run\""),
           "7: sessions[0].frames: expected null for a session that did not run (not_run), got 90");
}

// A seed's campaign.json that is a folder or a FIFO is that seed's failure,
// said so, and never read (a FIFO would block the sweep for ever); a
// missing one, or a missing seed folder, is said to be missing.
TEST(CliCampaignSweep, AggregateOnlyNamesFoldersFifosAndMissingFiles) {
  const std::string out = sweep_folder("not_files");
  for (int seed : {3, 4, 5}) fs::create_directories(out + "/seed_" + std::to_string(seed));
  fs::create_directories(out + "/seed_3/campaign.json");
  ASSERT_EQ(::mkfifo((out + "/seed_4/campaign.json").c_str(), 0600), 0);
  const auto r =
      pvb::test::run_pvbench_from_source("timeout 60", "sweep --campaign " + campaign_file(out) + " --out " +
                                                           out + " --aggregate-only --seeds 1-6");
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_NE(
      r.output.find("- seed 3: " + out + "/seed_3/campaign.json: is a folder; expected a regular file\n"),
      std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("- seed 4: " + out + "/seed_4/campaign.json: is a FIFO; expected a regular file\n"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("- seed 5: " + out + "/seed_5/campaign.json: missing\n"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("- seed 6: " + out + "/seed_6: missing (no folder for this seed)\n"),
            std::string::npos)
      << r.output;
  EXPECT_NE(pvb::read_file(out + "/aggregate.md").find("| again | localise | noon | 2 (0) |"),
            std::string::npos);
}

// --aggregate-only of a folder that does not exist says so, for a campaign
// and for a scenario, and writes nothing.
TEST(CliCampaignSweep, AggregateOnlyOfAMissingFolderSaysItIsMissing) {
  const std::string dir = scratch("missing");
  const std::string out = dir + "/nowhere";
  for (const std::string& what : {"--campaign " + campaign_file(dir), "--scenario " + kNoon}) {
    const auto r = run_pvbench("sweep " + what + " --out " + out + " --aggregate-only --seeds 1-2");
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_EQ(r.output, "pvbench: error: " + out +
                            ": missing; expected the sweep folder that holds the seed_S folders\n");
  }
  EXPECT_FALSE(fs::exists(out));
}

// A campaign.json of version 1 (before every session was listed with its
// status) is still read: a failed session (status null) and the sessions a
// stopped campaign never reached count as not completed.
TEST(CliCampaignSweep, AggregateOnlyReadsVersionOneFiles) {
  const std::string out = sweep_folder("version1");
  std::string v1 = replaced(campaign_json(2), "\"campaign_version\": 2", "\"campaign_version\": 1");
  v1 = replaced(
      v1,
      "\"status\": \"completed\", \"error\": null, \"frames\": 90, \"lost_frames\": 0, \"keyframes\": 20, "
      "\"keyframes_loaded\": 20",
      "\"status\": null, \"error\": \"it failed\", \"frames\": 0, \"lost_frames\": 0, \"keyframes\": 0, "
      "\"keyframes_loaded\": 0");
  const std::size_t third = v1.find(",\n    {\"name\": \"more\"");
  ASSERT_NE(third, std::string::npos);
  pvb::write_file(out + "/seed_2/campaign.json", v1.substr(0, third) + "\n  ]\n}\n");
  const auto r =
      run_pvbench("sweep --campaign " + campaign_file(out) + " --out " + out + " --aggregate-only");
  EXPECT_EQ(r.code, 3) << r.output;
  const std::string md = pvb::read_file(out + "/aggregate.md");
  EXPECT_NE(md.find("| noon | map | - | 2 (0) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| again | localise | noon | 2 (1) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| more | extend | noon | 2 (1) |"), std::string::npos) << md;
}

// A campaign whose later session cannot run is refused before any session
// runs, naming the campaign file, the line and the key: exit 1, nothing
// written, for pvbench campaign and for a sweep of it.
TEST(CliCampaign, ASessionThatCannotRunIsRefusedBeforeAnyWork) {
  const std::string dir = scratch("refused");
  const std::string far = campaign_file(
      dir, "  - {name: far, scenario: " + kNoon + ", mode: localise, map: noon, start_m: 500}\n");
  auto r = run_pvbench("campaign --campaign " + far + " --seed 1 --frames 5 --sync --out " + dir + "/out");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  EXPECT_EQ(r.output.rfind("pvbench: error: " + far +
                               ":6: sessions[3].start_m: expected a distance from 0 to 1 m "
                               "before the route's end (the route of " +
                               kNoon + " is ",
                           0),
            0u)
      << r.output;
  EXPECT_NE(r.output.find(" m long), got 500\n"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir + "/out"));
  r = run_pvbench("sweep --campaign " + far + " --seeds 1-2 --frames 5 --sync --out " + dir + "/sweep");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  EXPECT_FALSE(fs::exists(dir + "/sweep"));

  const std::string maps =
      campaign_file(dir, "  - {name: maps, scenario: " + kNoon + ", mode: localise, map: noon}\n");
  r = run_pvbench("campaign --campaign " + maps + " --out " + dir + "/out");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(
      r.output.find(maps + ":6: sessions[3].name: expected a name other than those the campaign writes"),
      std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}
