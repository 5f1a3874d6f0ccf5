// pvbench run, end to end: the default station in synchronous mode (metrics
// contract, report files, accuracy), bit-identical prefixes, replay of the
// recording, --compare, the closed loop, tracking loss with on_loss abort and
// wait, Ctrl-C, bad input.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>

#include "pvb/common/text.hpp"
#include "cli_output.hpp"
#include "run_pvbench.hpp"
#include "station_sequence.hpp"

using namespace pvb;

namespace {

const std::string kStation = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
const std::string kLossScenario =
    std::string(PVB_SOURCE_DIR) + "/tests/harness/run/data/turn_away_from_wall.yaml";

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_run_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + d).c_str());
  return d;
}

bool exists(const std::string& path) { return std::ifstream(path).good(); }

/// Writes the default station to `path` with its line `from` replaced by
/// `to`; false (nothing written) when the station has no such line.
bool write_station_with(const std::string& path, const std::string& from, const std::string& to) {
  std::string text = read_file(kStation);
  const std::size_t at = text.find(from);
  if (at == std::string::npos) return false;
  write_file(path, text.replace(at, from.size(), to));
  return true;
}

using pvb::test::data_lines;

/// The run's ground truth (`frames` poses) is the one `pvbench record`
/// writes for the station at its seed: the shared recording's first poses.
void expect_recorded_ground_truth(const std::string& run_dir, std::size_t frames) {
  const std::vector<std::string> rec_gt = data_lines(test::station_sequence() + "/groundtruth.txt");
  const std::vector<std::string> run_gt = data_lines(run_dir + "/groundtruth.txt");
  ASSERT_EQ(run_gt.size(), frames);
  ASSERT_GE(rec_gt.size(), frames);
  for (std::size_t i = 0; i < frames; ++i) EXPECT_EQ(rec_gt[i], run_gt[i]) << "frame " << i;
}

YAML::Node metrics(const std::string& dir) { return YAML::Load(read_file(dir + "/metrics.json")); }

void check_metrics_and_accuracy(const std::string& d) {
  const YAML::Node m = metrics(d);
  EXPECT_EQ(m["scenario"].as<std::string>(), "pv_station");
  EXPECT_EQ(m["seed"].as<int>(), 7);
  EXPECT_EQ(m["mode"].as<std::string>(), "pe-slam");
  EXPECT_EQ(m["status"].as<std::string>(), "completed");
  EXPECT_EQ(m["frames"].as<int>(), 150);
  EXPECT_EQ(m["lost_frames"].as<int>(), 0);
  EXPECT_EQ(m["loss_events"].size(), 0u);
  EXPECT_GT(m["keyframes"].as<int>(), 1);
  EXPECT_GT(m["map_points"].as<int>(), 500);
  EXPECT_EQ(m["ate"]["count"].as<int>(), 150);
  EXPECT_LT(m["ate"]["rmse"].as<double>(), 0.02);
  EXPECT_GT(m["ate"]["rmse"].as<double>(), 0.0);  // noisy sensor: never exactly zero
  EXPECT_LT(m["rpe"]["trans"]["rmse"].as<double>(), 0.01);
  EXPECT_GT(m["tracking_ms"]["median"].as<double>(), 0.0);
  EXPECT_GE(m["tracking_ms"]["p95"].as<double>(), m["tracking_ms"]["median"].as<double>());
  EXPECT_NEAR(m["sim_s"].as<double>(), 5.0, 1e-9);
  EXPECT_GT(m["cpu_s"].as<double>(), 0.0);
  EXPECT_NEAR(m["realtime_factor"].as<double>(), m["sim_s"].as<double>() / m["wall_s"].as<double>(), 1e-6);
  for (const char* stage : {"physics", "render", "sensor_model", "tracking", "mapping", "eval", "report"})
    EXPECT_TRUE(m["profile"][stage]) << stage;
  // Sync mode: the CPU cost of both halves, which add up to about the whole.
  const double sim_cpu_ms = m["profile"]["cpu_simulation"]["total_ms"].as<double>();
  const double slam_cpu_ms = m["profile"]["cpu_slam"]["total_ms"].as<double>();
  EXPECT_GT(sim_cpu_ms, 0.0);
  EXPECT_GT(slam_cpu_ms, 0.0);
  EXPECT_LE(sim_cpu_ms + slam_cpu_ms, 1000.0 * m["cpu_s"].as<double>() * 1.001 + 1.0);
  EXPECT_FALSE(m["closed_loop"]);
  EXPECT_FALSE(m["baseline"]);
}

