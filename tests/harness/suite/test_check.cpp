// The scenario checker against hand-written metrics.json fixtures: the
// run bounds and the sweep's (the place recognition, map and blind-stretch
// sections in test_check_sections.cpp).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/suite/aggregate.hpp"
#include "pvb/suite/check.hpp"
#include "pvb/suite/metrics_file.hpp"
#include "check_fixtures.hpp"
#include "suite_fixtures.hpp"

using namespace pvb;

using pvb::test::has_key;
using pvb::test::seed_run;
using pvb::test::suite_fixture;

namespace {

// The expectations of a nominal PV scene.
scenes::Expectations nominal() {
  scenes::Expectations e;
  e.ate_rmse_m_max = 0.01;
  e.rpe_trans_rmse_m_max = 0.005;
  e.lost_frames_max = 0;
  e.sweep.pe_not_significantly_worse = true;
  return e;
}

// n seeds with PE − baseline = d_mm[i % size] around a baseline of 5 mm.
suite::SweepAggregate sweep_of(int n, const std::vector<double>& d_mm) {
  std::vector<suite::SeedRun> runs;
  for (int i = 0; i < n; ++i) runs.push_back(seed_run(i + 1, 5.0 + d_mm[i % d_mm.size()], 5.0));
  return suite::aggregate("pv_station", runs);
}

}  // namespace

TEST(SuiteCheck, ReadsTheContractKeys) {
  const suite::MetricsFile m = suite::read_metrics_file(suite_fixture("good_compare.json"));
  EXPECT_EQ(m.scenario, "pv_station");
  ASSERT_TRUE(m.seed.has_value());
  EXPECT_EQ(*m.seed, 7u);
  EXPECT_EQ(m.primary.mode, "pe-slam");
  EXPECT_EQ(m.primary.status, "completed");
  EXPECT_EQ(m.primary.frames, 300);
  ASSERT_TRUE(m.primary.ate_rmse_m.has_value());
  EXPECT_DOUBLE_EQ(*m.primary.ate_rmse_m, 0.0042);
  ASSERT_TRUE(m.primary.rpe_trans_rmse_m.has_value());
  EXPECT_DOUBLE_EQ(*m.primary.rpe_trans_rmse_m, 0.0011);
  ASSERT_TRUE(m.primary.tracking_ms_median.has_value());
  EXPECT_DOUBLE_EQ(*m.primary.tracking_ms_median, 17.5);
  ASSERT_TRUE(m.primary.realtime_factor.has_value());
  EXPECT_DOUBLE_EQ(*m.primary.realtime_factor, 1.12);
  ASSERT_TRUE(m.baseline.has_value());
  EXPECT_EQ(m.baseline->mode, "baseline");  // a version 1 file's "orb-slam2"
  EXPECT_DOUBLE_EQ(*m.baseline->ate_rmse_m, 0.0051);
  EXPECT_FALSE(m.baseline->realtime_factor.has_value());
}

TEST(SuiteCheck, PassingRunHasNoViolations) {
  const auto v = suite::check_expectations(nominal(), suite_fixture("good_compare.json"));
  EXPECT_TRUE(v.empty()) << v.front().line();
}

TEST(SuiteCheck, EachViolatedBoundIsOneLine) {
  const auto v = suite::check_expectations(nominal(), suite_fixture("worse_than_baseline.json"));
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0].line(), "ate_rmse_m_max: ATE RMSE 0.0235 m > 0.01 m");
  EXPECT_EQ(v[1].line(), "rpe_trans_rmse_m_max: RPE translation RMSE 0.0062 m > 0.005 m");
  EXPECT_EQ(v[2].line(), "lost_frames_max: 4 lost frames > 0");
}

