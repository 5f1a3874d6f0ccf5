// pvbench check and the parts of pvbench sweep that need no `pvbench run`:
// exit codes, one line per violation, seed-list errors, --print-commands
// and --aggregate-only over hand-written metrics.json fixtures.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <regex>
#include <string>

#include "pvb/common/text.hpp"
#include "run_pvbench.hpp"
#include "suite_fixtures.hpp"

namespace fs = std::filesystem;
using pvb::test::run_pvbench;

using pvb::test::suite_fixture;

namespace {

std::string scratch(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("pvb_cli_suite_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

// A scenario with the nominal bounds, seed 7 (good_compare.json's).
std::string scenario_file() {
  const std::string path = scratch("scenario") + "/s.yaml";
  pvb::write_file(path,
                  "name: pv_station\nseed: 7\nroute: {waypoints_m: [[0, 0], [5, 0]]}\n"
                  "expect:\n  ate_rmse_m_max: 0.01\n  rpe_trans_rmse_m_max: 0.005\n  lost_frames_max: 0\n"
                  "  sweep: {pe_not_significantly_worse: true}\n");
  return path;
}

/// A fixture as the run of `scenario` with `seed` would have written it:
/// every "scenario" and "seed" value replaced (a sweep refuses a seed
/// folder whose metrics name another seed or scenario).
void write_metrics(const std::string& fixture_name, const std::string& path, const std::string& scenario,
                   int seed) {
  std::string text = pvb::read_file(suite_fixture(fixture_name));
  text = std::regex_replace(text, std::regex("\"scenario\": \"[^\"]*\""), "\"scenario\": \"" + scenario + "\"");
  text = std::regex_replace(text, std::regex("\"seed\": [0-9]+"), "\"seed\": " + std::to_string(seed));
  pvb::write_file(path, text);
}

int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

}  // namespace

TEST(CliCheck, PassingRunExitsZero) {
  const auto r =
      run_pvbench("check --scenario " + scenario_file() + " --metrics " + suite_fixture("good_compare.json"));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("good_compare.json: ok (pv_station)"), std::string::npos) << r.output;
}

TEST(CliCheck, ViolationsExitThreeWithOneLineEach) {
  const std::string metrics = scratch("violations") + "/worse_than_baseline.json";
  write_metrics("worse_than_baseline.json", metrics, "pv_station", 3);
  const auto r = run_pvbench("check --scenario " + scenario_file() + " --metrics " + metrics + " --seed 3");
  EXPECT_EQ(r.code, 3) << r.output;
  // Three violations and two notes: PE against the baseline (never judged on
  // one run) and where the sweep expectation is judged.
  EXPECT_EQ(count_lines(r.output), 5) << r.output;
  EXPECT_NE(r.output.find("worse_than_baseline.json: note: PE-SLAM − baseline ATE RMSE +8.50 mm"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("note: expect.sweep is judged over seeds: pvbench sweep --scenario "),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("worse_than_baseline.json: ate_rmse_m_max: ATE RMSE 0.0235 m > 0.01 m"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("lost_frames_max: 4 lost frames > 0"), std::string::npos) << r.output;
}

TEST(CliCheck, MalformedMetricsIsOneErrorLine) {
  const auto r =
      run_pvbench("check --scenario " + scenario_file() + " --metrics " + suite_fixture("missing_status.json"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("pvbench: error: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("missing_status.json:1: status: missing"), std::string::npos) << r.output;
}

TEST(CliCheck, ShippedFailureScenarioAcceptsAReportedLoss) {
  const std::string scenes = std::string(PVB_SOURCE_DIR) + "/scenes/";
  EXPECT_EQ(run_pvbench("check --scenario " + scenes + "tracking_failure.yaml --metrics " +
                        suite_fixture("lost_aborted.json") + " --seed 5")
                .code,
            0);
  const std::string completed = scratch("failure") + "/good_compare.json";
  write_metrics("good_compare.json", completed, "tracking_failure", 97);  // the scenario's seed
  const auto r = run_pvbench("check --scenario " + scenes + "tracking_failure.yaml --metrics " + completed);
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_NE(r.output.find("tracking_loss_expected: no tracking loss was reported"), std::string::npos)
      << r.output;
}

// Another scenario's run is refused with one line, never judged by this
// scenario's bounds.
TEST(CliCheck, RunOfAnotherScenarioIsRefused) {
  const std::string scenes = std::string(PVB_SOURCE_DIR) + "/scenes/";
  const auto r = run_pvbench("check --scenario " + scenes + "lawnmower_return.yaml --metrics " +
                             suite_fixture("good_compare.json"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("good_compare.json: scenario: expected a run of lawnmower_return ("), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("got pv_station"), std::string::npos) << r.output;
}

// A run of another seed than the one judged (the scenario's, or --seed) is
// refused with one line.
TEST(CliCheck, RunOfAnotherSeedIsRefused) {
  const std::string scenario = scenario_file();  // seed 7
  const std::string metrics = scratch("other_seed") + "/metrics.json";
  write_metrics("good_compare.json", metrics, "pv_station", 5);
  auto r = run_pvbench("check --scenario " + scenario + " --metrics " + metrics);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output,
            "pvbench: error: " + metrics +
                ": seed: expected 7 (the scenario's seed; give --seed 5 for a run of that seed), got 5\n");
  r = run_pvbench("check --scenario " + scenario + " --metrics " + metrics + " --seed 6");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output, "pvbench: error: " + metrics + ": seed: expected 6 (--seed), got 5\n");
  EXPECT_EQ(run_pvbench("check --scenario " + scenario + " --metrics " + metrics + " --seed 5").code, 0);
  r = run_pvbench("check --scenario " + scenario + " --metrics " + metrics + " --seed -5");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
}

// A count or error out of its range is one error line, never judged.
TEST(CliCheck, ValuesOutOfRangeAreOneErrorLine) {
  const std::string metrics = scratch("range") + "/metrics.json";
  write_metrics("good_compare.json", metrics, "pv_station", 7);
  std::string text = pvb::read_file(metrics);
  const std::string lost = "\"lost_frames\": 0";
  text.replace(text.find(lost), lost.size(), "\"lost_frames\": -3");
  pvb::write_file(metrics, text);
  const auto r = run_pvbench("check --scenario " + scenario_file() + " --metrics " + metrics);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output, "pvbench: error: " + metrics +
                          ":5: lost_frames: expected an integer in [0, frames = 300], got -3\n");
}

TEST(CliSweep, AggregateOnlyRefusesRunsOfAnotherScenarioOrSeed) {
  const std::string scenes = std::string(PVB_SOURCE_DIR) + "/scenes/";
  const std::string out = scratch("identity");
  fs::create_directories(out + "/seed_1");
  fs::create_directories(out + "/seed_2");
  write_metrics("good_compare.json", out + "/seed_1/metrics.json", "pv_station", 1);
  write_metrics("good_compare.json", out + "/seed_2/metrics.json", "pv_station", 2);
  EXPECT_EQ(run_pvbench("sweep --out " + out + " --aggregate-only").code, 0);
  // Judged by another scenario's bounds: refused.
  auto r = run_pvbench("sweep --scenario " + scenes + "lawnmower_return.yaml --out " + out + " --aggregate-only --check");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("seed_1/metrics.json: scenario: expected a run of lawnmower_return"), std::string::npos)
      << r.output;
  // A seed folder holding another seed's run.
  write_metrics("good_compare.json", out + "/seed_2/metrics.json", "pv_station", 7);
  r = run_pvbench("sweep --out " + out + " --aggregate-only");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("seed_2/metrics.json: seed: expected 2 (the folder seed_2), got 7"), std::string::npos)
      << r.output;
  // Two scenarios mixed in one sweep folder.
  write_metrics("good_compare.json", out + "/seed_2/metrics.json", "along_row", 2);
  r = run_pvbench("sweep --out " + out + " --aggregate-only");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("seed_2/metrics.json: scenario: expected a run of pv_station (the sweep's other seeds)"),
            std::string::npos)
      << r.output;
}

// A seed whose metrics.json holds a value out of its range is a failed
// seed, named with the file, line and key, and left out of the means: a
// negative ATE is not averaged as a good run.
TEST(CliSweep, AggregateOnlyLeavesOutMetricsWithValuesOutOfRange) {
  const std::string out = scratch("range");
  for (int seed : {1, 2}) {
    fs::create_directories(out + "/seed_" + std::to_string(seed));
    write_metrics("good_compare.json", out + "/seed_" + std::to_string(seed) + "/metrics.json", "pv_station",
                  seed);
  }
  std::string text = pvb::read_file(out + "/seed_2/metrics.json");
  const std::string ate = "\"ate\": {\"rmse\": 0.0042";
  text.replace(text.find(ate), ate.size(), "\"ate\": {\"rmse\": -1");
  pvb::write_file(out + "/seed_2/metrics.json", text);
  const auto r = run_pvbench("sweep --out " + out + " --aggregate-only");
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_NE(r.output.find(out + "/seed_2/metrics.json:6: ate.rmse: expected a number >= 0, got -1"),
            std::string::npos)
      << r.output;
  const std::string md = pvb::read_file(out + "/aggregate.md");
  EXPECT_NE(md.find("2 seeds, 1 with metrics, 1 failed"), std::string::npos) << md;
  EXPECT_EQ(md.find("-1000"), std::string::npos) << md;
}

TEST(CliSweep, BadSeedListIsOneErrorLine) {
  const std::string out = scratch("bad_seeds");
  const auto r = run_pvbench("sweep --scenario " + scenario_file() + " --seeds 5-1 --out " + out);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output, "pvbench: error: command line: --seeds: expected a range a-b with a <= b, got '5-1'\n");
  EXPECT_FALSE(fs::exists(out + "/seed_5"));
}