// The dense maps: written, scored against the true surface, in the report.
void check_dense_map(const std::string& d) {
  const YAML::Node dm = metrics(d)["dense_map"];
  ASSERT_TRUE(dm);
  EXPECT_GT(dm["keyframes"].as<int>(), 1);
  EXPECT_GT(dm["points"].as<int>(), 10000);
  EXPECT_GT(dm["pose_updates"].as<int>(), 0);  // local BA moved keyframes and the map followed
  EXPECT_EQ(dm["alignment"].as<std::string>(), "first");
  EXPECT_GT(dm["surface_samples"].as<int>(), 10000);
  for (const char* name : {"corrected", "live"}) {
    const YAML::Node all = dm["maps"][name]["all"];
    ASSERT_TRUE(all) << name;
    // 150 frames, a few millimetres of drift: the Kinect model's noise (about
    // 1 cm at 3 m) dominates; a frame mix-up or a wrong alignment is metres off.
    EXPECT_LT(all["accuracy_m"]["median"].as<double>(), 0.02) << name;
    EXPECT_GT(all["accuracy_m"]["median"].as<double>(), 0.0) << name;
    EXPECT_GT(all["completeness_at"][2].as<double>(), 0.8) << name;
    EXPECT_LT(all["ghosting"].as<double>(), 0.01) << name;
  }
  EXPECT_TRUE(dm["maps"]["corrected"]["per_class"]["panel"]);
  EXPECT_TRUE(metrics(d)["profile"]["map_eval"]);
  for (const char* f : {"PointCloud.ply", "PointCloud_live.ply", "map_errors.ply", "map_error_top.png"})
    EXPECT_TRUE(exists(d + "/" + f)) << f;
  EXPECT_FALSE(exists(d + "/PointCloud_before_loop.ply"));  // no loop in 150 frames
  const std::string html = read_file(d + "/index.html");
  EXPECT_NE(html.find("<h2>Dense map</h2>"), std::string::npos);
  EXPECT_NE(html.find("map_error_top.png"), std::string::npos);
}

