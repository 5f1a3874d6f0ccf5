// Sweep aggregation over hand-written metrics.json fixtures.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>

#include "pvb/suite/aggregate.hpp"

using namespace pvb;

namespace {

std::string fixture(const std::string& name) {
  return std::string(PVB_SOURCE_DIR) + "/tests/harness/suite/fixtures/" + name;
}

// Seed 1: good (PE 4.2 mm, baseline 5.1 mm); seed 2: PE 23.5 mm, baseline
// 15.0 mm, 4 lost; seed 3: no metrics.json; seed 4: aborted, no ATE, exit 0.
suite::SweepAggregate sample() {
  std::vector<suite::SeedRun> runs;
  runs.push_back(suite::read_seed_run(1, fixture("good_compare.json")));
  runs.push_back(suite::read_seed_run(2, fixture("worse_than_baseline.json")));
  runs.push_back(suite::read_seed_run(3, fixture("seed_3_never_written.json"), 1));
  runs.push_back(suite::read_seed_run(4, fixture("lost_aborted.json")));
  return suite::aggregate("pv_station", runs);
}

}  // namespace

TEST(SweepAggregate, SummaryIsMeanAndSampleSd) {
  const suite::Summary s = suite::summarize({1.0, 2.0, 3.0, 4.0});
  EXPECT_EQ(s.count, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_NEAR(s.sd, std::sqrt(5.0 / 3.0), 1e-12);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(suite::summarize({7.0}).sd, 0.0);
  EXPECT_EQ(suite::summarize({}).count, 0);
}

TEST(SweepAggregate, SkipsMissingValuesAndCountsFailures) {
  const suite::SweepAggregate a = sample();
  ASSERT_EQ(a.runs.size(), 4u);
  EXPECT_EQ(a.failed, 1);  // seed 3; the aborted seed 4 exited 0 and has metrics
  EXPECT_FALSE(a.runs[2].metrics.has_value());
  EXPECT_NE(a.runs[2].error.find("seed_3_never_written.json"), std::string::npos);

  EXPECT_EQ(a.primary.ate_rmse_m.count, 2);  // seed 4 has ate: null
  EXPECT_NEAR(a.primary.ate_rmse_m.mean, (0.0042 + 0.0235) / 2, 1e-12);
  EXPECT_NEAR(a.primary.ate_rmse_m.sd, (0.0235 - 0.0042) / std::sqrt(2.0), 1e-12);
  EXPECT_EQ(a.primary.lost_frames.count, 3);
  EXPECT_NEAR(a.primary.lost_frames.mean, 5.0 / 3.0, 1e-12);
  EXPECT_NEAR(a.primary.tracking_ms_median.mean, (17.5 + 19.0 + 15.0) / 3, 1e-12);
  EXPECT_NEAR(a.primary.realtime_factor.mean, (1.12 + 0.93 + 1.3) / 3, 1e-12);

  ASSERT_TRUE(a.has_baseline);
  EXPECT_EQ(a.baseline.ate_rmse_m.count, 2);
  EXPECT_NEAR(a.baseline.ate_rmse_m.mean, (0.0051 + 0.0150) / 2, 1e-12);
  EXPECT_EQ(a.baseline.realtime_factor.count, 0);
}

TEST(SweepAggregate, NoBaselineWithoutCompare) {
  std::vector<suite::SeedRun> runs = {suite::read_seed_run(5, fixture("lost_aborted.json"))};
  const suite::SweepAggregate a = suite::aggregate("tracking_failure", runs);
  EXPECT_FALSE(a.has_baseline);
  EXPECT_EQ(a.failed, 0);
  EXPECT_NE(suite::format_markdown(a).find("| PE-SLAM | 1 | n/a |"), std::string::npos)
      << suite::format_markdown(a);
}

TEST(SweepAggregate, MarkdownHasSummaryAndPerSeedRows) {
  const std::string md = suite::format_markdown(sample());
  EXPECT_NE(md.find("4 seeds, 3 with metrics, 1 failed"), std::string::npos) << md;
  // PE-SLAM ATE mean 13.85 mm, sd 19.3 / sqrt(2) = 13.65 mm.
  EXPECT_NE(md.find("| PE-SLAM | 3 | 13.85 ± 13.65 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| ORB-SLAM2 baseline | 2 | 10.05 ± 7.00 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 2 | 0 | completed | 600 | 4 | 23.50 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 3 | 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("first loss at frame 141"), std::string::npos) << md;
}

TEST(SweepAggregate, CsvHasOneRowPerSeed) {
  const std::string csv = suite::format_csv(sample());
  std::vector<std::string> lines;
  std::size_t pos = 0;
  while (pos < csv.size()) {
    const std::size_t nl = csv.find('\n', pos);
    lines.push_back(csv.substr(pos, nl - pos));
    pos = nl + 1;
  }
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0].substr(0, 10), "seed,exit_");
  EXPECT_EQ(lines[1], "1,0,completed,300,0,0.0042,0.0011,17.5,1.12,0,0.0051,16.9,");
  EXPECT_EQ(lines[4], "4,0,aborted,142,1,,,15,1.3,,,,");
  EXPECT_EQ(lines[3].substr(0, 14), "3,1,,,,,,,,,,,");
}

TEST(SweepAggregate, JsonParsesAndCarriesTheSummaries) {
  const YAML::Node j = YAML::Load(suite::format_json(sample()));
  EXPECT_EQ(j["scenario"].as<std::string>(), "pv_station");
  EXPECT_EQ(j["seeds"].as<int>(), 4);
  EXPECT_EQ(j["failed"].as<int>(), 1);
  EXPECT_NEAR(j["primary"]["ate_rmse_m"]["mean"].as<double>(), 0.01385, 1e-9);
  EXPECT_EQ(j["primary"]["ate_rmse_m"]["count"].as<int>(), 2);
  EXPECT_NEAR(j["baseline"]["ate_rmse_m"]["mean"].as<double>(), 0.01005, 1e-9);
  ASSERT_EQ(j["runs"].size(), 4u);
  EXPECT_TRUE(j["runs"][3]["ate_rmse_m"].IsNull());
  EXPECT_NE(j["runs"][2]["error"].as<std::string>().find("seed_3_never_written"), std::string::npos);
  EXPECT_NEAR(j["runs"][1]["baseline"]["ate_rmse_m"].as<double>(), 0.015, 1e-12);
}

TEST(SweepAggregate, FigureShowsEverySeedAndBothModes) {
  const suite::SweepAggregate a = sample();
  const eval::Figure f = make_sweep_figure(a);
  const std::string svg = eval::format_svg(f);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  for (const char* label : {">1<", ">2<", ">3<", ">4<", "ORB-SLAM2", "PE-SLAM"})
    EXPECT_NE(svg.find(label), std::string::npos) << label;
  // One hollow square per baseline value plus the legend's.
  EXPECT_EQ(f.polylines.size(), 3u);
  // The PE dots lie inside the plot, the higher ATE higher up (smaller y).
  std::vector<double> dot_y;
  for (const auto& l : f.lines)
    if (l.width_px == 8 && l.y0 > 40) dot_y.push_back(l.y0);
  ASSERT_EQ(dot_y.size(), 2u);
  EXPECT_GT(dot_y[0], dot_y[1]);
}