TEST(CliSweep, BadCountsAreOneErrorLine) {
  const std::string out = scratch("bad_counts");
  for (const char* option : {"--jobs 0", "--jobs -2", "--frames 0", "--frames -3"}) {
    const auto r = run_pvbench("sweep --scenario " + scenario_file() + " --seeds 1 --out " + out + " " + option);
    EXPECT_EQ(r.code, 1) << option << ": " << r.output;
    EXPECT_EQ(r.output.rfind("pvbench: error: pvbench sweep: --", 0), 0u) << r.output;
    EXPECT_EQ(count_lines(r.output), 1) << r.output;
  }
  EXPECT_FALSE(fs::exists(out + "/seed_1"));
}

TEST(CliSweep, PrintCommandsGivesOneSelfContainedLinePerSeed) {
  const std::string out = scratch("print");
  const std::string scenario = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  const auto r = run_pvbench("sweep --scenario " + scenario + " --seeds 1-2,9 --out " + out +
                             " --frames 30 --compare --sync --print-commands");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(count_lines(r.output), 3) << r.output;
  const std::string exe = fs::canonical(pvb::test::pvbench_path()).string();
  const std::string seed9 = "mkdir -p " + out + "/seed_9 && " + exe + " run --scenario " + scenario +
                            " --seed 9 --out " + out + "/seed_9 --overwrite --frames 30 --compare --sync > " + out +
                            "/seed_9/stdout.log 2>&1\n";
  EXPECT_NE(r.output.find(seed9), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out + "/seed_1"));  // printing runs nothing
}

