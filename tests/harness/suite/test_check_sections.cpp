// The scenario checker's sections of metrics.json against hand-written
// fixtures: place recognition (loops, relocalisations, cover), the scored
// maps, and the blind stretch of a covered camera.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "check_fixtures.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/suite/aggregate.hpp"
#include "pvb/suite/check.hpp"
#include "pvb/suite/metrics_file.hpp"
#include "suite_fixtures.hpp"

using namespace pvb;

using pvb::test::has_key;
using pvb::test::seed_run;
using pvb::test::suite_fixture;

namespace {

suite::MetricsFile kidnapped() { return suite::read_metrics_file(suite_fixture("kidnapped.json")); }

}  // namespace

TEST(SuiteCheckPlace, ReadsPlaceRecognitionAndCover) {
  const suite::MetricsFile m = kidnapped();
  ASSERT_TRUE(m.primary.place.has_value());
  EXPECT_EQ(m.primary.place->loops_accepted, 1);
  EXPECT_EQ(m.primary.place->loops_true.value_or(-1), 1);
  EXPECT_EQ(m.primary.place->relocalisations_false.value_or(-1), 0);
  ASSERT_TRUE(m.primary.camera_covered_frames.has_value());
  EXPECT_EQ(m.primary.camera_covered_frames->second, 659);
  ASSERT_EQ(m.primary.loss_events.size(), 1u);
  EXPECT_EQ(m.primary.loss_events[0].recovered_frame.value_or(-1), 675);
  EXPECT_NEAR(m.primary.refined_ate_rmse_m.value_or(0), 0.0068, 1e-12);
}

TEST(SuiteCheckPlace, FalseLoopsAndRelocalisationsAreCounted) {
  scenes::Expectations e;
  e.false_loops_max = 0;
  suite::MetricsFile m = kidnapped();
  EXPECT_TRUE(suite::check_expectations(e, m).empty());
  m.primary.place->loops_false = 1;
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "false_loops_max"));
  m.primary.place->loops_false = 0;
  m.primary.place->relocalisations_false = 1;
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "false_loops_max"));
  m.primary.place->loops_false.reset();  // no ground truth: cannot be judged
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "false_loops_max"));
}

TEST(SuiteCheckPlace, LoopsMinCountsTrueLoops) {
  scenes::Expectations e;
  e.loops_min = 1;
  suite::MetricsFile m = kidnapped();
  EXPECT_TRUE(suite::check_expectations(e, m).empty());
  m.primary.place->loops_true = 0;
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "loops_min"));
}

TEST(SuiteCheckPlace, RelocalisationIsCountedFromTheCamerasReturn) {
  scenes::Expectations e;
  suite::MetricsFile m = kidnapped();
  // Recovered at 675, the camera back at 660: 15 frames.
  e.relocalised_within_frames = 15;
  EXPECT_TRUE(suite::check_expectations(e, m).empty());
  e.relocalised_within_frames = 14;
  const auto v = suite::check_expectations(e, m);
  ASSERT_TRUE(has_key(v, "relocalised_within_frames"));
  EXPECT_NE(v[0].message.find("15 frames after the camera's return at frame 660"), std::string::npos)
      << v[0].message;
  // Without a cover the loss's own frame counts: 74 frames.
  m.primary.camera_covered_frames.reset();
  e.relocalised_within_frames = 74;
  EXPECT_TRUE(suite::check_expectations(e, m).empty());
  e.relocalised_within_frames = 73;
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "relocalised_within_frames"));
  // Never recovered.
  m.primary.loss_events[0].recovered_frame.reset();
  e.relocalised_within_frames = 1000;
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "relocalised_within_frames"));
}

// A bound whose data is missing is never passed: 40 lost frames without
// their loss events cannot show a relocalisation within 30 frames.
TEST(SuiteCheckPlace, RelocalisationBoundWithoutLossEventsIsNotJudged) {
  scenes::Expectations e;
  e.relocalised_within_frames = 30;
  suite::MetricsFile m = kidnapped();
  m.primary.lost_frames = 40;
  m.primary.loss_events.clear();
  const auto v = suite::check_expectations(e, m);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_EQ(v[0].line(), "relocalised_within_frames: not judged: 40 lost frames but no loss_events in the metrics");
  m.primary.lost_frames = 0;  // nothing lost: nothing to relocalise from
  EXPECT_TRUE(suite::check_expectations(e, m).empty());
}