TEST(SuiteCheck, BoundsAreInclusiveAndUnsetBoundsAreNotChecked) {
  scenes::Expectations e;
  e.ate_rmse_m_max = 0.0235;  // exactly the measured value
  e.lost_frames_max = 4;
  EXPECT_TRUE(suite::check_expectations(e, suite_fixture("worse_than_baseline.json")).empty());
  e.ate_rmse_m_max = 0.0234;
  EXPECT_TRUE(has_key(suite::check_expectations(e, suite_fixture("worse_than_baseline.json")), "ate_rmse_m_max"));
  EXPECT_TRUE(suite::check_expectations(scenes::Expectations{}, suite_fixture("worse_than_baseline.json")).empty());
}

TEST(SuiteCheck, KeyframesOfTheFinalMapAreBounded) {
  scenes::Expectations e;
  e.keyframes_max = 30;  // worse_than_baseline.json: 30 keyframes
  EXPECT_TRUE(suite::check_expectations(e, suite_fixture("worse_than_baseline.json")).empty());
  e.keyframes_max = 29;
  const auto v = suite::check_expectations(e, suite_fixture("worse_than_baseline.json"));
  ASSERT_EQ(v.size(), 1u);
  EXPECT_EQ(v[0].line(), "keyframes_max: 30 keyframes in the final map > 29");
  suite::MetricsFile m = suite::read_metrics_file(suite_fixture("worse_than_baseline.json"));
  m.primary.keyframes.reset();
  const auto missing = suite::check_expectations(e, m);
  ASSERT_EQ(missing.size(), 1u);
  EXPECT_EQ(missing[0].line(), "keyframes_max: no keyframe count in the metrics (keyframes is absent)");
}

TEST(SuiteCheck, NullMetricsAndMissingBaselineAreViolations) {
  // An aborted run has no ATE; without tracking_loss_expected, every bound fails.
  const auto v = suite::check_expectations(nominal(), suite_fixture("lost_aborted.json"));
  EXPECT_TRUE(has_key(v, "status"));
  EXPECT_TRUE(has_key(v, "ate_rmse_m_max"));
  EXPECT_TRUE(has_key(v, "rpe_trans_rmse_m_max"));
  EXPECT_TRUE(has_key(v, "lost_frames_max"));
  EXPECT_EQ(v.size(), 4u);
}

TEST(SuiteCheck, ExpectedTrackingLossPassesWithAReason) {
  scenes::Expectations e;
  e.tracking_loss_expected = true;
  EXPECT_TRUE(suite::check_expectations(e, suite_fixture("lost_aborted.json")).empty());
}

TEST(SuiteCheck, ExpectedTrackingLossFailsWithoutLossOrReason) {
  scenes::Expectations e;
  e.tracking_loss_expected = true;
  const auto none = suite::check_expectations(e, suite_fixture("good_compare.json"));
  ASSERT_EQ(none.size(), 1u);
  EXPECT_EQ(none[0].line(),
            "tracking_loss_expected: no tracking loss was reported (0 lost frames, no loss_events)");

  const auto bad = suite::check_expectations(e, suite_fixture("lost_no_reason.json"));
  ASSERT_EQ(bad.size(), 2u);
  EXPECT_EQ(bad[0].line(), "tracking_loss_expected: the run was interrupted before it ended");
  EXPECT_EQ(bad[1].line(), "tracking_loss_expected: loss event 0 (frame 88) gives no reason");
}