TEST(CliSweep, AggregateOnlyCollectsSeedFolders) {
  const std::string out = scratch("aggregate");
  fs::create_directories(out + "/seed_1");
  fs::create_directories(out + "/seed_2");
  fs::create_directories(out + "/seed_10");  // a seed that left no metrics
  fs::create_directories(out + "/not_a_seed");
  write_metrics("good_compare.json", out + "/seed_1/metrics.json", "pv_station", 1);
  write_metrics("worse_than_baseline.json", out + "/seed_2/metrics.json", "pv_station", 2);
  const auto r = run_pvbench("sweep --out " + out + " --aggregate-only");
  EXPECT_EQ(r.code, 3) << r.output;  // one seed failed
  for (const char* f : {"aggregate.md", "aggregate.csv", "aggregate.json", "aggregate.svg", "aggregate.png"})
    EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
  const std::string md = pvb::read_file(out + "/aggregate.md");
  EXPECT_NE(md.find("# Sweep: pv_station"), std::string::npos) << md;  // name from the metrics
  EXPECT_NE(md.find("3 seeds, 2 with metrics, 1 failed"), std::string::npos) << md;
  EXPECT_NE(md.find("| 10 | 0 |"), std::string::npos) << md;
  const std::string csv = pvb::read_file(out + "/aggregate.csv");
  EXPECT_EQ(count_lines(csv), 4) << csv;  // header + seeds 1, 2, 10 in numeric order
  EXPECT_LT(csv.find("\n1,"), csv.find("\n2,"));
  EXPECT_LT(csv.find("\n2,"), csv.find("\n10,"));
  // Both seeds ran --compare: the paired line is the last thing printed
  // (d = -0.9 and +8.5 mm, CI from t(0.975, 1) = 12.706, d_z = 3.8 / 6.647).
  const std::string paired =
      "PE-SLAM − baseline ATE: mean 3.80 mm, 95 % CI [-55.92, 63.52] mm over 2 seeds (effect size d_z 0.57; "
      "PE ≤ baseline on 1, sign test p = 1.00); no significant difference at 95 %; not significantly worse: "
      "no (upper end 63.52 mm > margin 1.0";
  const std::size_t last = r.output.rfind("PE-SLAM − baseline ATE: ");
  ASSERT_NE(last, std::string::npos) << r.output;
  EXPECT_EQ(r.output.substr(last, paired.size()), paired) << r.output;
  EXPECT_EQ(r.output.find('\n', last), r.output.size() - 1) << r.output;  // the last line

  // An explicit list aggregates only those seeds.
  const auto two = run_pvbench("sweep --out " + out + " --aggregate-only --seeds 1-2");
  EXPECT_EQ(two.code, 0) << two.output;
  EXPECT_NE(pvb::read_file(out + "/aggregate.md").find("2 seeds, 2 with metrics, 0 failed"),
            std::string::npos);
}

