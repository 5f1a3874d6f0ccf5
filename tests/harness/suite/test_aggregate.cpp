// Sweep aggregation over hand-written metrics.json fixtures.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <optional>
#include <string>

#include "pvb/suite/aggregate.hpp"
#include "suite_fixtures.hpp"

using namespace pvb;

using pvb::test::suite_fixture;

namespace {

// Seed 1: good (PE 4.2 mm, baseline 5.1 mm); seed 2: PE 23.5 mm, baseline
// 15.0 mm, 4 lost; seed 3: no metrics.json; seed 4: aborted, no ATE, exit 0.
suite::SweepAggregate sample() {
  std::vector<suite::SeedRun> runs;
  runs.push_back(suite::read_seed_run(1, suite_fixture("good_compare.json")));
  runs.push_back(suite::read_seed_run(2, suite_fixture("worse_than_baseline.json")));
  runs.push_back(suite::read_seed_run(3, suite_fixture("seed_3_never_written.json"), 1));
  runs.push_back(suite::read_seed_run(4, suite_fixture("lost_aborted.json")));
  return suite::aggregate("pv_station", runs);
}

// A --compare seed built by hand: ATEs in millimetres, nullopt for "ate": null.
suite::SeedRun compare_run(std::uint64_t seed, std::optional<double> pe_mm, std::optional<double> base_mm) {
  suite::SeedRun r;
  r.seed = seed;
  suite::MetricsFile m;
  m.primary.mode = "pe-slam";
  m.primary.status = "completed";
  m.primary.frames = 100;
  if (pe_mm) m.primary.ate_rmse_m = *pe_mm / 1000.0;
  suite::RunMetrics b;
  b.mode = "baseline";
  b.status = "completed";
  b.frames = 100;
  if (base_mm) b.ate_rmse_m = *base_mm / 1000.0;
  m.baseline = b;
  r.metrics = m;
  return r;
}

}  // namespace

TEST(StudentT, QuantilesMatchPublishedTables) {
  // Two-sided 95 % critical values from the usual t table (3 decimals).
  EXPECT_NEAR(suite::student_t_quantile(0.975, 1), 12.706, 5e-4);
  EXPECT_NEAR(suite::student_t_quantile(0.975, 2), 4.303, 5e-4);
  EXPECT_NEAR(suite::student_t_quantile(0.975, 3), 3.182, 5e-4);
  EXPECT_NEAR(suite::student_t_quantile(0.975, 4), 2.776, 5e-4);
  EXPECT_NEAR(suite::student_t_quantile(0.975, 7), 2.365, 5e-4);
  EXPECT_NEAR(suite::student_t_quantile(0.975, 10), 2.228, 5e-4);
  EXPECT_NEAR(suite::student_t_quantile(0.975, 30), 2.042, 5e-4);
  EXPECT_NEAR(suite::student_t_quantile(0.975, 120), 1.980, 5e-4);
  EXPECT_NEAR(suite::student_t_quantile(0.975, 100000), 1.960, 5e-4);  // the normal's 1.95996
  EXPECT_NEAR(suite::student_t_quantile(0.95, 10), 1.812, 5e-4);
  EXPECT_NEAR(suite::student_t_quantile(0.995, 5), 4.032, 5e-4);
}

TEST(StudentT, ClosedFormsSymmetryAndBadInput) {
  // dof 1 is the Cauchy distribution: t = tan(pi (p - 1/2)); dof 2:
  // t = (2p - 1) sqrt(2 / (4 p (1 - p))).
  const double pi = 3.14159265358979323846;
  EXPECT_NEAR(suite::student_t_quantile(0.975, 1), std::tan(pi * 0.475), 1e-9);
  EXPECT_NEAR(suite::student_t_quantile(0.9, 2), 0.8 * std::sqrt(2.0 / (4 * 0.9 * 0.1)), 1e-12);
  EXPECT_DOUBLE_EQ(suite::student_t_quantile(0.025, 6), -suite::student_t_quantile(0.975, 6));
  EXPECT_EQ(suite::student_t_quantile(0.5, 3), 0.0);
  EXPECT_TRUE(std::isnan(suite::student_t_quantile(1.0, 3)));
  EXPECT_TRUE(std::isnan(suite::student_t_quantile(0.975, 0)));
}