TEST(SuiteCheck, MalformedMetricsAreIoErrorsNamingFileAndKey) {
  auto message = [](const std::string& name) -> std::string {
    try {
      suite::read_metrics_file(suite_fixture(name));
    } catch (const IoError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message("missing_status.json").find("missing_status.json:1: status: missing"), std::string::npos)
      << message("missing_status.json");
  EXPECT_NE(message("bad_type.json").find("bad_type.json:2: lost_frames: expected an integer"),
            std::string::npos)
      << message("bad_type.json");
  EXPECT_NE(message("not_json.json").find("not_json.json"), std::string::npos);
  EXPECT_NE(message("not_json.json").find("not valid JSON"), std::string::npos) << message("not_json.json");
  EXPECT_THROW(suite::read_metrics_file(suite_fixture("does_not_exist.json")), IoError);
}

// metrics.json is read as JSON is meant: a quoted number is a string, and a
// version newer than this program's is refused, not read as its own.
TEST(SuiteCheck, StringsAreNotNumbersAndUnknownVersionsAreRefused) {
  const std::string good = read_file(suite_fixture("good_compare.json"));
  const std::string path = ::testing::TempDir() + "pvb_metrics_strict_" + std::to_string(::getpid()) + ".json";
  auto message = [&path](const std::string& text) -> std::string {
    write_file(path, text);
    try {
      suite::read_metrics_file(path);
    } catch (const IoError& e) {
      return e.what();
    }
    return "(no error)";
  };
  EXPECT_EQ(message(good), "(no error)");
  std::string quoted = good;
  const std::string lost = "\"lost_frames\": 0";
  quoted.replace(quoted.find(lost), lost.size(), "\"lost_frames\": \"0\"");
  EXPECT_NE(message(quoted).find("lost_frames: expected an integer, got the string \"0\""), std::string::npos)
      << message(quoted);
  std::string version = good;
  version.replace(version.find('{'), 1, "{\"metrics_version\": 2,");
  EXPECT_EQ(message(version), "(no error)");
  const std::string v2 = "\"metrics_version\": 2";
  version.replace(version.find(v2), v2.size(), "\"metrics_version\": 99");
  EXPECT_NE(message(version).find("metrics_version: expected 1 to 2 (this pvbench reads up to version 2), got 99"),
            std::string::npos)
      << message(version);
  std::remove(path.c_str());
}

// A value out of its range is refused naming the file, the line and the
// key: a negative ATE would be averaged as a good run, a lost-frame count
// below 0 or above the frames would pass any bound.
TEST(SuiteCheck, ValuesOutOfRangeAreRefusedNamingFileLineAndKey) {
  const std::string path = ::testing::TempDir() + "pvb_metrics_range_" + std::to_string(::getpid()) + ".json";
  auto message = [&path](const std::string& fixture_name, const std::string& from, const std::string& to) {
    return test::metrics_error_after_edit(path, fixture_name, from, to);
  };
  const std::string f = path + ":";
  EXPECT_EQ(message("good_compare.json", "\"lost_frames\": 0", "\"lost_frames\": -3"),
            f + "5: lost_frames: expected an integer in [0, frames = 300], got -3");
  EXPECT_EQ(message("good_compare.json", "\"lost_frames\": 0", "\"lost_frames\": 301"),
            f + "5: lost_frames: expected an integer in [0, frames = 300], got 301");
  EXPECT_EQ(message("good_compare.json", "\"frames\": 300", "\"frames\": -1"),
            f + "5: frames: expected an integer >= 0, got -1");
  EXPECT_EQ(message("good_compare.json", "\"ate\": {\"rmse\": 0.0042", "\"ate\": {\"rmse\": -1"),
            f + "6: ate.rmse: expected a number >= 0, got -1");
  EXPECT_EQ(message("good_compare.json", "\"rmse\": 0.0051", "\"rmse\": -0.5"),
            f + "16: baseline.ate.rmse: expected a number >= 0, got -0.5");
  EXPECT_EQ(message("good_compare.json", "\"median\": 17.5", "\"median\": -2"),
            f + "10: tracking_ms.median: expected a number >= 0, got -2");
  EXPECT_EQ(message("good_compare.json", "\"realtime_factor\": 1.12", "\"realtime_factor\": -1"),
            f + "11: realtime_factor: expected a number >= 0, got -1");
  EXPECT_EQ(message("good_compare.json", "\"keyframes\": 21", "\"keyframes\": -21"),
            f + "5: keyframes: expected an integer >= 0, got -21");
  EXPECT_EQ(message("dense_map.json", "\"ghosting\": 0.001", "\"ghosting\": 1.5"),
            f + "23: dense_map.maps.corrected.all.ghosting: expected a number in [0, 1], got 1.5");
  EXPECT_EQ(message("dense_map.json", "[0.5, 0.8, 0.9, 0.95]", "[0.5, 0.8, 7.5, 0.95]"),
            f + "22: dense_map.maps.corrected.all.completeness_at[2]: expected a number in [0, 1], got 7.5");
  EXPECT_EQ(message("dense_map.json", "\"recovered_frame\": 675", "\"recovered_frame\": 500"),
            f + "32: loss_events[0].recovered_frame: expected an integer >= frame = 601, got 500");
  EXPECT_EQ(message("dense_map.json", "\"loops_false\": 0", "\"loops_false\": -1"),
            f + "12: place_recognition.loops_false: expected an integer >= 0, got -1");
  EXPECT_EQ(message("dense_map.json", "[600, 659]", "[600, 599]"),
            f + "5: camera_covered_frames[1]: expected an integer >= first = 600, got 599");
  EXPECT_EQ(message("dense_map.json", "[600, 659]", "[\"600\", 659]"),
            f + "5: camera_covered_frames[0]: expected an integer, got the string \"600\"");
  std::remove(path.c_str());
}

// yaml-cpp keeps both of two equal keys and finds the first: a key given
// twice in one object is refused, read or not, naming both lines.
TEST(SuiteCheck, DuplicateKeysInMetricsAreRefused) {
  const std::string path = ::testing::TempDir() + "pvb_metrics_dup_" + std::to_string(::getpid()) + ".json";
  auto message = [&path](const std::string& from, const std::string& to) {
    return test::metrics_error_after_edit(path, "good_compare.json", from, to);
  };
  const std::string f = path + ":";
  EXPECT_EQ(message("\"frames\": 300,", "\"frames\": 300,\n  \"frames\": 3,"),
            f + "6: frames: expected each key once in its section (first given at line 5), got a second frames");
  EXPECT_EQ(message("\"count\": 300}", "\"count\": 300, \"count\": 1}"),
            f + "6: ate.count: expected each key once in its section (first given at line 6), got a second count");
  EXPECT_EQ(message("\"mode\": \"orb-slam2\",", "\"mode\": \"orb-slam2\", \"mode\": \"pe-slam\","),
            f + "14: baseline.mode: expected each key once in its section (first given at line 14), got a second mode");
  // Wrong types name the line too.
  EXPECT_EQ(message("\"keyframes\": 21", "\"keyframes\": [21]"),
            f + "5: keyframes: expected an integer, got a list or an object");
  std::remove(path.c_str());
  // The folder's identity is read the same way from meta.json.
  const std::string dir = ::testing::TempDir() + "pvb_meta_dup_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  write_file(dir + "/meta.json", "{\"seed\": 1,\n \"seed\": 2}\n");
  try {
    suite::read_folder_identity(dir);
    ADD_FAILURE() << "accepted";
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()), dir + "/meta.json:2: seed: expected each key once in its section (first given "
                                            "at line 1), got a second seed");
  }
}

