// The scenario checker against hand-written metrics.json fixtures.
#include <gtest/gtest.h>

#include <string>

#include "pvb/common/error.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/suite/check.hpp"

using namespace pvb;

namespace {

std::string fixture(const std::string& name) {
  return std::string(PVB_SOURCE_DIR) + "/tests/harness/suite/fixtures/" + name;
}

// The expectations of a nominal PV scene.
scenes::Expectations nominal() {
  scenes::Expectations e;
  e.ate_rmse_m_max = 0.01;
  e.rpe_trans_rmse_m_max = 0.005;
  e.lost_frames_max = 0;
  e.pe_not_worse_than_baseline = true;
  return e;
}

bool has_key(const std::vector<suite::Violation>& v, const std::string& key) {
  for (const auto& x : v)
    if (x.key == key) return true;
  return false;
}

}  // namespace

TEST(SuiteCheck, ReadsTheContractKeys) {
  const suite::MetricsFile m = suite::read_metrics_file(fixture("good_compare.json"));
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
  EXPECT_EQ(m.baseline->mode, "orb-slam2");
  EXPECT_DOUBLE_EQ(*m.baseline->ate_rmse_m, 0.0051);
  EXPECT_FALSE(m.baseline->realtime_factor.has_value());
}

TEST(SuiteCheck, PassingRunHasNoViolations) {
  const auto v = suite::check_expectations(nominal(), fixture("good_compare.json"));
  EXPECT_TRUE(v.empty()) << v.front().line();
}

TEST(SuiteCheck, EachViolatedBoundIsOneLine) {
  const auto v = suite::check_expectations(nominal(), fixture("worse_than_baseline.json"));
  ASSERT_EQ(v.size(), 4u);
  EXPECT_EQ(v[0].line(), "ate_rmse_m_max: ATE RMSE 0.0235 m > 0.01 m");
  EXPECT_EQ(v[1].line(), "rpe_trans_rmse_m_max: RPE translation RMSE 0.0062 m > 0.005 m");
  EXPECT_EQ(v[2].line(), "lost_frames_max: 4 lost frames > 0");
  EXPECT_EQ(v[3].line(), "pe_not_worse_than_baseline: PE-SLAM ATE RMSE 0.0235 m > baseline 0.015 m");
}

TEST(SuiteCheck, BoundsAreInclusiveAndUnsetBoundsAreNotChecked) {
  scenes::Expectations e;
  e.ate_rmse_m_max = 0.0235;  // exactly the measured value
  e.lost_frames_max = 4;
  EXPECT_TRUE(suite::check_expectations(e, fixture("worse_than_baseline.json")).empty());
  e.ate_rmse_m_max = 0.0234;
  EXPECT_TRUE(has_key(suite::check_expectations(e, fixture("worse_than_baseline.json")), "ate_rmse_m_max"));
  EXPECT_TRUE(suite::check_expectations(scenes::Expectations{}, fixture("worse_than_baseline.json")).empty());
}

TEST(SuiteCheck, NullMetricsAndMissingBaselineAreViolations) {
  // An aborted run has no ATE; without tracking_loss_expected, every bound fails.
  const auto v = suite::check_expectations(nominal(), fixture("lost_aborted.json"));
  EXPECT_TRUE(has_key(v, "status"));
  EXPECT_TRUE(has_key(v, "ate_rmse_m_max"));
  EXPECT_TRUE(has_key(v, "rpe_trans_rmse_m_max"));
  EXPECT_TRUE(has_key(v, "lost_frames_max"));
  ASSERT_TRUE(has_key(v, "pe_not_worse_than_baseline"));
  for (const auto& x : v) {
    if (x.key == "pe_not_worse_than_baseline") {
      EXPECT_EQ(x.message, "no baseline in the metrics (run with --compare)");
    }
  }
}

TEST(SuiteCheck, ExpectedTrackingLossPassesWithAReason) {
  scenes::Expectations e;
  e.tracking_loss_expected = true;
  EXPECT_TRUE(suite::check_expectations(e, fixture("lost_aborted.json")).empty());
}

TEST(SuiteCheck, ExpectedTrackingLossFailsWithoutLossOrReason) {
  scenes::Expectations e;
  e.tracking_loss_expected = true;
  const auto none = suite::check_expectations(e, fixture("good_compare.json"));
  ASSERT_EQ(none.size(), 1u);
  EXPECT_EQ(none[0].line(),
            "tracking_loss_expected: no tracking loss was reported (0 lost frames, no loss_events)");

  const auto bad = suite::check_expectations(e, fixture("lost_no_reason.json"));
  ASSERT_EQ(bad.size(), 2u);
  EXPECT_EQ(bad[0].line(), "tracking_loss_expected: the run was interrupted before it ended");
  EXPECT_EQ(bad[1].line(), "tracking_loss_expected: loss event 0 (frame 88) gives no reason");
}

TEST(SuiteCheck, MalformedMetricsAreIoErrorsNamingFileAndKey) {
  auto message = [](const std::string& name) -> std::string {
    try {
      suite::read_metrics_file(fixture(name));
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
  EXPECT_THROW(suite::read_metrics_file(fixture("does_not_exist.json")), IoError);
}

TEST(SuiteCheck, PeAgainstBaselineIsJudgedOnTheWholeScenarioOnly) {
  const suite::MetricsFile m = suite::read_metrics_file(fixture("worse_than_baseline.json"));
  std::vector<std::string> notes;
  // Run as long as the scenario: judged.
  auto v = suite::check_expectations(nominal(), m, m.primary.frames, &notes);
  EXPECT_TRUE(has_key(v, "pe_not_worse_than_baseline"));
  EXPECT_TRUE(notes.empty());
  // Cut short (the scenario has more frames): not judged, a note with both values instead.
  v = suite::check_expectations(nominal(), m, m.primary.frames + 1, &notes);
  EXPECT_FALSE(has_key(v, "pe_not_worse_than_baseline"));
  EXPECT_TRUE(has_key(v, "ate_rmse_m_max"));  // the other bounds still hold for a cut run
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("not judged"), std::string::npos) << notes[0];
  EXPECT_NE(notes[0].find("baseline 0.015 m"), std::string::npos) << notes[0];
}