TEST(PairedComparison, ClearPeWin) {
  // d = -1, -2, -3, -2 mm: mean -2, sd sqrt(2/3) = 0.8165, se 0.40825,
  // t(0.975, 3) = 3.1824 -> half width 1.2992 mm.
  const suite::PairedComparison p = suite::compare_paired(
      {compare_run(1, 5, 6), compare_run(2, 4, 6), compare_run(3, 3, 6), compare_run(4, 5, 7)});
  EXPECT_EQ(p.count, 4);
  EXPECT_NEAR(p.mean_m, -0.002, 1e-12);
  EXPECT_NEAR(p.sd_m, 0.001 * std::sqrt(2.0 / 3.0), 1e-12);
  EXPECT_NEAR(p.se_m, 0.001 * std::sqrt(2.0 / 3.0) / 2.0, 1e-12);
  ASSERT_TRUE(p.has_ci);
  EXPECT_NEAR(p.t_quantile, 3.1824, 1e-4);
  EXPECT_NEAR(p.ci_low_m, -0.0032992, 1e-6);
  EXPECT_NEAR(p.ci_high_m, -0.0007008, 1e-6);
  EXPECT_EQ(p.pe_not_worse, 4);
  EXPECT_EQ(p.pe_better, 4);
  EXPECT_EQ(p.pe_worse, 0);
  EXPECT_NEAR(p.effect_size_dz, -2.0 / std::sqrt(2.0 / 3.0), 1e-9);
  EXPECT_NEAR(p.sign_test_p, 2.0 / 16.0, 1e-12);  // all four signs negative
  // Baseline mean 6.25 mm: the margin is 10 % of it, above the 0.5 mm floor.
  EXPECT_NEAR(p.baseline_mean_m, 0.00625, 1e-12);
  EXPECT_NEAR(p.margin_m, 0.000625, 1e-12);
  EXPECT_TRUE(p.not_worse);
  EXPECT_EQ(p.verdict, suite::PairedVerdict::kPeBetter);
  const std::string line = suite::format_paired_line(p);
  EXPECT_EQ(line.find("PE-SLAM − baseline ATE: mean -2.00 mm, 95 % CI [-3.30, -0.70] mm over 4 seeds "
                      "(effect size d_z -2.45; PE ≤ baseline on 4, sign test p = 0.12); PE-SLAM better; "
                      "not significantly worse: yes (upper end -0.70 mm ≤ margin 0.6"),
            0u)
      << line;
}

TEST(PairedComparison, ClearLoss) {
  // d = +3, +5, +4 mm: mean 4, sd 1, se 0.57735, t(0.975, 2) = 4.3027 ->
  // half width 2.4841 mm.
  const suite::PairedComparison p =
      suite::compare_paired({compare_run(1, 9, 6), compare_run(2, 10, 5), compare_run(3, 12, 8)});
  EXPECT_EQ(p.count, 3);
  EXPECT_NEAR(p.mean_m, 0.004, 1e-12);
  EXPECT_NEAR(p.sd_m, 0.001, 1e-12);
  EXPECT_NEAR(p.ci_low_m, 0.0015159, 1e-6);
  EXPECT_NEAR(p.ci_high_m, 0.0064841, 1e-6);
  EXPECT_EQ(p.pe_not_worse, 0);
  EXPECT_EQ(p.pe_worse, 3);
  EXPECT_NEAR(p.sign_test_p, 0.25, 1e-12);
  EXPECT_FALSE(p.not_worse);
  EXPECT_EQ(p.verdict, suite::PairedVerdict::kBaselineBetter);
  // Baseline mean 19/3 mm: margin 0.633 mm.
  EXPECT_EQ(suite::format_paired_line(p),
            "PE-SLAM − baseline ATE: mean 4.00 mm, 95 % CI [1.52, 6.48] mm over 3 seeds "
            "(effect size d_z 4.00; PE ≤ baseline on 0, sign test p = 0.25); baseline better; "
            "not significantly worse: no (upper end 6.48 mm > margin 0.63 mm)");
}