// A run of another scenario or seed is refused, not judged by the wrong bounds.
TEST(SuiteCheck, MetricsOfAnotherRunAreRefused) {
  const suite::MetricsFile m = suite::read_metrics_file(suite_fixture("good_compare.json"));
  ASSERT_TRUE(m.seed.has_value());
  EXPECT_NO_THROW(suite::expect_run_identity(m, m.scenario, "x.yaml", m.seed));
  try {
    suite::expect_run_identity(m, "lawnmower_return", "scenes/lawnmower_return.yaml", std::nullopt);
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), m.path + ": scenario: expected a run of lawnmower_return "
                                              "(scenes/lawnmower_return.yaml), got " + m.scenario);
  }
  try {
    suite::expect_run_identity(m, "", "", *m.seed + 1, "the folder seed_" + std::to_string(*m.seed + 1));
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(": seed: expected " + std::to_string(*m.seed + 1) + " (the folder seed_"),
              std::string::npos)
        << e.what();
  }
}

TEST(SuiteCheck, PeAgainstBaselineIsANoteNeverAViolationOfOneRun) {
  // PE-SLAM 23.5 mm against the baseline's 15 mm: one run says nothing
  // about the distribution, so it is a note with both values.
  const suite::MetricsFile m = suite::read_metrics_file(suite_fixture("worse_than_baseline.json"));
  std::vector<std::string> notes;
  scenes::Expectations e;
  e.sweep.pe_not_significantly_worse = true;
  EXPECT_TRUE(suite::check_expectations(e, m, &notes).empty());
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].find("PE-SLAM − baseline ATE RMSE +8.50 mm (PE-SLAM 0.0235 m, baseline 0.015 m)"), 0u)
      << notes[0];
  // Without a baseline there is nothing to note.
  notes.clear();
  EXPECT_TRUE(suite::check_expectations(e, suite_fixture("lost_aborted.json"), &notes).size() == 1);  // status
  EXPECT_TRUE(notes.empty());
}