void check_report_files(const std::string& d) {
  EXPECT_EQ(data_lines(d + "/groundtruth.txt").size(), 150u);
  EXPECT_EQ(data_lines(d + "/CameraTrajectory.txt").size(), 150u);
  EXPECT_EQ(data_lines(d + "/timing.csv").size(), 151u);  // header + one line per frame
  {  // The local map the last frame was tracked against: keyframes and points, last two columns.
    const std::vector<std::string> timing = data_lines(d + "/timing.csv");
    const std::string& head = timing.front();
    const std::string tail = "local_keyframes,local_points";
    EXPECT_EQ(head.substr(head.size() - std::min(head.size(), tail.size())), tail) << head;
    const std::string& last = timing.back();
    const std::size_t comma = last.rfind(',');
    const int keyframes = std::stoi(last.substr(last.rfind(',', comma - 1) + 1));
    EXPECT_GT(keyframes, 1);
    EXPECT_GT(std::stoi(last.substr(comma + 1)), 10 * keyframes);  // tens of points a keyframe
  }
  // Costs every 300 frames and at the end: one sample of 150 frames.
  EXPECT_EQ(data_lines(d + "/costs.csv").size(), 2u);
  const YAML::Node costs = metrics(d)["costs"];
  ASSERT_EQ(costs["rows"].size(), 1u);
  EXPECT_EQ(costs["every_frames"].as<int>(), 300);
  EXPECT_EQ(costs["columns"][4].as<std::string>(), "rss_mb");
  EXPECT_EQ(costs["rows"][0][0].as<int>(), 149);
  for (int c : {2, 3, 4, 5, 7}) EXPECT_GT(costs["rows"][0][c].as<double>(), 0) << c;
  EXPECT_GT(costs["rows"][0][4].as<double>(), costs["rows"][0][5].as<double>());  // the process holds the map
  EXPECT_EQ(data_lines(d + "/KeyFrameTrajectory.txt").size(),
            static_cast<std::size_t>(metrics(d)["keyframes"].as<int>()));
  for (const char* f : {"run.log", "index.html", "contact_sheet.png", "camera.yaml", "trajectory_error.svg",
                        "trajectory_error.png", "ate_over_time.svg", "ate_over_time.png",
                        "tracking_time_hist.svg", "tracking_time_hist.png", "matches.svg", "matches.png"})
    EXPECT_TRUE(exists(d + "/" + f)) << f;
  const std::string html = read_file(d + "/index.html");
  EXPECT_NE(html.find("trajectory_error.png"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  // The ground truth is the simulator's: the same poses `pvbench record`
  // writes (the shared recording of the station at the same seed).
  expect_recorded_ground_truth(d, 150);
}

// Both systems on the same frames (--compare): the baseline named for what
// it is and never running PE-match, one ground truth for both.
void check_comparison(const std::string& d, const std::string& output) {
  EXPECT_NE(output.find("PE-SLAM"), std::string::npos) << output;
  // The baseline is named for what it is, never as the ORB-SLAM2 program.
  EXPECT_NE(output.find("PE-SLAM against the baseline (ORB-SLAM2 motion model) on the same frames:"),
            std::string::npos)
      << output;
  EXPECT_EQ(output.find("ORB-SLAM2 baseline"), std::string::npos) << output;
  const YAML::Node m = metrics(d);
  EXPECT_EQ(m["metrics_version"].as<int>(), 2);
  EXPECT_EQ(m["mode"].as<std::string>(), "pe-slam");
  ASSERT_TRUE(m["baseline"]);
  EXPECT_EQ(m["baseline"]["mode"].as<std::string>(), "baseline");
  EXPECT_TRUE(m["comparison"]["tracking_ms_median"]["baseline"].IsScalar());
  EXPECT_EQ(m["baseline"]["frames"].as<int>(), 40);
  EXPECT_LT(m["baseline"]["ate"]["rmse"].as<double>(), 0.02);
  EXPECT_TRUE(m["comparison"]["ate_rmse_reduction_pct"].IsScalar());
  EXPECT_EQ(data_lines(d + "/baseline/CameraTrajectory.txt").size(), 40u);
  // Both saw the same frames: one ground truth for both.
  EXPECT_EQ(data_lines(d + "/groundtruth.txt").size(), 40u);
  // The baseline never runs PE-match.
  for (const std::string& line : data_lines(d + "/baseline/timing.csv")) {
    const std::vector<std::string> f = split_ws(line, ",");
    if (f[0] == "frame") continue;
    EXPECT_EQ(f[8], f[9]) << line;  // coarse == kept
  }
}

// Sync mode is bit-identical, and a shorter run is a prefix of a longer one
// (nothing depends on frames not yet seen); running the baseline beside it
// (--compare, which renders once for both) changes nothing of PE-SLAM's.
void check_bit_identical_prefix(const std::string& d) {
  const std::string s = fresh("short");
  const test::RunResult r =
      test::run_pvbench("run --scenario " + kStation + " --out " + s + " --sync --frames 40 --compare");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::vector<std::string> a = data_lines(d + "/CameraTrajectory.txt"),
                                 b = data_lines(s + "/CameraTrajectory.txt");
  ASSERT_EQ(b.size(), 40u);
  for (std::size_t i = 0; i < b.size(); ++i) EXPECT_EQ(a[i], b[i]) << "frame " << i;
  SCOPED_TRACE("the comparison beside it");
  check_comparison(s, r.output);
}

// A recording replays what the live run saw: `pvbench slam` on `pvbench
// record`'s folder (the shared recording, its first 40 frames) gives the
// live run's trajectory bit for bit (the sensor model emits depth on the
// PNG grid; settings travel through camera.yaml), with no --seed: PE-match
// takes the recording's own seed from its meta.json.
void check_replay_of_recording(const std::string& d) {
  const std::string& rec = test::station_sequence();
  const std::string out = fresh("replay_slam");
  const test::RunResult r = test::run_pvbench("slam --sequence " + rec + " --settings " + rec +
                                              "/camera.yaml --out " + out + " --sync --no-dense --max-frames 40");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("PE-match seed 7 (" + rec + "/meta.json)\n"), std::string::npos) << r.output;
  EXPECT_EQ(test::json_number(read_file(out + "/stats.json"), "seed"), 7.0);
  const std::vector<std::string> live = data_lines(d + "/CameraTrajectory.txt"),
                                 replay = data_lines(out + "/CameraTrajectory.txt");
  ASSERT_EQ(replay.size(), 40u);
  for (std::size_t i = 0; i < replay.size(); ++i) EXPECT_EQ(live[i], replay[i]) << "frame " << i;
}

// One 150-frame synchronous run of the default station, the fast CI set's
// (the shared output that scenario_ci.pv_station judges by the scenario's
// bounds; ctest runs every test in its own process, so the checks share
// this test).
TEST(RunCli, DefaultStationSync) {
  static_assert(test::kStationRunFrames == 150, "the checks below count 150 frames");
  const std::string d = test::station_ci_run();
  ASSERT_TRUE(exists(d + "/metrics.json")) << d;
  {
    SCOPED_TRACE("metrics and accuracy");
    check_metrics_and_accuracy(d);
  }
  {
    SCOPED_TRACE("report files");
    check_report_files(d);
  }
  {
    SCOPED_TRACE("dense map");
    check_dense_map(d);
  }
  {
    SCOPED_TRACE("bit-identical prefix, beside the baseline");
    check_bit_identical_prefix(d);
  }
  {
    SCOPED_TRACE("replay of the recording");
    check_replay_of_recording(d);
  }
}

TEST(RunCli, BaselineAloneIsOrbSlam2WithoutPeMatch) {
  const std::string d = fresh("baseline");
  const test::RunResult r =
      test::run_pvbench("run --scenario " + kStation + " --out " + d + " --sync --frames 10 --baseline");
  ASSERT_EQ(r.code, 0) << r.output;
  const YAML::Node m = metrics(d);
  EXPECT_EQ(m["mode"].as<std::string>(), "baseline");
  EXPECT_FALSE(m["baseline"]);
  EXPECT_FALSE(m["comparison"]);
  int motion_frames = 0;
  for (const std::string& line : data_lines(d + "/timing.csv")) {
    const std::vector<std::string> f = split_ws(line, ",");
    if (f[0] == "frame") continue;
    EXPECT_EQ(f[7], "0") << line;   // no PE-match time
    EXPECT_EQ(f[8], f[9]) << line;  // coarse == kept
    ASSERT_EQ(f.size(), 17u) << line;
    EXPECT_LE(std::stoi(f[13]), std::stoi(f[4])) << line;  // keypoints with depth <= keypoints
    EXPECT_GT(std::stod(f[14]), 0.3) << line;              // the station's depth covers most pixels
    EXPECT_LE(std::stod(f[14]), 1.0) << line;
    motion_frames += f[3] == "motion";
  }
  EXPECT_GT(motion_frames, 5);
}

TEST(RunCli, ClosedLoopFollowsTheRouteFromTheSlamPose) {
  const std::string d = fresh("closed");
  const test::RunResult r =
      test::run_pvbench("run --scenario " + kStation + " --out " + d + " --sync --frames 90 --closed-loop");
  ASSERT_EQ(r.code, 0) << r.output;
  const YAML::Node m = metrics(d);
  ASSERT_TRUE(m["closed_loop"]);
  EXPECT_EQ(m["closed_loop"]["hold_frames"].as<int>(), 0);
  EXPECT_LT(m["closed_loop"]["path_error_max_m"].as<double>(), 0.10);
  EXPECT_LE(m["closed_loop"]["path_error_rmse_m"].as<double>(),
            m["closed_loop"]["path_error_max_m"].as<double>());
  EXPECT_LT(m["ate"]["rmse"].as<double>(), 0.02);
  EXPECT_TRUE(exists(d + "/path_error.png"));
  // The robot moved: it was steered, not held.
  const std::vector<std::string> gt = data_lines(d + "/groundtruth.txt");
  ASSERT_EQ(gt.size(), 90u);
  const std::vector<std::string> a = split_ws(gt.front()), b = split_ws(gt.back());
  EXPECT_GT(std::hypot(std::stod(b[1]) - std::stod(a[1]), std::stod(b[2]) - std::stod(a[2])), 0.9);
}

// The fixture loses tracking for good when the robot turns away from the wall.
TEST(RunCli, ClosedLoopAbortsOnLossWithAReport) {
  const std::string d = fresh("abort");
  const test::RunResult r =
      test::run_pvbench("run --scenario " + kLossScenario + " --out " + d + " --sync --closed-loop");
  EXPECT_EQ(r.code, 4) << r.output;
  const YAML::Node m = metrics(d);
  EXPECT_EQ(m["status"].as<std::string>(), "aborted");
  ASSERT_EQ(m["loss_events"].size(), 1u);
  const int frame = m["loss_events"][0]["frame"].as<int>();
  EXPECT_GT(frame, 30);
  EXPECT_EQ(m["frames"].as<int>(), frame + 1);  // stopped at the loss
  const std::string reason = m["loss_events"][0]["reason"].as<std::string>();
  EXPECT_NE(reason.find("need"), std::string::npos) << reason;
  EXPECT_NE(r.output.find("lost tracking: " + reason), std::string::npos) << r.output;
  EXPECT_NE(read_file(d + "/index.html").find(reason), std::string::npos);
}

TEST(RunCli, ClosedLoopWaitsOnLossHoldingTheRobot) {
  const std::string d = fresh("wait");
  const std::string scenario = ::testing::TempDir() + "pvb_run_wait_" + std::to_string(::getpid()) + ".yaml";
  std::string text = read_file(kLossScenario);
  const std::size_t at = text.find("on_loss: abort");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 14, "on_loss: wait");
  write_file(scenario, text);
  const test::RunResult r =
      test::run_pvbench("run --scenario " + scenario + " --out " + d + " --sync --closed-loop --frames 105");
  EXPECT_EQ(r.code, 0) << r.output;
  const YAML::Node m = metrics(d);
  EXPECT_EQ(m["status"].as<std::string>(), "completed");
  EXPECT_EQ(m["frames"].as<int>(), 105);
  ASSERT_GE(m["loss_events"].size(), 1u);
  EXPECT_GT(m["lost_frames"].as<int>(), 0);
  // Held while lost (and the robot stands: the last ground-truth poses agree).
  EXPECT_GE(m["closed_loop"]["hold_frames"].as<int>(), m["lost_frames"].as<int>());
  const std::vector<std::string> gt = data_lines(d + "/groundtruth.txt");
  const std::vector<std::string> a = split_ws(gt[gt.size() - 5]), b = split_ws(gt.back());
  if (m["loss_events"][m["loss_events"].size() - 1]["recovered_frame"].IsNull()) {
    EXPECT_LT(std::hypot(std::stod(b[1]) - std::stod(a[1]), std::stod(b[2]) - std::stod(a[2])), 0.01);
  }
  // run.log explains the lost frames after the loss: why relocalisation
  // failed on each, and a summary of the stretch.
  const std::string log = read_file(d + "/run.log");
  const int lost_at = m["loss_events"][0]["frame"].as<int>();
  const std::size_t attempt = log.find("pe-slam still lost");
  ASSERT_NE(attempt, std::string::npos) << log;
  const std::string attempt_line = log.substr(attempt, log.find('\n', attempt) - attempt);
  EXPECT_NE(attempt_line.find(": relocalisation: "), std::string::npos) << attempt_line;
  const std::size_t summary = log.find("frames " + std::to_string(lost_at) + "-");
  ASSERT_NE(summary, std::string::npos) << log;
  const std::string line = log.substr(summary, log.find('\n', summary) - summary);
  EXPECT_NE(line.find("relocalisation attempts failed ("), std::string::npos) << line;
}