TEST(SuiteCheckPlace, RefinedAteBound) {
  scenes::Expectations e;
  suite::MetricsFile m = kidnapped();
  e.refined_ate_rmse_m_max = 0.0068;
  EXPECT_TRUE(suite::check_expectations(e, m).empty());
  e.refined_ate_rmse_m_max = 0.0067;
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "refined_ate_rmse_m_max"));
  m.primary.refined_ate_rmse_m.reset();
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "refined_ate_rmse_m_max"));
}

TEST(SuiteCheckPlace, SweepTotals) {
  std::vector<suite::SeedRun> runs;
  for (int s = 1; s <= 3; ++s) runs.push_back(suite::read_seed_run(s, suite_fixture("kidnapped.json")));
  runs[1].metrics->primary.place->loops_false = 2;
  const suite::SweepAggregate a = suite::aggregate("kidnapped", runs);
  EXPECT_EQ(a.primary_place.seeds, 3);
  EXPECT_EQ(a.primary_place.loops_true, 3);
  EXPECT_EQ(a.primary_place.loops_false, 2);
  EXPECT_EQ(a.primary_place.seeds_with_false_match, 1);
  EXPECT_EQ(a.primary.refined_ate_rmse_m.count, 3);
  EXPECT_NE(suite::format_markdown(a).find("2 false"), std::string::npos);
}

// With --compare, the summary table's PE-SLAM and baseline rows stay
// together: the dense-map and place-recognition lines come after the table.
TEST(SuiteCheckMap, SummaryTableStaysWholeWithMapAndPlaceLines) {
  std::vector<suite::SeedRun> runs;
  for (int s = 1; s <= 2; ++s) {
    suite::SeedRun r = suite::read_seed_run(s, suite_fixture("kidnapped.json"));
    const suite::MetricsFile maps = suite::read_metrics_file(suite_fixture("dense_map.json"));
    r.metrics->primary.maps = maps.primary.maps;
    r.metrics->baseline = r.metrics->primary;
    r.metrics->baseline->mode = "baseline";
    runs.push_back(r);
  }
  const std::string md = suite::format_markdown(suite::aggregate("kidnapped", runs));
  const std::size_t pe = md.find("\n| PE-SLAM |");
  ASSERT_NE(pe, std::string::npos) << md;
  const std::size_t next_line = md.find('\n', pe + 1) + 1;
  EXPECT_EQ(md.compare(next_line, 9, "| baselin"), 0) << md;
  EXPECT_LT(next_line, md.find("dense map over")) << md;
  EXPECT_LT(next_line, md.find("Place recognition over")) << md;
}

TEST(SuiteCheckMap, ReadsTheScoredMaps) {
  const suite::MetricsFile m = suite::read_metrics_file(suite_fixture("dense_map.json"));
  ASSERT_EQ(m.primary.maps.size(), 2u);
  const suite::MapMetrics* c = m.primary.map("corrected");
  ASSERT_NE(c, nullptr);
  EXPECT_DOUBLE_EQ(c->accuracy_median_m.value_or(-1), 0.012);
  EXPECT_DOUBLE_EQ(c->completeness_2cm, 0.8);
  EXPECT_DOUBLE_EQ(c->completeness_5cm, 0.9);
  EXPECT_DOUBLE_EQ(c->ghosting, 0.001);
  EXPECT_DOUBLE_EQ(m.primary.map("live")->ghosting, 0.012);
  EXPECT_EQ(m.primary.map("before_loop"), nullptr);
  EXPECT_TRUE(suite::read_metrics_file(suite_fixture("kidnapped.json")).primary.maps.empty());
}

TEST(SuiteCheckMap, AccuracyAndCompletenessBoundsOnTheCorrectedMap) {
  scenes::Expectations e;
  e.map_accuracy_m_max = 0.012;  // inclusive
  e.map_completeness_min = 0.9;
  suite::MetricsFile m = suite::read_metrics_file(suite_fixture("dense_map.json"));
  EXPECT_TRUE(suite::check_expectations(e, m).empty());
  e.map_accuracy_m_max = 0.011;
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "map_accuracy_m_max"));
  EXPECT_FALSE(has_key(suite::check_expectations(e, m), "map_completeness_min"));
  e.map_completeness_min = 0.95;
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "map_completeness_min"));
  m.primary.maps.clear();  // not scored (--no-map-eval, or no dense map): cannot be judged
  e.map_accuracy_m_max.reset();
  EXPECT_TRUE(has_key(suite::check_expectations(e, m), "map_completeness_min"));
}

