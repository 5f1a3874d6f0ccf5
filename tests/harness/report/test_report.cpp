// The report pieces of a scenario run, on hand-built reports: metrics.json
// (parsed back with yaml-cpp, as the checker reads it), geometry helpers,
// the comparison table and index.html.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>

#include "pvb/common/text.hpp"
#include "pvb/eval/charts.hpp"
#include "pvb/report/report.hpp"

namespace pvb::run {
namespace {

geom::SE3d pose_xy(double x, double y, double yaw) {
  geom::SE3d T = geom::SE3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.5);
  return T;
}

/// An evaluation of a synthetic drive: ground truth along x, the estimate
/// off by a known lateral error that grows with time.
eval::EvalResult synthetic_eval(double lateral_error_m) {
  eval::Trajectory gt, est;
  for (int i = 0; i < 50; ++i) {
    const std::int64_t t_ns = i * 33'333'333LL;
    const double x = 0.02 * i;
    gt.poses.push_back({t_ns, pose_xy(x, 0.1 * std::sin(0.2 * i), 0.05 * i)});
    est.poses.push_back({t_ns, pose_xy(x, 0.1 * std::sin(0.2 * i) + lateral_error_m * i / 49.0, 0.05 * i)});
  }
  eval::EvalOptions eo;
  eo.alignment = eval::Alignment::kNone;
  return eval::evaluate(gt, est, eo);
}

SlamRun slam_run(const std::string& mode, double lateral_error_m) {
  SlamRun r;
  r.mode = mode;
  r.frames = 50;
  r.lost_frames = 2;
  r.keyframes = 7;
  r.map_points = 900;
  for (int i = 0; i < 50; ++i)
    r.per_frame.push_back({i, i / 30.0, i != 20 && i != 21, 10.0 + i % 5, i > 0 ? 300 : 0, i > 0 ? 290 : 0,
                           i != 20 && i != 21 ? "ok" : "lost", i != 20 && i != 21 ? "motion" : "none"});
  r.loss_events.push_back(
      {20, 20 / 30.0, "local map: only 21 inliers after pose optimisation (need 30)", 22});
  r.eval = synthetic_eval(lateral_error_m);
  return r;
}

RunReport hand_report() {
  RunReport r;
  r.scenario = "pv_station";
  r.scenario_file = "scenes/pv_station.yaml";
  r.seed = 7;
  r.sync = true;
  r.renderer = "test";
  r.sim_s = 50 / 30.0;
  r.wall_s = 0.5;
  r.primary = slam_run("pe-slam", 0.01);
  r.profile = {{"render", 500, 50, "producer"}, {"tracking", 250, 50, "consumer"}};
  return r;
}

TEST(RunReport, MetricsJsonHasTheContractKeys) {
  const RunReport r = hand_report();
  const YAML::Node m = YAML::Load(metrics_json(r));
  EXPECT_EQ(m["scenario"].as<std::string>(), "pv_station");
  EXPECT_EQ(m["scenario_file"].as<std::string>(), "scenes/pv_station.yaml");
  EXPECT_EQ(m["seed"].as<int>(), 7);
  EXPECT_EQ(m["mode"].as<std::string>(), "pe-slam");
  EXPECT_EQ(m["status"].as<std::string>(), "completed");
  EXPECT_EQ(m["frames"].as<int>(), 50);
  EXPECT_EQ(m["lost_frames"].as<int>(), 2);
  EXPECT_EQ(m["keyframes"].as<int>(), 7);
  EXPECT_EQ(m["map_points"].as<int>(), 900);
  EXPECT_NEAR(m["ate"]["rmse"].as<double>(), r.primary.eval->ate.rmse, 1e-12);
  for (const char* k : {"mean", "median", "std", "min", "max", "count"})
    EXPECT_TRUE(m["ate"][k].IsScalar()) << k;
  EXPECT_EQ(m["rpe"]["unit"].as<std::string>(), "f");
  EXPECT_NEAR(m["rpe"]["trans"]["rmse"].as<double>(), r.primary.eval->rpe_trans_m.rmse, 1e-12);
  EXPECT_NEAR(m["rpe"]["rot_deg"]["max"].as<double>(), r.primary.eval->rpe_rot_deg.max, 1e-12);
  // tracking times 10..14 ms, evenly: median 12, mean 12.
  EXPECT_NEAR(m["tracking_ms"]["median"].as<double>(), 12.0, 1e-9);
  EXPECT_NEAR(m["tracking_ms"]["mean"].as<double>(), 12.0, 1e-9);
  EXPECT_NEAR(m["tracking_ms"]["p95"].as<double>(), 14.0, 1e-9);
  EXPECT_NEAR(m["realtime_factor"].as<double>(), (50 / 30.0) / 0.5, 1e-6);
  EXPECT_NEAR(m["sim_s"].as<double>(), 50 / 30.0, 1e-6);
  EXPECT_NEAR(m["wall_s"].as<double>(), 0.5, 1e-9);
  ASSERT_EQ(m["loss_events"].size(), 1u);
  EXPECT_EQ(m["loss_events"][0]["frame"].as<int>(), 20);
  EXPECT_NEAR(m["loss_events"][0]["t_s"].as<double>(), 20 / 30.0, 1e-6);
  EXPECT_NE(m["loss_events"][0]["reason"].as<std::string>().find("21 inliers"), std::string::npos);
  EXPECT_EQ(m["loss_events"][0]["recovered_frame"].as<int>(), 22);
  EXPECT_NEAR(m["profile"]["render"]["per_frame_ms"].as<double>(), 10.0, 1e-9);
  EXPECT_EQ(m["profile"]["render"]["thread"].as<std::string>(), "producer");
  // Only with --closed-loop / --compare:
  EXPECT_FALSE(m["closed_loop"]);
  EXPECT_FALSE(m["baseline"]);
  EXPECT_FALSE(m["comparison"]);
}

TEST(RunReport, CompareAddsBaselineAndReductions) {
  RunReport r = hand_report();
  r.baseline = slam_run("baseline", 0.04);
  const YAML::Node m = YAML::Load(metrics_json(r));
  ASSERT_TRUE(m["baseline"]);
  EXPECT_EQ(m["baseline"]["mode"].as<std::string>(), "baseline");
  EXPECT_EQ(m["baseline"]["frames"].as<int>(), 50);
  EXPECT_EQ(m["baseline"]["status"].as<std::string>(), "completed");
  EXPECT_NEAR(m["baseline"]["ate"]["rmse"].as<double>(), r.baseline->eval->ate.rmse, 1e-12);
  const double expected =
      100.0 * (r.baseline->eval->ate.rmse - r.primary.eval->ate.rmse) / r.baseline->eval->ate.rmse;
  EXPECT_GT(expected, 0.0);
  EXPECT_NEAR(m["comparison"]["ate_rmse_reduction_pct"].as<double>(), expected, 1e-6);
  EXPECT_TRUE(m["comparison"]["rpe_trans_rmse_reduction_pct"].IsScalar());

  const std::string table = comparison_table(r);
  EXPECT_NE(table.find("[1] baseline"), std::string::npos) << table;
  EXPECT_EQ(table.find("ORB-SLAM2"), std::string::npos) << table;
  EXPECT_NE(table.find("PE-SLAM"), std::string::npos);
  EXPECT_NE(table.find("tracking ms median"), std::string::npos);
  EXPECT_NE(table.find("ATE rmse"), std::string::npos);
  EXPECT_LT(table.find("lost frames"), table.find("(percentages"));  // the footnote stays last
  EXPECT_TRUE(comparison_table(hand_report()).empty());
}

TEST(RunReport, UnevaluatedRunsAndStatuses) {
  RunReport r = hand_report();
  r.primary.eval.reset();
  r.primary.eval_note = "only 2 tracked frames (need 3)";
  r.status = RunStatus::kInterrupted;
  r.status_detail = "interrupted after 50 of 751 frames";
  r.closed_loop = ClosedLoopMetrics{{0, 1}, {0.01, 0.03}, 0.0224, 0.03, 4};
  const YAML::Node m = YAML::Load(metrics_json(r));
  EXPECT_TRUE(m["ate"].IsNull());
  EXPECT_TRUE(m["rpe"].IsNull());
  EXPECT_EQ(m["status"].as<std::string>(), "interrupted");
  EXPECT_EQ(m["eval_note"].as<std::string>(), "only 2 tracked frames (need 3)");
  EXPECT_NEAR(m["closed_loop"]["path_error_rmse_m"].as<double>(), 0.0224, 1e-12);
  EXPECT_NEAR(m["closed_loop"]["path_error_max_m"].as<double>(), 0.03, 1e-12);
  EXPECT_EQ(m["closed_loop"]["hold_frames"].as<int>(), 4);
  EXPECT_EQ(exit_code(RunStatus::kCompleted), 0);
  EXPECT_EQ(exit_code(RunStatus::kInterrupted), 130);
  EXPECT_EQ(exit_code(RunStatus::kAborted), 4);
  EXPECT_STREQ(to_string(RunStatus::kAborted), "aborted");
}

TEST(RunReport, DistanceToPolyline) {
  const std::vector<Eigen::Vector2d> line{{0, 0}, {2, 0}, {2, 2}};
  EXPECT_NEAR(distance_to_polyline({1, 0.5}, line), 0.5, 1e-12);
  EXPECT_NEAR(distance_to_polyline({3, 1}, line), 1.0, 1e-12);
  EXPECT_NEAR(distance_to_polyline({-3, 4}, line), 5.0, 1e-12);     // beyond the first end point
  EXPECT_NEAR(distance_to_polyline({1.5, 1.0}, line), 0.5, 1e-12);  // nearer the second segment
  EXPECT_NEAR(distance_to_polyline({1, 1}, {{0, 0}}), std::sqrt(2.0), 1e-12);
  EXPECT_TRUE(std::isinf(distance_to_polyline({1, 1}, {})));
}

TEST(RunReport, PercentileAndRealtimeFactor) {
  EXPECT_EQ(percentile({}, 0.5), 0.0);
  EXPECT_NEAR(percentile({4, 1, 3, 2}, 0.5), 2.5, 1e-12);
  EXPECT_NEAR(percentile({0, 10}, 0.95), 9.5, 1e-12);
  EXPECT_NEAR(realtime_factor(25, 20), 1.25, 1e-12);
  EXPECT_EQ(realtime_factor(25, 0), 0.0);
}

TEST(RunReport, IndexHtmlIsSelfContained) {
  RunReport r = hand_report();
  r.baseline = slam_run("baseline", 0.04);
  r.log_lines = {"frame 20 (t = 0.667 s): pe-slam lost tracking: <reason & more>"};
  const std::string html = index_html(r, {"trajectory_error", "matches"});
  EXPECT_NE(html.find("<img src=\"trajectory_error.png\""), std::string::npos);
  EXPECT_NE(html.find("href=\"matches.svg\""), std::string::npos);
  EXPECT_NE(html.find("contact_sheet.png"), std::string::npos);
  EXPECT_NE(html.find("href=\"metrics.json\""), std::string::npos);
  EXPECT_NE(html.find("&lt;reason &amp; more&gt;"), std::string::npos);  // log text is escaped
  EXPECT_NE(html.find("21 inliers"), std::string::npos);                 // the loss event and its reason
  EXPECT_NE(html.find("PE-SLAM against the baseline (ORB-SLAM2 motion model)"), std::string::npos);
  EXPECT_NE(html.find("PE-SLAM (compared with the baseline (ORB-SLAM2 motion model))"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find("src=\"/"), std::string::npos);  // relative links only
}

TEST(RunReport, LocalMappingLoopsAndRefinedAteInTheReport) {
  RunReport r = hand_report();
  EXPECT_FALSE(YAML::Load(metrics_json(r))["local_mapping"]);  // not known: no key, no row
  EXPECT_EQ(index_html(r, {}).find("local mapping"), std::string::npos);

  r.primary.local_mapping = slam::LocalMappingStats{41, 39, 5, 12345.0};
  const YAML::Node m = YAML::Load(metrics_json(r));
  ASSERT_TRUE(m["local_mapping"]);
  EXPECT_EQ(m["local_mapping"]["keyframes"].as<int>(), 41);
  EXPECT_EQ(m["local_mapping"]["local_ba"].as<int>(), 39);
  EXPECT_EQ(m["local_mapping"]["local_ba_stopped"].as<int>(), 5);
  EXPECT_NEAR(m["local_mapping"]["busy_ms"].as<double>(), 12345.0, 1e-6);
  const std::string html = index_html(r, {});
  EXPECT_NE(html.find("<th>local mapping</th><td>41 keyframes processed, 39 local BAs (5 stopped by a new "
                      "keyframe), 12.3 s busy</td>"),
            std::string::npos);
  EXPECT_EQ(html.find("loops closed"), std::string::npos);  // loop closing off

  r.primary.refined_eval = synthetic_eval(0.005);
  char refined[32];
  std::snprintf(refined, sizeof refined, "%.4f", r.primary.refined_eval->ate.rmse);
  EXPECT_NE(index_html(r, {}).find(std::string("<th>refined trajectory ATE rmse [m]</th><td>") + refined),
            std::string::npos);
  r.primary.loop_closing_json = "{\"loops\": 2}";
  r.primary.loops_closed = 2;
  EXPECT_NE(index_html(r, {}).find("<th>loops closed</th><td>2</td>"), std::string::npos);
}

TEST(RunReport, DenseMapInMetricsAndReport) {
  RunReport r = hand_report();
  EXPECT_FALSE(YAML::Load(metrics_json(r))["dense_map"]);  // dense mapping off
  EXPECT_EQ(index_html(r, {}).find("Dense map"), std::string::npos);

  DenseMapReport d;
  d.keyframes = 30;
  d.points = 1000;
  d.live_points = 1100;
  d.pose_updates = 30;
  d.keyframes_moved = 120;
  d.update_ms_median = 4.5;
  d.update_ms_max = 250;
  d.loop_update_ms = {250};
  d.files = {"PointCloud.ply", "PointCloud_live.ply", "PointCloud_before_loop.ply", "PointCloud_after_loop.ply"};
  d.note = "not scored (--no-map-eval)";
  r.primary.dense_map = d;
  YAML::Node m = YAML::Load(metrics_json(r));
  ASSERT_TRUE(m["dense_map"]);
  EXPECT_EQ(m["dense_map"]["keyframes_moved"].as<int>(), 120);
  EXPECT_NEAR(m["dense_map"]["loop_update_ms"][0].as<double>(), 250.0, 1e-9);
  EXPECT_EQ(m["dense_map"]["files"].size(), 4u);
  EXPECT_FALSE(m["dense_map"]["maps"]);
  EXPECT_NE(index_html(r, {}).find("Not scored: not scored (--no-map-eval)"), std::string::npos);

  // Scored: one map with two classes (ids as sim::SurfaceClass: 2 panel, 5 wall).
  eval::MapScores s;
  s.accuracy.median = 0.012;
  s.accuracy.count = 1000;
  s.completeness_at = {0.5, 0.8, 0.9, 0.95};
  s.fscore_at = {0.5, 0.8, 0.9, 0.95};
  s.ghosting = 0.001;
  MapResult corrected{"corrected", {}, 1.0};
  corrected.accuracy.all = s;
  corrected.accuracy.per_class = {{2, s}, {5, s}};
  r.primary.dense_map->maps = {corrected};
  r.primary.dense_map->note.clear();
  r.primary.dense_map->alignment = "first";
  r.primary.dense_map->top_view = "map_error_top.png";
  m = YAML::Load(metrics_json(r));
  EXPECT_NEAR(m["dense_map"]["maps"]["corrected"]["all"]["accuracy_m"]["median"].as<double>(), 0.012, 1e-12);
  EXPECT_TRUE(m["dense_map"]["maps"]["corrected"]["per_class"]["wall"]);
  const std::string html = index_html(r, {});
  EXPECT_NE(html.find("<tr><td>panel</td><td>1000</td><td>12.0 / "), std::string::npos) << html;
  EXPECT_NE(html.find("<img src=\"map_error_top.png\""), std::string::npos);
  EXPECT_NE(html.find("a loop correction reached the map in 250.0 ms"), std::string::npos);
}

TEST(RunReport, WriteReportWritesEveryFile) {
  const std::string dir = ::testing::TempDir() + "pvb_run_report_" + std::to_string(::getpid());
  std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str());
  RunReport r = hand_report();
  r.baseline = slam_run("baseline", 0.04);
  r.closed_loop = ClosedLoopMetrics{{0, 1}, {0.01, 0.03}, 0.0224, 0.03, 0};
  const std::vector<std::string> figures = write_report(r, dir);
  for (const char* f : {"trajectory_error", "trajectory_error_baseline", "ate_over_time",
                        "tracking_time_hist", "matches", "path_error"}) {
    EXPECT_NE(std::find(figures.begin(), figures.end(), f), figures.end()) << f;
    for (const char* ext : {".svg", ".png"})
      EXPECT_TRUE(std::ifstream(dir + "/" + f + ext).good()) << f << ext;
  }
  for (const char* f : {"metrics.json", "index.html", "contact_sheet.png"})
    EXPECT_TRUE(std::ifstream(dir + "/" + f).good()) << f;
  EXPECT_NO_THROW(YAML::Load(read_file(dir + "/metrics.json")));
}

TEST(Charts, HistogramCountsEqualBinsLastClosed) {
  const std::vector<std::size_t> c = eval::histogram_counts({0, 0.5, 1, 1.5, 2, 2, 5, -1}, 0, 2, 4);
  ASSERT_EQ(c.size(), 4u);
  EXPECT_EQ(c[0], 1u);  // 0              bins of width 0.5, closed on the left
  EXPECT_EQ(c[1], 1u);  // 0.5
  EXPECT_EQ(c[2], 1u);  // 1
  EXPECT_EQ(c[3], 3u);  // 1.5, 2, 2 (the last bin is closed); 5 and -1 are outside
}

TEST(Charts, LineChartBreaksAtNonFiniteValues) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  eval::Series s{"a", {0, 1, 2, 3, 4}, {1, 2, nan, 3, 4}, eval::series_color(0)};
  const eval::Figure f = eval::make_line_chart("t", "x", "y", {s});
  // Two pieces of the data line; the legend stroke (horizontal) aside.
  int pieces = 0;
  for (const auto& p : f.polylines) {
    const bool same_colour = p.color.r == s.color.r && p.color.g == s.color.g && p.color.b == s.color.b;
    const bool legend = p.points.size() == 2 && p.points[0].second == p.points[1].second;
    if (same_colour && !legend) ++pieces;
  }
  EXPECT_EQ(pieces, 2);
  EXPECT_NE(eval::format_svg(f).find("<polyline"), std::string::npos);
}