// The pipelined run (the default): render thread, sensor-model thread and
// tracking, each with its CPU time in the profile; frames paced at the
// camera rate; mapping at a lower priority; the same ground truth as the
// simulator gives `pvbench record`.
TEST(RunCli, PipelinedRunProfilesEachThread) {
  const std::string d = fresh("pipelined");
  const test::RunResult r = test::run_pvbench("run --scenario " + kStation + " --out " + d + " --frames 45");
  ASSERT_EQ(r.code, 0) << r.output;
  const YAML::Node m = metrics(d);
  EXPECT_EQ(m["status"].as<std::string>(), "completed");
  EXPECT_FALSE(m["sync"].as<bool>());
  EXPECT_EQ(m["frames"].as<int>(), 45);
  EXPECT_EQ(m["lost_frames"].as<int>(), 0);
  const YAML::Node p = m["profile"];
  for (const char* stage :
       {"render", "sensor_model", "tracking", "producer_wait", "sensor_wait", "consumer_wait"})
    EXPECT_TRUE(p[stage]) << stage;
  double thread_sum_ms = 0;
  for (const auto& kv : p) {
    const std::string name = kv.first.as<std::string>();
    if (name.rfind("cpu_thread_", 0) == 0) thread_sum_ms += kv.second["total_ms"].as<double>();
  }
  for (const char* thread : {"cpu_thread_pvb-render", "cpu_thread_pvb-sensor", "cpu_thread_pvbench"}) {
    ASSERT_TRUE(p[thread]) << thread;
    EXPECT_GT(p[thread]["total_ms"].as<double>(), 0.0) << thread;
  }
  EXPECT_TRUE(p["cpu_thread_pvb-mapping"]);
  // The threads' times are parts of the process's over the loop.
  EXPECT_LE(thread_sum_ms, 1000.0 * m["cpu_s"].as<double>() * 1.02 + 20.0);
  EXPECT_GT(thread_sum_ms, 0.5 * 1000.0 * m["cpu_s"].as<double>());
  const std::string log = read_file(d + "/run.log");
  EXPECT_NE(log.find("mapping workers: 2 at nice 10"), std::string::npos) << log;  // local and dense
  EXPECT_NE(log.find("frames paced at 30 Hz"), std::string::npos) << log;
  // Paced: a frame is tracked after it is due, never before.
  ASSERT_TRUE(p["frame_latency"]);
  EXPECT_GT(p["frame_latency"]["per_frame_ms"].as<double>(), 0.0);
  EXPECT_GE(p["frame_latency_max"]["total_ms"].as<double>(), p["frame_latency"]["per_frame_ms"].as<double>());
  // Frame 44 is due 44 / 30 s after frame 0: a paced loop cannot be faster.
  EXPECT_GE(m["wall_s"].as<double>(), 44.0 / 30.0);
  expect_recorded_ground_truth(d, 45);
}