TEST(PairedComparison, TieStraddlesZeroAndEqualCountsAsNotWorse) {
  // d = -1, +1.5, -0.5, +0.5, 0 mm: mean 0.1, sd sqrt(3.7 / 4) = 0.96177,
  // se 0.43012, t(0.975, 4) = 2.7764 -> CI [-1.0942, 1.2942] mm.  PE ≤
  // baseline on the seeds with d = -1, -0.5 and the exact tie.
  const suite::PairedComparison p =
      suite::compare_paired({compare_run(1, 4, 5), compare_run(2, 6.5, 5), compare_run(3, 4.5, 5),
                             compare_run(4, 5.5, 5), compare_run(5, 5, 5)});
  EXPECT_EQ(p.count, 5);
  EXPECT_NEAR(p.mean_m, 0.0001, 1e-12);
  EXPECT_NEAR(p.sd_m, 0.001 * std::sqrt(0.925), 1e-12);
  EXPECT_NEAR(p.ci_low_m, -0.0010942, 1e-6);
  EXPECT_NEAR(p.ci_high_m, 0.0012942, 1e-6);
  EXPECT_EQ(p.pe_not_worse, 3);
  // The sign test leaves the tie out: 2 better, 2 worse.
  EXPECT_EQ(p.pe_better, 2);
  EXPECT_EQ(p.pe_worse, 2);
  EXPECT_DOUBLE_EQ(p.sign_test_p, 1.0);
  EXPECT_EQ(p.verdict, suite::PairedVerdict::kNoSignificantDifference);
  EXPECT_EQ(suite::format_paired_line(p),
            "PE-SLAM − baseline ATE: mean 0.10 mm, 95 % CI [-1.09, 1.29] mm over 5 seeds "
            "(effect size d_z 0.10; PE ≤ baseline on 3, sign test p = 1.00); no significant difference at "
            "95 %; not significantly worse: no (upper end 1.29 mm > margin 0.50 mm)");
}

TEST(PairedComparison, SeedsWithoutBothAtesAreLeftOut) {
  std::vector<suite::SeedRun> runs = {compare_run(1, 4, 6),             // d = -2
                                      compare_run(2, std::nullopt, 5),  // PE lost its ATE
                                      compare_run(3, 7, std::nullopt),  // baseline lost its ATE
                                      compare_run(4, 3, 4),             // d = -1
                                      compare_run(5, 100, 1)};          // no baseline object (below)
  runs[4].metrics->baseline.reset();
  suite::SeedRun no_metrics;
  no_metrics.seed = 6;
  no_metrics.error = "missing";
  runs.push_back(no_metrics);
  EXPECT_FALSE(suite::paired_ate_difference_m(runs[1]));
  EXPECT_FALSE(suite::paired_ate_difference_m(runs[2]));
  EXPECT_FALSE(suite::paired_ate_difference_m(runs[4]));
  EXPECT_FALSE(suite::paired_ate_difference_m(runs[5]));
  EXPECT_NEAR(*suite::paired_ate_difference_m(runs[0]), -0.002, 1e-12);

  // Pairs: d = -2, -1 mm; mean -1.5, sd 0.7071, se 0.5, t(0.975, 1) = 12.706.
  const suite::SweepAggregate a = suite::aggregate("s", runs);
  EXPECT_EQ(a.paired.count, 2);
  EXPECT_NEAR(a.paired.mean_m, -0.0015, 1e-12);
  EXPECT_NEAR(a.paired.se_m, 0.0005, 1e-12);
  EXPECT_NEAR(a.paired.ci_low_m, -0.0015 - 12.7062 * 0.0005, 1e-6);
  EXPECT_EQ(a.paired.pe_not_worse, 2);
  EXPECT_EQ(a.paired.verdict, suite::PairedVerdict::kNoSignificantDifference);
  // The per-system means still use every ATE they have.
  EXPECT_EQ(a.primary.ate_rmse_m.count, 4);
  EXPECT_EQ(a.baseline.ate_rmse_m.count, 3);
}