TEST(SuiteCheckMap, SweepsAggregateTheMaps) {
  std::vector<suite::SeedRun> runs = {suite::read_seed_run(1, suite_fixture("dense_map.json")),
                                      suite::read_seed_run(2, suite_fixture("dense_map.json")),
                                      suite::read_seed_run(3, suite_fixture("kidnapped.json"))};
  runs[1].metrics->primary.maps[0].accuracy_median_m = 0.016;
  const suite::SweepAggregate a = suite::aggregate("kidnapped", runs);
  EXPECT_EQ(a.primary.map_accuracy_median_m.count, 2);
  EXPECT_NEAR(a.primary.map_accuracy_median_m.mean, 0.014, 1e-12);
  EXPECT_NEAR(a.primary.map_ghosting_live.mean, 0.012, 1e-12);
  const std::string md = suite::format_markdown(a);
  EXPECT_NE(md.find("dense map over 2 seeds: median accuracy 14.0 ± 2.8 mm"), std::string::npos) << md;
}

namespace {

suite::MetricsFile blind_run() { return suite::read_metrics_file(suite_fixture("blind.json")); }

scenes::Expectations blind_bounds() {
  scenes::Expectations e;
  e.blind_poses_all = true;
  e.blind_after_error_m_max = 0.05;
  e.blind_after_error_deg_max = 1.0;
  e.blind_no_global_relocalisation = true;
  return e;
}

std::vector<std::string> lines_of(const std::vector<suite::Violation>& v) {
  std::vector<std::string> out;
  for (const suite::Violation& x : v) out.push_back(x.line());
  return out;
}

}  // namespace

TEST(SuiteCheckBlind, ReadsTheBlindStretch) {
  const suite::MetricsFile m = blind_run();
  ASSERT_TRUE(m.primary.blind.has_value());
  const suite::BlindMetrics& b = *m.primary.blind;
  EXPECT_EQ(b.first_covered, 450);
  EXPECT_EQ(b.last_covered, 539);
  EXPECT_EQ(b.covered_frames(), 90);
  EXPECT_EQ(b.covered_with_pose, 90);
  EXPECT_EQ(b.first_after.value_or(-1), 540);
  EXPECT_TRUE(b.first_after_tracked);
  EXPECT_EQ(b.first_after_method, "motion");
  EXPECT_EQ(b.first_after_state, "ok");
  EXPECT_DOUBLE_EQ(b.first_after_error_m.value_or(-1), 0.031);
  EXPECT_DOUBLE_EQ(b.first_after_error_deg.value_or(-1), 0.42);
  EXPECT_FALSE(kidnapped().primary.blind.has_value());
}

// A stretch driven on dead reckoning meets every bound; each bound fails
// on its own when its figure is past it.
TEST(SuiteCheckBlind, EachBoundHoldsAndFailsOnItsOwn) {
  const scenes::Expectations e = blind_bounds();
  EXPECT_TRUE(suite::check_expectations(e, blind_run()).empty());
  suite::MetricsFile m = blind_run();
  m.primary.blind->covered_with_pose = 89;
  EXPECT_EQ(lines_of(suite::check_expectations(e, m)),
            std::vector<std::string>{"blind_poses_all: 89 of 90 covered frames have a pose"});
  m = blind_run();
  m.primary.blind->first_after_error_m = 0.0501;
  EXPECT_EQ(lines_of(suite::check_expectations(e, m)),
            std::vector<std::string>{"blind_after_error_m_max: error across the stretch 0.0501 m > 0.05 m"});
  m = blind_run();
  m.primary.blind->first_after_error_deg = 1.5;
  EXPECT_EQ(lines_of(suite::check_expectations(e, m)),
            std::vector<std::string>{"blind_after_error_deg_max: error across the stretch 1.5 deg > 1 deg"});
  m = blind_run();
  m.primary.blind->first_after_method = "reloc";
  m.primary.blind->relocalised_frames = 1;
  EXPECT_EQ(
      lines_of(suite::check_expectations(e, m)),
      std::vector<std::string>{
          "blind_no_global_relocalisation: the first frame after the cover (540) was tracked by a global "
          "relocalisation"});
  m = blind_run();
  m.primary.blind->first_after_method = "init";
  EXPECT_EQ(lines_of(suite::check_expectations(e, m)),
            std::vector<std::string>{
                "blind_no_global_relocalisation: the first frame after the cover (540) began a new map"});
  m = blind_run();
  m.primary.blind->first_after_state = "dead_reckoning";
  EXPECT_EQ(lines_of(suite::check_expectations(e, m)),
            std::vector<std::string>{"blind_no_global_relocalisation: the first frame after the cover (540) has a "
                                     "pose but tracking has not resumed (state dead_reckoning)"});
  m = blind_run();
  m.primary.blind->relocalised_frames = 2;
  EXPECT_EQ(lines_of(suite::check_expectations(e, m)),
            std::vector<std::string>{
                "blind_no_global_relocalisation: 2 covered frames were tracked by a global relocalisation"});
}