// Ctrl-C: a child `pvbench run` (pipelined) gets SIGINT once it has
// tracked some frames; it must exit 130 with a partial report.
TEST(RunCli, SigintWritesThePartialReport) {
  const std::string d = fresh("sigint");
  const std::string log = ::testing::TempDir() + "pvb_run_sigint_" + std::to_string(::getpid()) + ".txt";
  const pid_t pid = test::spawn_pvbench({"run", "--scenario", kStation, "--out", d}, log);
  ASSERT_GE(pid, 0);
  // Wait for 20 tracked frames (the trajectory is flushed as it grows).
  ASSERT_TRUE(test::wait_until(pid, [&] { return data_lines(d + "/CameraTrajectory.txt").size() >= 20; }, 300))
      << "pvbench ended early or tracked nothing: " << read_file(log);
  const std::optional<int> ended = test::interrupt_and_wait(pid, 120);
  ASSERT_TRUE(ended.has_value()) << "pvbench did not stop within 120 s of SIGINT";
  const int status = *ended;
  ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal: " << read_file(log);
  EXPECT_EQ(WEXITSTATUS(status), 130) << read_file(log);
  const YAML::Node m = metrics(d);
  EXPECT_EQ(m["status"].as<std::string>(), "interrupted");
  const int frames = m["frames"].as<int>();
  EXPECT_GE(frames, 20);
  EXPECT_LT(frames, 751);
  EXPECT_EQ(data_lines(d + "/groundtruth.txt").size(), static_cast<std::size_t>(frames));
  EXPECT_TRUE(m["ate"].IsMap());  // the partial trajectory is evaluated
  EXPECT_TRUE(exists(d + "/index.html"));
  EXPECT_NE(read_file(d + "/run.log").find("interrupted"), std::string::npos);
}