TEST(SuiteCheckSweep, NotSignificantlyWorseHoldsWhenTheUpperEndIsWithinTheMargin) {
  // d = -0.5, +0.5 mm over 10 seeds: mean 0, sd 0.527, upper end
  // 2.262 · 0.527 / sqrt(10) = 0.377 mm <= max(0.5, 10 % of 5 mm) = 0.5 mm.
  std::vector<std::string> notes;
  const auto v = suite::check_sweep(nominal(), sweep_of(10, {-0.5, 0.5}), &notes);
  EXPECT_TRUE(v.empty()) << v.front().line();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("holds"), std::string::npos) << notes[0];
  EXPECT_NE(notes[0].find("+0.38 mm <= margin 0.50 mm over 10 seeds"), std::string::npos) << notes[0];
}

TEST(SuiteCheckSweep, NotSignificantlyWorseFailsPastTheMarginOrWithTooFewSeeds) {
  // d = -0.2, +0.8 mm over 10 seeds: upper end 0.3 + 0.377 = 0.677 mm > 0.5 mm.
  const auto worse = suite::check_sweep(nominal(), sweep_of(10, {-0.2, 0.8}));
  ASSERT_EQ(worse.size(), 1u);
  EXPECT_EQ(worse[0].line(),
            "sweep.pe_not_significantly_worse: the paired 95 % interval of PE-SLAM − baseline ATE reaches "
            "+0.68 mm > margin 0.50 mm over 10 seeds");
  // The first passing case, with 9 seeds: the verdict needs 10.
  const auto few = suite::check_sweep(nominal(), sweep_of(9, {-0.5, 0.5}));
  ASSERT_EQ(few.size(), 1u);
  EXPECT_EQ(few[0].line(), "sweep.pe_not_significantly_worse: needs 10 seeds with both ATEs, got 9");
  // A sweep without --compare cannot be judged.
  suite::SweepAggregate alone = sweep_of(10, {0.0});
  for (auto& r : alone.runs) r.metrics->baseline.reset();
  alone = suite::aggregate("pv_station", alone.runs);
  const auto none = suite::check_sweep(nominal(), alone);
  ASSERT_EQ(none.size(), 1u);
  EXPECT_EQ(none[0].message, "no baseline in the sweep (run it with --compare)");
}

TEST(SuiteCheckSweep, EverySeedIsJudgedByTheRunBounds) {
  std::vector<suite::SeedRun> runs = {seed_run(1, 4, 5), seed_run(2, 12, 5)};  // seed 2 over 1 cm
  suite::SeedRun missing;
  missing.seed = 3;
  missing.error = "cannot open seed_3/metrics.json";
  runs.push_back(missing);
  scenes::Expectations e;
  e.ate_rmse_m_max = 0.01;
  const auto v = suite::check_sweep(e, suite::aggregate("pv_station", runs));
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[0].line(), "seed 2: ate_rmse_m_max: ATE RMSE 0.012 m > 0.01 m");
  EXPECT_EQ(v[1].line(), "seed 3: metrics: none (cannot open seed_3/metrics.json)");
}