TEST(RunReport, PlaceRecognitionInMetricsAndReport) {
  RunReport r = hand_report();
  PlaceRecognition p;
  p.loops_proposed = 4;
  p.loops_accepted = 2;
  p.relocalisations = 1;
  r.camera_covered_frames = std::make_pair(30, 39);
  r.primary.place = p;
  YAML::Node m = YAML::Load(metrics_json(r));
  EXPECT_EQ(m["place_recognition"]["loops_proposed"].as<int>(), 4);
  EXPECT_FALSE(m["place_recognition"]["loops_false"].IsDefined());  // no labels without ground truth
  EXPECT_EQ(m["camera_covered_frames"][1].as<int>(), 39);

  eval::PlaceLabels labels;
  labels.loops_true = 1;
  labels.loops_false = 1;
  labels.relocalisations_true = 1;
  r.primary.place->labels = labels;
  m = YAML::Load(metrics_json(r));
  EXPECT_EQ(m["place_recognition"]["loops_false"].as<int>(), 1);
  EXPECT_EQ(m["place_recognition"]["relocalisations_true"].as<int>(), 1);
  EXPECT_TRUE(m["place_recognition"]["loop_events"].IsSequence());
  EXPECT_NE(index_html(r, {}).find("<th>loops true / false / missed</th><td>1 / 1 / 0"), std::string::npos);
}