// Ctrl-C once the frames are done and the map is being saved: the save
// finishes (the map is whole), and the run still ends as interrupted.
TEST(RunCli, SigintWhileTheMapIsSavedEndsInterruptedWithAWholeMap) {
  const std::string d = fresh("sigint_save");
  const std::string map = d + "_map.pvbmap";
  std::remove(map.c_str());
  const std::string log = ::testing::TempDir() + "pvb_run_sigint_save_" + std::to_string(::getpid()) + ".txt";
  const pid_t pid = test::spawn_pvbench(
      {"run", "--scenario", kStation, "--out", d, "--frames", "40", "--sync", "--save-map", map}, log);
  ASSERT_GE(pid, 0);
  ASSERT_TRUE(test::wait_until(
      pid, [&] { return exists(log) && read_file(log).find("saving the map to") != std::string::npos; }, 300))
      << read_file(log);
  const std::optional<int> ended = test::interrupt_and_wait(pid, 120);
  ASSERT_TRUE(ended.has_value() && WIFEXITED(*ended)) << read_file(log);
  EXPECT_EQ(WEXITSTATUS(*ended), 130) << read_file(log);
  EXPECT_EQ(metrics(d)["status"].as<std::string>(), "interrupted");
  // The map is whole: pvbench slam loads it to localise in (on the shared
  // recording of the same station: no scene to build for two frames).
  const std::string& rec = test::station_sequence();
  const test::RunResult again =
      test::run_pvbench("slam --sequence " + rec + " --settings " + rec + "/camera.yaml --out " + d +
                        "_again --max-frames 2 --sync --no-dense --map " + map + " --map-mode localise");
  EXPECT_EQ(again.code, 0) << again.output;
  EXPECT_NE(again.output.find(map), std::string::npos) << again.output;
}