// What a camera-only SLAM does: no pose while covered, lost on the first
// frame after, relocalised later.  Every blind bound is violated and says why.
TEST(SuiteCheckBlind, ACameraOnlyRunViolatesEveryBlindBound) {
  suite::MetricsFile m = blind_run();
  suite::BlindMetrics& b = *m.primary.blind;
  b.covered_with_pose = 0;
  b.first_after_tracked = false;
  b.first_after_state = "lost";
  b.first_after_method = "none";
  b.first_after_error_m.reset();
  b.first_after_error_deg.reset();
  const std::vector<std::string> lines = lines_of(suite::check_expectations(blind_bounds(), m));
  const std::string no_error =
      "no error across the stretch in the metrics (the first frame after it or the last before it has no "
      "pose)";
  EXPECT_EQ(lines, (std::vector<std::string>{
                       "blind_poses_all: 0 of 90 covered frames have a pose",
                       "blind_after_error_m_max: " + no_error, "blind_after_error_deg_max: " + no_error,
                       "blind_no_global_relocalisation: the first frame after the cover "
                       "(540) has no pose (state lost)"}));
  // A run that ended inside the cover, and one with no blind object at all.
  b.first_after.reset();
  scenes::Expectations only_reloc;
  only_reloc.blind_no_global_relocalisation = true;
  EXPECT_EQ(lines_of(suite::check_expectations(only_reloc, m)),
            std::vector<std::string>{
                "blind_no_global_relocalisation: the run ended before the first frame after the cover"});
  m.primary.blind.reset();
  EXPECT_EQ(lines_of(suite::check_expectations(only_reloc, m)),
            std::vector<std::string>{
                "blind_no_global_relocalisation: no blind stretch in the metrics (blind is absent)"});
}

TEST(SuiteCheckBlind, BadBlindObjectsAreRefusedNamingFileLineAndKey) {
  const std::string path = ::testing::TempDir() + "pvb_metrics_blind_" + std::to_string(::getpid()) + ".json";
  auto message = [&path](const std::string& from, const std::string& to) {
    return test::metrics_error_after_edit(path, "blind.json", from, to);
  };
  const std::string f = path + ":";
  EXPECT_EQ(
      message("\"covered_frames_with_pose\": 90", "\"covered_frames_with_pose\": 91"),
      f + "10: blind.covered_frames_with_pose: expected an integer in [0, the covered frames = 90], got 91");
  EXPECT_EQ(message("\"first_after_tracked\": true", "\"first_after_tracked\": \"yes\""),
            f + "12: blind.first_after_tracked: expected true or false, got the string \"yes\"");
  EXPECT_EQ(message("\"covered_frames\": [450, 539]", "\"covered_frames\": [450, 439]"),
            f + "10: blind.covered_frames[1]: expected an integer >= first = 450, got 439");
  EXPECT_EQ(message("\"rot_deg\": 0.42", "\"rot_deg\": 270"),
            f + "13: blind.first_after_error.rot_deg: expected a number in [0, 180], got 270");
  EXPECT_EQ(message("{\"trans_m\": 0.031, \"rot_deg\": 0.42}", "0.031"),
            f + "13: blind.first_after_error: expected an object or null");
  std::remove(path.c_str());
}