TEST(PairedComparison, SignTestIsTheExactTwoSidedBinomial) {
  EXPECT_DOUBLE_EQ(suite::sign_test_p(0, 0), 1.0);
  EXPECT_NEAR(suite::sign_test_p(0, 10), 2.0 / 1024.0, 1e-12);
  EXPECT_NEAR(suite::sign_test_p(10, 10), 2.0 / 1024.0, 1e-12);  // symmetric
  EXPECT_NEAR(suite::sign_test_p(2, 10), 2.0 * (1 + 10 + 45) / 1024.0, 1e-12);
  EXPECT_NEAR(suite::sign_test_p(11, 14), 2.0 * (1 + 14 + 91 + 364) / 16384.0, 1e-12);
  EXPECT_DOUBLE_EQ(suite::sign_test_p(5, 10), 1.0);       // capped at 1
  EXPECT_NEAR(suite::sign_test_p(0, 2000), 0.0, 1e-300);  // no overflow for large n
}

TEST(PairedComparison, NotWorseMarginIsHalfAMillimetreOrTenPercent) {
  EXPECT_DOUBLE_EQ(suite::not_worse_margin_m(0.003), 0.0005);
  EXPECT_DOUBLE_EQ(suite::not_worse_margin_m(0.0), 0.0005);
  EXPECT_NEAR(suite::not_worse_margin_m(0.012), 0.0012, 1e-15);
  // d = +0.4, +0.6 mm, +0.5 mm around a 4 mm baseline: the upper end
  // 0.5 + 4.3027 · 0.1 / sqrt(3) = 0.748 mm is over the 0.5 mm floor.
  auto p = suite::compare_paired({compare_run(1, 4.4, 4), compare_run(2, 4.6, 4), compare_run(3, 4.5, 4)});
  EXPECT_NEAR(p.ci_high_m, 0.0005 + 4.3027 * 0.0001 / std::sqrt(3.0), 1e-7);
  EXPECT_FALSE(p.not_worse);
  // The same differences around a 10 mm baseline: the margin is 1 mm.
  p = suite::compare_paired({compare_run(1, 10.4, 10), compare_run(2, 10.6, 10), compare_run(3, 10.5, 10)});
  EXPECT_NEAR(p.margin_m, 0.001, 1e-12);
  EXPECT_TRUE(p.not_worse);
}

TEST(PairedComparison, OneSeedHasNoInterval) {
  const suite::PairedComparison p =
      suite::compare_paired({compare_run(1, 4, 5), compare_run(2, std::nullopt, 5)});
  EXPECT_EQ(p.count, 1);
  EXPECT_FALSE(p.has_ci);
  EXPECT_NEAR(p.mean_m, -0.001, 1e-12);
  EXPECT_EQ(p.sd_m, 0.0);
  EXPECT_EQ(p.verdict, suite::PairedVerdict::kTooFewSeeds);
  EXPECT_EQ(suite::format_paired_line(p),
            "PE-SLAM − baseline ATE: mean -1.00 mm over 1 seed (PE ≤ baseline on 1); too few seeds");

  const suite::PairedComparison none = suite::compare_paired({compare_run(1, std::nullopt, 5)});
  EXPECT_EQ(none.count, 0);
  EXPECT_EQ(none.verdict, suite::PairedVerdict::kTooFewSeeds);
  EXPECT_EQ(suite::format_paired_line(none), "PE-SLAM − baseline ATE: no seed with both ATEs; too few seeds");
  const std::string md = suite::format_markdown(suite::aggregate("s", {compare_run(1, std::nullopt, 5)}));
  EXPECT_NE(md.find("\nPE-SLAM − baseline ATE: no seed with both ATEs; too few seeds\n"), std::string::npos)
      << md;
  EXPECT_EQ(md.find("standard error"), std::string::npos) << md;
  const YAML::Node j = YAML::Load(suite::format_json(suite::aggregate("s", {compare_run(1, 4, 5)})));
  EXPECT_EQ(j["paired"]["count"].as<int>(), 1);
  EXPECT_TRUE(j["paired"]["ci95_low_m"].IsNull());
  EXPECT_EQ(j["paired"]["verdict"].as<std::string>(), "too few seeds");
}

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
  std::vector<suite::SeedRun> runs = {suite::read_seed_run(5, suite_fixture("lost_aborted.json"))};
  const suite::SweepAggregate a = suite::aggregate("tracking_failure", runs);
  EXPECT_FALSE(a.has_baseline);
  EXPECT_EQ(a.failed, 0);
  EXPECT_NE(suite::format_markdown(a).find("| PE-SLAM | 1 | n/a |"), std::string::npos)
      << suite::format_markdown(a);
  EXPECT_EQ(suite::format_markdown(a).find("PE-SLAM − baseline"), std::string::npos);
  EXPECT_TRUE(YAML::Load(suite::format_json(a))["paired"].IsNull());
}