// Two runs into one folder at once: the second is refused while the first
// holds it, and the first's report is its own.
TEST(RunCli, ASecondRunIntoAFolderInUseIsRefused) {
  const std::string d = fresh("busy");
  const std::string log = ::testing::TempDir() + "pvb_run_busy_" + std::to_string(::getpid()) + ".txt";
  const pid_t pid = test::spawn_pvbench({"run", "--scenario", kStation, "--out", d, "--overwrite"}, log);
  ASSERT_GE(pid, 0);
  ASSERT_TRUE(test::wait_until(
      pid, [&] { return data_lines(d + "/CameraTrajectory.txt").size() >= 5; }, 300))
      << read_file(log);
  const test::RunResult second =
      test::run_pvbench("run --scenario " + kStation + " --out " + d + " --overwrite --frames 2 --sync");
  EXPECT_EQ(second.code, 1) << second.output;
  EXPECT_NE(second.output.find(d + ": another pvbench process is writing this output folder now"),
            std::string::npos)
      << second.output;
  const std::optional<int> ended = test::interrupt_and_wait(pid, 120);
  ASSERT_TRUE(ended.has_value() && WIFEXITED(*ended)) << read_file(log);
  EXPECT_EQ(WEXITSTATUS(*ended), 130);
  EXPECT_GE(metrics(d)["frames"].as<int>(), 5);  // the first run's own metrics, not the second's 2 frames
}

// SLAM that never initialises (a depth range that nothing on the station
// lies in: no keypoint has depth, so neither one frame nor two views can
// start): the report is written and the run fails, exit 1, with no map.
TEST(RunCli, ARunThatNeverInitialisesFailsAndSavesNoMap) {
  const std::string d = fresh("noinit");
  const std::string scenario = d + "_small.yaml";
  ASSERT_TRUE(write_station_with(scenario, "  depth_range_m: [0.5, 4.5]\n", "  depth_range_m: [0.5, 0.6]\n"));
  const std::string map = d + "_map.pvbmap";
  std::remove(map.c_str());
  const test::RunResult r = test::run_pvbench("run --scenario " + scenario + " --out " + d +
                                              " --frames 5 --sync --no-map-eval --save-map " + map);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("pvbench: error: " + scenario + ": tracking never initialised in 5 frames ("),
            std::string::npos)
      << r.output;
  EXPECT_EQ(metrics(d)["status"].as<std::string>(), "failed");
  EXPECT_TRUE(exists(d + "/index.html"));
  EXPECT_FALSE(exists(map));
}

// The disk under the keyframe feature file fills mid-run (every file the
// run writes capped at 32 MiB, below the file's first 64 MB chunk): one
// error line, exit 1, the report written with the run failed and the
// frames tracked until then, and no map saved.
TEST(RunCli, AFeatureFileThatCannotGrowFailsTheRunWithItsReport) {
  const std::string d = fresh("fullspill");
  const std::string map = d + "_map.pvbmap";
  std::remove(map.c_str());
  const test::RunResult r = test::run_pvbench_with_file_limit(
      "run --scenario " + kStation + " --out " + d + " --frames 200 --sync --no-map-eval --save-map " + map, 32768);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("pvbench: error: " + kStation + ": pe-slam stopped after "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("cannot grow the keyframe feature file by 64 MB"), std::string::npos) << r.output;
  EXPECT_EQ(metrics(d)["status"].as<std::string>(), "failed");
  EXPECT_TRUE(exists(d + "/index.html"));
  EXPECT_GE(data_lines(d + "/CameraTrajectory.txt").size(), 20u);  // what was tracked is kept
  EXPECT_LT(metrics(d)["frames"].as<int>(), 200);
  EXPECT_FALSE(exists(map));
}

// The default station's Kinect in the sun: depth on a few keypoints per
// frame, far from the 500 a one-frame start needs; the core starts from
// two views, scaled by those few, and tracks on without a loss.
TEST(RunCli, AKinectInTheSunStartsFromTwoViews) {
  const std::string d = fresh("sun");
  const std::string scenario = d + "_sun.yaml";
  ASSERT_TRUE(write_station_with(scenario, "    sunlight: off\n", "    sunlight: on\n"));
  const test::RunResult r =
      test::run_pvbench("run --scenario " + scenario + " --out " + d + " --frames 60 --sync --no-map-eval");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("only "), std::string::npos) << r.output;  // too little depth for one frame
  EXPECT_NE(r.output.find("initialised from two views ("), std::string::npos) << r.output;
  const YAML::Node m = metrics(d);
  EXPECT_LT(m["not_initialized_frames"].as<int>(), 30);
  EXPECT_EQ(m["lost_frames"].as<int>(), 0);
  EXPECT_LT(m["ate"]["rmse"].as<double>(), 0.02);  // tracking that works: the 2 cm tier (docs/scenarios.md)
}