// The cost samples go into metrics.json as rows under named columns, and
// into two figures against the map's keyframes.
TEST(RunReport, CostsAreRowsUnderTheirColumnsAndTwoFigures) {
  RunReport r = hand_report();
  r.primary.cost_every_frames = 300;
  for (int k = 1; k <= 3; ++k) {
    CostSample c;
    c.frame = 300 * k - 1;
    c.keyframes = static_cast<std::size_t>(40 * k);
    c.rss_mb = 300 + 10.0 * k;
    c.sparse_mb = 5.0 * k;
    c.loop_detect_ms = 1.5;
    c.local_ba_ms = 80.0 + k;
    r.primary.costs.push_back(c);
  }
  const YAML::Node m = YAML::Load(metrics_json(r))["costs"];
  EXPECT_EQ(m["every_frames"].as<int>(), 300);
  ASSERT_EQ(m["columns"].size(), cost_columns().size());
  ASSERT_EQ(m["rows"].size(), 3u);
  const auto column = [&](const std::string& name) {
    for (std::size_t i = 0; i < cost_columns().size(); ++i)
      if (cost_columns()[i] == name) return static_cast<int>(i);
    return -1;
  };
  EXPECT_EQ(m["columns"][column("keyframes")].as<std::string>(), "keyframes");
  EXPECT_EQ(m["rows"][2][column("keyframes")].as<int>(), 120);
  EXPECT_EQ(m["rows"][1][column("rss_mb")].as<double>(), 320.0);
  EXPECT_EQ(m["rows"][0][column("frame")].as<int>(), 299);
  EXPECT_EQ(m["rows"][0][column("loop_detect_ms")].as<double>(), 1.5);
  EXPECT_EQ(m["rows"][2][column("local_ba_ms")].as<double>(), 83.0);
  const std::string dir = ::testing::TempDir() + "/cost_figures";
  std::filesystem::create_directories(dir);
  const std::vector<std::string> written = write_figures(r, dir);
  for (const char* f : {"cost_memory", "cost_time"})
    EXPECT_NE(std::find(written.begin(), written.end(), f), written.end()) << f;
  r.primary.costs.resize(1);  // one sample draws no line
  const std::vector<std::string> one = write_figures(r, dir);
  EXPECT_EQ(std::find(one.begin(), one.end(), "cost_memory"), one.end());
}