TEST(SweepAggregate, MarkdownHasSummaryAndPerSeedRows) {
  const std::string md = suite::format_markdown(sample());
  EXPECT_NE(md.find("4 seeds, 3 with metrics, 1 failed"), std::string::npos) << md;
  // PE-SLAM ATE mean 13.85 mm, sd 19.3 / sqrt(2) = 13.65 mm.
  EXPECT_NE(md.find("| PE-SLAM | 3 | 13.85 ± 13.65 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| baseline (ORB-SLAM2 motion model) | 2 | 10.05 ± 7.00 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 2 | 0 | completed | 600 | 4 | 23.50 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 3 | 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("first loss at frame 141"), std::string::npos) << md;
  // Paired: d = -0.9 and +8.5 mm; mean 3.8, sd 6.6468, se 4.7, t(0.975, 1)
  // = 12.7062 -> half width 59.72 mm.  Right after the summary table.
  const std::size_t line = md.find(
      "\nPE-SLAM − baseline ATE: mean 3.80 mm, 95 % CI [-55.92, 63.52] mm over 2 seeds (effect size d_z "
      "0.57; "
      "PE ≤ baseline on 1, sign test p = 1.00); no significant difference at 95 %; not significantly worse: "
      "no "
      "(upper end 63.52 mm > margin 1.0");
  EXPECT_NE(line, std::string::npos) << md;
  EXPECT_LT(md.find("| baseline (ORB-SLAM2 motion model) | 2 |"), line);
  EXPECT_LT(line, md.find("## Per seed"));
  EXPECT_NE(md.find("SD 6.65 mm, standard error 4.70 mm"), std::string::npos) << md;
  EXPECT_NE(md.find("| 15.00 | 8.50 |"), std::string::npos) << md;  // seed 2's baseline ATE and d
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
  EXPECT_NE(lines[0].find(",baseline_tracking_ms_median,pe_minus_baseline_ate_m,error"), std::string::npos);
  EXPECT_EQ(lines[1], "1,0,completed,300,0,0.0042,0.0011,17.5,1.12,0,0.0051,16.9,-0.0009,");
  EXPECT_EQ(lines[2].substr(lines[2].size() - 8), ",0.0085,");
  EXPECT_EQ(lines[4], "4,0,aborted,142,1,,,15,1.3,,,,,");
  EXPECT_EQ(lines[3].substr(0, 15), "3,1,,,,,,,,,,,,");  // 14 columns, the last one the error
  EXPECT_NE(lines[3][15], ',');
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
  EXPECT_NEAR(j["runs"][1]["pe_minus_baseline_ate_m"].as<double>(), 0.0085, 1e-12);
  EXPECT_EQ(j["paired"]["count"].as<int>(), 2);
  EXPECT_NEAR(j["paired"]["mean_m"].as<double>(), 0.0038, 1e-9);
  EXPECT_NEAR(j["paired"]["se_m"].as<double>(), 0.0047, 1e-9);
  EXPECT_NEAR(j["paired"]["ci95_low_m"].as<double>(), 0.0038 - 12.7062 * 0.0047, 1e-6);
  EXPECT_NEAR(j["paired"]["ci95_high_m"].as<double>(), 0.0038 + 12.7062 * 0.0047, 1e-6);
  EXPECT_EQ(j["paired"]["pe_not_worse"].as<int>(), 1);
  EXPECT_EQ(j["paired"]["pe_better"].as<int>(), 1);
  EXPECT_NEAR(j["paired"]["sign_test_p"].as<double>(), 1.0, 1e-12);
  EXPECT_FALSE(j["paired"]["not_significantly_worse"].as<bool>());
  EXPECT_EQ(j["paired"]["verdict"].as<std::string>(), "no significant difference at 95 %");
}

TEST(SweepAggregate, FigureShowsEverySeedAndBothModes) {
  const suite::SweepAggregate a = sample();
  const eval::Figure f = make_sweep_figure(a);
  const std::string svg = eval::format_svg(f);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  for (const char* label : {">1<", ">2<", ">3<", ">4<", ">baseline<", "PE-SLAM"})
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

TEST(PairedComparison, TwoSensorSetupsAreNamedByTheSetups) {
  // --compare-sensors camera,camera+imu+wheels: the same figures as ClearLoss,
  // with B = camera+imu+wheels the primary run and A = camera the reference.
  std::vector<suite::SeedRun> runs = {compare_run(1, 9, 6), compare_run(2, 10, 5), compare_run(3, 12, 8)};
  for (suite::SeedRun& r : runs) {
    r.metrics->primary.sensors = "camera+imu+wheels";
    r.metrics->baseline->mode = "pe-slam";
    r.metrics->baseline->sensors = "camera";
  }
  const suite::PairedComparison p = suite::compare_paired(runs);
  EXPECT_EQ(p.verdict, suite::PairedVerdict::kBaselineBetter);
  EXPECT_EQ(suite::verdict_text(p), "camera better");
  EXPECT_EQ(suite::format_paired_line(p),
            "camera+imu+wheels − camera ATE: mean 4.00 mm, 95 % CI [1.52, 6.48] mm over 3 seeds "
            "(effect size d_z 4.00; camera+imu+wheels ≤ camera on 0, sign test p = 0.25); camera better; "
            "not significantly worse: no (upper end 6.48 mm > margin 0.63 mm)");
  const suite::SweepAggregate a = suite::aggregate("s", runs);
  EXPECT_NE(suite::format_markdown(a).find("| camera | 3 |"), std::string::npos) << suite::format_markdown(a);
  EXPECT_NE(suite::format_json(a).find("\"primary\": \"camera+imu+wheels\", \"reference\": \"camera\""),
            std::string::npos);
}

// The per-seed table named the reference run "baseline" with
// --compare-sensors too: its columns are named by the setups.
TEST(SweepAggregate, PerSeedColumnsAreNamedByTheSetupsCompared) {
  std::vector<suite::SeedRun> runs = {compare_run(1, 9, 6), compare_run(2, 10, 5)};
  const std::string by_mode = suite::format_markdown(suite::aggregate("s", runs));
  EXPECT_NE(by_mode.find("| baseline lost | baseline ATE RMSE (mm) | PE − baseline (mm) |"), std::string::npos)
      << by_mode;
  for (suite::SeedRun& r : runs) {
    r.metrics->primary.sensors = "camera+imu";
    r.metrics->baseline->mode = "pe-slam";
    r.metrics->baseline->sensors = "camera";
  }
  const std::string md = suite::format_markdown(suite::aggregate("s", runs));
  EXPECT_NE(md.find("| camera lost | camera ATE RMSE (mm) | camera+imu − camera (mm) |"), std::string::npos) << md;
  EXPECT_EQ(md.find("baseline lost"), std::string::npos) << md;
  EXPECT_NE(md.find("10 % of the camera's mean"), std::string::npos) << md;
}