// A cover on the default station: the run goes through it whatever the
// SLAM core does while blind, and its blind object says what the files
// say (the covered frames with a pose, the first frame after the cover and
// its tracking as timing.csv has them); the robot drives on meanwhile.
TEST(RunCli, ACoverIsDrivenThroughAndReportedAsABlindStretch) {
  const std::string d = fresh("cover");
  const std::string scenario = d + "_cover.yaml";
  write_file(scenario, read_file(kStation) + "cover: {at_s: 2, covered_s: 0.5}\n");
  const test::RunResult r =
      test::run_pvbench("run --scenario " + scenario + " --out " + d + " --frames 90 --sync --no-map-eval");
  ASSERT_EQ(r.code, 0) << r.output;
  const YAML::Node m = metrics(d);
  EXPECT_EQ(m["status"].as<std::string>(), "completed");
  EXPECT_EQ(m["camera_covered_frames"][0].as<int>(), 60);
  EXPECT_EQ(m["camera_covered_frames"][1].as<int>(), 74);
  const YAML::Node b = m["blind"];
  ASSERT_TRUE(b.IsMap()) << read_file(d + "/metrics.json");
  EXPECT_EQ(b["covered_frames"][0].as<int>(), 60);
  EXPECT_EQ(b["covered_frames"][1].as<int>(), 74);
  EXPECT_EQ(b["covered_frames_processed"].as<int>(), 15);
  EXPECT_EQ(b["first_after_frame"].as<int>(), 75);
  // timing.csv: frame,t_s,state,method,...; CameraTrajectory.txt: one line a pose.
  const std::vector<std::string> timing = data_lines(d + "/timing.csv");
  ASSERT_EQ(timing.size(), 91u);  // the header and 90 frames
  std::set<std::string> posed_times;
  for (const std::string& line : data_lines(d + "/CameraTrajectory.txt"))
    posed_times.insert(split_ws(line)[0]);
  int covered_with_pose = 0;
  for (int i = 60; i <= 74; ++i)
    covered_with_pose += posed_times.count(split_ws(timing[static_cast<std::size_t>(i) + 1])[1]) > 0 ? 1 : 0;
  EXPECT_EQ(b["covered_frames_with_pose"].as<int>(), covered_with_pose);
  const std::vector<std::string> after = split_ws(timing[76]);
  ASSERT_EQ(after[0], "75");
  EXPECT_EQ(b["first_after_state"].as<std::string>(), after[2]);
  EXPECT_EQ(b["first_after_method"].as<std::string>(), after[3]);
  EXPECT_EQ(b["first_after_tracked"].as<bool>(), posed_times.count(after[1]) > 0);
  EXPECT_EQ(b["first_after_error"].IsNull(), !b["first_after_tracked"].as<bool>());
  EXPECT_NE(r.output.find("blind stretch (frames 60-74): "), std::string::npos) << r.output;
  EXPECT_NE(read_file(d + "/index.html").find("<h2>Blind stretch</h2>"), std::string::npos);
  // The robot drove on: 0.45 m/s over the half second of the cover.
  const std::vector<std::string> gt = data_lines(d + "/groundtruth.txt");
  const std::vector<std::string> g0 = split_ws(gt[59]), g1 = split_ws(gt[75]);
  EXPECT_GT(std::hypot(std::stod(g1[1]) - std::stod(g0[1]), std::stod(g1[2]) - std::stod(g0[2])), 0.15);
}

TEST(RunCli, BadInputIsOneClearError) {
  const std::string d = fresh("bad");
  test::RunResult r = test::run_pvbench("run --scenario /nonexistent/scene.yaml --out " + d);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("pvbench: error: /nonexistent/scene.yaml"), std::string::npos) << r.output;
  r = test::run_pvbench("run --scenario " + kStation + " --out " + d + " --compare --baseline");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("pvbench: error:"), std::string::npos) << r.output;
  // A count that is not a positive whole number is one line and exit 1
  // (CLI11's own check printed a 309-digit range and exited 105).
  for (const char* frames : {"0", "-3", "1e3", "x"}) {
    r = test::run_pvbench("run --scenario " + kStation + " --out " + d + " --frames " + frames);
    EXPECT_EQ(r.code, 1) << frames << ": " << r.output;
    EXPECT_EQ(r.output, std::string("pvbench: error: pvbench run: --frames: expected a whole number in [1, ") +
                            "10000000], got " + frames + "\n")
        << r.output;
  }
}

}  // namespace