TEST(RunReport, RefusedLoopsAreCountedByCheckAndTheVerifiedOnesJudged) {
  RunReport r = hand_report();
  PlaceRecognition p;
  p.refusals.push_back({{10'000'000'000, 1'000'000'000, geom::SE3d::Identity()}, "inliers", false, 0, 0, std::nullopt});
  p.refusals.push_back({{20'000'000'000, 2'000'000'000, geom::SE3d::Identity()}, "drift", true, 2.5, 1.9, std::nullopt});
  p.refusals.push_back({{30'000'000'000, 3'000'000'000, geom::SE3d::Identity()}, "drift", true, 6.0, 2.0, std::nullopt});
  p.refusals_dropped = 7;
  r.primary.place = p;
  YAML::Node m = YAML::Load(metrics_json(r))["place_recognition"];
  EXPECT_EQ(m["refusals"]["kept"].as<int>(), 3);
  EXPECT_EQ(m["refusals"]["dropped"].as<int>(), 7);
  EXPECT_EQ(m["refusals"]["by_reason"]["drift"].as<int>(), 2);
  EXPECT_EQ(m["refusals"]["by_reason"]["inliers"].as<int>(), 1);
  EXPECT_EQ(m["refusals"]["verified"].as<int>(), 2);
  EXPECT_TRUE(m["refusals"]["verified_true"].IsNull());  // no ground truth yet
  ASSERT_EQ(m["refusal_events"].size(), 3u);
  EXPECT_EQ(m["refusal_events"][1]["reason"].as<std::string>(), "drift");
  EXPECT_NEAR(m["refusal_events"][1]["drift_bound_m"].as<double>(), 1.9, 1e-9);
  EXPECT_TRUE(m["refusal_events"][1]["correct"].IsNull());

  // With ground truth: the first verified refusal was a true loop thrown away, the second a look-alike.
  eval::LabelledPlaceEvent right, wrong;
  right.event.T_q_r = wrong.event.T_q_r = geom::SE3d::Identity();
  right.judged = wrong.judged = true;
  right.correct = true;
  wrong.error_m = 4.1;
  r.primary.place->refusals[1].label = right;
  r.primary.place->refusals[2].label = wrong;
  m = YAML::Load(metrics_json(r))["place_recognition"];
  EXPECT_EQ(m["refusals"]["verified_true"].as<int>(), 1);
  EXPECT_TRUE(m["refusal_events"][0]["correct"].IsNull());  // refused before verification: not judged
  EXPECT_TRUE(m["refusal_events"][1]["correct"].as<bool>());
  EXPECT_FALSE(m["refusal_events"][2]["correct"].as<bool>());
  EXPECT_NEAR(m["refusal_events"][2]["error_m"].as<double>(), 4.1, 1e-9);
}

}  // namespace
}  // namespace pvb::run