TEST(CliSweep, AggregateOnlyWithoutSeedFoldersIsAnError) {
  const std::string out = scratch("empty");
  const auto r = run_pvbench("sweep --out " + out + " --aggregate-only");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("seed_*/metrics.json: expected at least one seed folder, got none"),
            std::string::npos)
      << r.output;
}

namespace {

// DIR/seed_1..seed_N/metrics.json from fixtures: `good` copies of
// good_compare.json (PE 4.2 mm, baseline 5.1 mm), then worse_than_baseline.json.
std::string sweep_folder(const std::string& name, int good, int worse) {
  const std::string out = scratch(name);
  for (int i = 1; i <= good + worse; ++i) {
    const std::string dir = out + "/seed_" + std::to_string(i);
    fs::create_directories(dir);
    write_metrics(i <= good ? "good_compare.json" : "worse_than_baseline.json", dir + "/metrics.json",
                  "pv_station", i);
  }
  return out;
}

}  // namespace

TEST(CliSweep, CheckJudgesEverySeedAndTheSweep) {
  const std::string scenario = scenario_file();
  const auto ok = run_pvbench("sweep --scenario " + scenario + " --out " + sweep_folder("check_ok", 10, 0) +
                              " --aggregate-only --check");
  EXPECT_EQ(ok.code, 0) << ok.output;
  EXPECT_NE(
      ok.output.find("check: note: sweep.pe_not_significantly_worse: holds, the paired 95 % interval of "
                     "PE-SLAM − baseline ATE reaches -0.90 mm <= margin 0.51 mm over 10 seeds\n"),
      std::string::npos)
      << ok.output;
  EXPECT_NE(ok.output.find("check: ok (pv_station, 10 seeds)\n"), std::string::npos) << ok.output;

  // One seed breaks three run bounds and drags the paired interval's upper
  // end to 2.17 mm, past the margin of 10 % of the baseline's 6.09 mm.
  const auto bad = run_pvbench("sweep --scenario " + scenario + " --out " + sweep_folder("check_bad", 9, 1) +
                               " --aggregate-only --check");
  EXPECT_EQ(bad.code, 3) << bad.output;
  EXPECT_NE(bad.output.find("check: seed 10: ate_rmse_m_max: ATE RMSE 0.0235 m > 0.01 m\n"),
            std::string::npos)
      << bad.output;
  EXPECT_NE(bad.output.find("check: seed 10: lost_frames_max: 4 lost frames > 0\n"), std::string::npos)
      << bad.output;
  EXPECT_NE(bad.output.find("check: sweep.pe_not_significantly_worse: the paired 95 % interval of PE-SLAM − "
                            "baseline ATE reaches +2.17 mm > margin 0.61 mm over 10 seeds\n"),
            std::string::npos)
      << bad.output;
  EXPECT_EQ(bad.output.find("check: ok"), std::string::npos) << bad.output;
}

TEST(CliSweep, CheckNeedsTheScenario) {
  const auto r =
      run_pvbench("sweep --out " + sweep_folder("check_noscenario", 2, 0) + " --aggregate-only --check");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output,
            "pvbench: error: command line: --check: expected a --scenario whose expect: section judges the "
            "sweep\n");
}
