// pvbench record, end to end: the acceptance run (the shared 300 frames of the
// default station), byte-identical output, depth/pose consistency, errors.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <regex>

#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/trajectory.hpp"
#include "run_pvbench.hpp"
#include "station_sequence.hpp"

using namespace pvb;

namespace {

const std::string kBin = std::string(PVB_BINARY_DIR) + "/bin/pvbench";
const std::string kStation = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";

using Result = pvb::test::RunResult;
Result run(const std::string& args) { return pvb::test::run_pvbench(args); }

// ctest runs each test in its own process, possibly in parallel: folders
// carry the process id.
std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_rec_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + d).c_str());
  return d;
}

// All files below dir, relative paths, sorted.
std::vector<std::string> list_files(const std::string& dir) {
  const std::string list = ::testing::TempDir() + "pvb_list_" + std::to_string(::getpid()) + ".txt";
  std::system(("cd " + dir + " && find . -type f | sort > " + list).c_str());
  std::vector<std::string> out;
  std::ifstream in(list);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

// Lines of a TUM list that are not comments.
std::size_t data_lines(const std::string& path) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string l; std::getline(in, l);) n += !l.empty() && l[0] != '#';
  return n;
}

// The acceptance sequence: the default station's shared recording (300
// frames at seed 7, made once per build; station_sequence.hpp).
const std::string& station_run() { return pvb::test::station_sequence(); }
constexpr std::size_t kStationFrames = pvb::test::kStationFrames;

}  // namespace

TEST(RecordCli, WritesAConsistentTumSequence) {
  const std::string& d = station_run();
  for (const char* f : {"rgb.txt", "depth.txt", "groundtruth.txt", "associations.txt", "camera.yaml",
                        "scene.xml", "meta.json", "textures/brick.png"})
    EXPECT_EQ(::access((d + "/" + f).c_str(), R_OK), 0) << f;
  const auto rgb = dataset::read_tum_list(d + "/rgb.txt");
  ASSERT_EQ(rgb.size(), kStationFrames);
  // exactly 1/30 s apart (TUM text keeps microseconds)
  for (std::size_t i = 0; i < rgb.size(); ++i)
    EXPECT_NEAR(static_cast<double>(rgb[i].first), i * 1e9 / 30.0, 500.0) << i;
  const eval::Trajectory gt_traj = eval::read_tum(d + "/groundtruth.txt");
  ASSERT_EQ(gt_traj.size(), kStationFrames);
  // the robot moves: about 0.45 m/s x 4 s over the first 120 frames
  const double moved =
      (gt_traj.poses[119].T_w_c.translation() - gt_traj.poses.front().T_w_c.translation()).norm();
  EXPECT_GT(moved, 1.0);
  EXPECT_LT(moved, 2.5);
  std::string depth_name = rgb[5].second;
  depth_name.replace(0, 3, "depth");
  const cv::Mat d16 = cv::imread(d + "/" + depth_name, cv::IMREAD_ANYDEPTH);
  EXPECT_EQ(d16.type(), CV_16UC1);

  // Depth and ground-truth poses agree: warp frame i into frame i+5 with
  // depth, pose and intrinsics; the predicted depth must match the depth
  // observed there within 1 % (median).
  dataset::TumSequenceReader seq(d);
  const eval::Trajectory gt = eval::read_tum(d + "/groundtruth.txt");
  cv::FileStorage fs(d + "/camera.yaml", cv::FileStorage::READ);
  const double fx = fs["Camera.fx"], fy = fs["Camera.fy"], cx = fs["Camera.cx"], cy = fs["Camera.cy"];
  for (std::size_t i : {0u, 40u, 100u}) {
    const sensor::RgbdFrame a = seq.load(i), b = seq.load(i + 5);
    const geom::SE3d T_b_a = gt.poses[i + 5].T_w_c.inverse() * gt.poses[i].T_w_c;
    std::vector<double> rel;
    for (int r = 0; r < a.depth_m.rows; r += 4)
      for (int c = 0; c < a.depth_m.cols; c += 4) {
        const double z = a.depth_m.at<float>(r, c);
        if (z <= 0) continue;
        const Eigen::Vector3d p_b = T_b_a * Eigen::Vector3d((c - cx) / fx * z, (r - cy) / fy * z, z);
        const int u = static_cast<int>(std::lround(fx * p_b.x() / p_b.z() + cx));
        const int v = static_cast<int>(std::lround(fy * p_b.y() / p_b.z() + cy));
        if (u < 0 || v < 0 || u >= b.depth_m.cols || v >= b.depth_m.rows) continue;
        const double zb = b.depth_m.at<float>(v, u);
        if (zb <= 0) continue;
        rel.push_back(std::abs(p_b.z() - zb) / zb);
      }
    ASSERT_GT(rel.size(), 5000u) << "frame " << i;
    std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
    EXPECT_LT(rel[rel.size() / 2], 0.01) << "frame " << i;
  }
}

// The motion files read back in a second tool: Python's csv and yaml
// modules (tests/harness/cli/read_motion_files.py checks layouts, periods,
// counts and plausible readings).
TEST(RecordCli, MotionFilesReadBackWithPythonsCsvAndYaml) {
  const std::string& d = station_run();
  const std::string log = ::testing::TempDir() + "pvb_py_" + std::to_string(::getpid()) + ".txt";
  const int status = std::system(("python3 " + std::string(PVB_SOURCE_DIR) +
                                  "/tests/harness/cli/read_motion_files.py " + d + " > " + log + " 2>&1").c_str());
  EXPECT_EQ(status, 0) << read_file(log);
  EXPECT_NE(read_file(log).find("all read back"), std::string::npos) << read_file(log);
}

// Live equals replay: a run sees the very IMU and encoder readings a
// recording of the same scenario holds, byte for byte (the shared run's
// 150 frames against the start of the shared 300-frame recording: the
// settings files the same, every reading list its first lines).
TEST(RecordCli, RunWritesTheMotionReadingsTheRecordingHolds) {
  const std::string& rec = station_run();
  const std::string& live = pvb::test::station_ci_run();
  for (const char* f : {"imu.yaml", "robot.yaml", "robot_truth.yaml"})
    EXPECT_TRUE(read_file(rec + "/" + f) == read_file(live + "/" + f)) << f << " differs";
  for (const char* f : {"imu0/data.csv", "imu0/truth.csv", "accelerometer.txt", "wheels.csv", "wheels_truth.csv",
                        "odom.txt"}) {
    const std::string r = read_file(rec + "/" + f), l = read_file(live + "/" + f);
    // Half the frames hold about half the readings: a list cut short would not.
    EXPECT_GT(data_lines(live + "/" + f), data_lines(rec + "/" + f) * 2 / 5) << f;
    EXPECT_TRUE(r.compare(0, l.size(), l) == 0) << f << " is not the start of the recording's";
  }
}

// The same scenario, seed and backend give the same files: a recording of
// the first 60 frames is the start of the shared 300-frame one, file for
// file (every image, the scene and the settings the same bytes, every
// per-frame list and motion file its first lines; meta.json the same but
// for the frame count and the measured timings; the contact sheet, frames
// spread over the whole recording, is made of those frames; .pvbench lists
// what was written).
TEST(RecordCli, SameScenarioSeedAndBackendGiveIdenticalFiles) {
  const std::string& a = station_run();
  const std::string b = fresh("station_b");
  constexpr std::size_t kFrames = 60;
  const Result r =
      run("record --scenario " + kStation + " --out " + b + " --frames " + std::to_string(kFrames) + " --seed 7");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::vector<std::string> files_a = list_files(a), files_b = list_files(b);
  std::size_t images = 0;
  for (const auto& f : files_b) {
    ASSERT_TRUE(std::binary_search(files_a.begin(), files_a.end(), f)) << f << " is not in the longer recording";
    images += f.rfind("./rgb/", 0) == 0 || f.rfind("./depth/", 0) == 0;
    if (f == "./meta.json" || f == "./contact_sheet.png" || f == "./.pvbench") continue;
    const std::string fa = read_file(a + "/" + f), fb = read_file(b + "/" + f);
    EXPECT_FALSE(fb.empty()) << f;
    EXPECT_TRUE(fa.compare(0, fb.size(), fb) == 0) << f << " is not the start of the longer recording's";
  }
  EXPECT_EQ(images, 2 * kFrames);
  for (const char* list : {"rgb.txt", "depth.txt", "groundtruth.txt", "associations.txt"})
    EXPECT_EQ(data_lines(b + "/" + list), kFrames) << list;
  // meta.json differs only in the frame count and its measured timings
  const auto same_part = [](const std::string& meta) {
    static const std::regex timings("\"timings\": \\{[^}]*\\}"), frames("\"frames\": [0-9]+");
    return std::regex_replace(std::regex_replace(meta, timings, ""), frames, "");
  };
  EXPECT_EQ(same_part(read_file(a + "/meta.json")), same_part(read_file(b + "/meta.json")));
}

TEST(RecordCli, BadScenarioGivesOneClearLine) {
  const std::string bad = ::testing::TempDir() + "pvb_bad_scenario_" + std::to_string(::getpid()) + ".yaml";
  write_file(bad, "route: {waypoints_m: [[0, 0], [5, 0]]}\ncamera:\n  fps: -30\n");
  const Result r = run("record --scenario " + bad + " --out " + fresh("bad") + " --frames 2");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(r.output.find(bad + ":3: camera.fps: expected a value in [1, 240], got -30"), std::string::npos)
      << r.output;
}

TEST(RecordCli, UnwritableOutputGivesOneClearLine) {
  const std::string file = ::testing::TempDir() + "pvb_plain_file_" + std::to_string(::getpid());
  write_file(file, "x");
  const Result r = run("record --scenario " + kStation + " --out " + file + "/seq --frames 2");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(r.output.find("pvbench: error: " + file + "/seq: cannot create folder"), std::string::npos)
      << r.output;
}

TEST(RecordCli, MissingScenarioFile) {
  const Result r = run("record --scenario /nonexistent.yaml --out " + fresh("missing"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("/nonexistent.yaml: cannot open for reading"), std::string::npos) << r.output;
}

namespace {

// Runs `pvbench ARGS` with the working directory `cwd`.
Result run_in(const std::string& cwd, const std::string& args) {
  const std::string log = ::testing::TempDir() + "pvb_rec_cwd_" + std::to_string(::getpid()) + ".txt";
  const int status = std::system(("cd " + cwd + " && " + kBin + " " + args + " > " + log + " 2>&1").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(log)};
}

}  // namespace

// A bad --frames is one line and exit 1, like any bad input (CLI11's own
// check printed a 309-digit range and exited 105).
TEST(RecordCli, FramesMustBeAWholeNumberAtLeastOne) {
  const std::string d = fresh("frames");
  for (const char* frames : {"0", "-3", "abc", "2.5"}) {
    const Result r = run("record --scenario " + kStation + " --out " + d + " --frames " + frames);
    EXPECT_EQ(r.code, 1) << frames << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(
        r.output.find(std::string("pvbench: error: pvbench record: --frames: expected a whole number in [1, "
                                  "1000000000], got ") +
                      frames),
        std::string::npos)
        << r.output;
  }
  EXPECT_NE(::access(d.c_str(), F_OK), 0) << "nothing is written for a bad option";
}

// Ctrl-C stops at the next frame: exit 130, one line saying so, meta.json
// marked interrupted with the frames written, and the lists hold those frames.
TEST(RecordCli, CtrlCStopsAtTheNextFrameAndWritesMeta) {
  const std::string d = fresh("sigint");
  const std::string log = ::testing::TempDir() + "pvb_rec_sigint_" + std::to_string(::getpid()) + ".txt";
  const pid_t pid =
      test::spawn_pvbench({"record", "--scenario", kStation, "--out", d, "--frames", "600"}, log);
  ASSERT_GE(pid, 0);
  ASSERT_TRUE(test::wait_until(
      pid, [&] { return data_lines(d + "/associations.txt") >= 3; }, 300))
      << "pvbench ended early or wrote nothing: " << read_file(log);
  const std::optional<int> ended = test::interrupt_and_wait(pid, 120);
  ASSERT_TRUE(ended.has_value()) << "pvbench did not stop within 120 s of SIGINT";
  ASSERT_TRUE(WIFEXITED(*ended)) << "killed by a signal: " << read_file(log);
  EXPECT_EQ(WEXITSTATUS(*ended), 130) << read_file(log);
  const std::string out = read_file(log);
  EXPECT_NE(out.find("record: stopped by a signal after "), std::string::npos) << out;

  const std::string meta = read_file(d + "/meta.json");
  EXPECT_NE(meta.find("\"interrupted\": true"), std::string::npos) << meta;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(meta, m, std::regex("\"frames\": ([0-9]+)"))) << meta;
  const std::size_t frames = std::stoul(m[1]);
  EXPECT_GE(frames, 3u);
  EXPECT_LT(frames, 600u);
  for (const char* list : {"rgb.txt", "depth.txt", "groundtruth.txt", "associations.txt"})
    EXPECT_EQ(data_lines(d + "/" + list), frames) << list;
  EXPECT_EQ(::access((d + "/contact_sheet.png").c_str(), R_OK), 0);
}

// A scenario within every key's range but far larger than the renderer
// draws (50 x 50 tables, 57 500 geoms) is refused at once with one line.
TEST(RecordCli, SceneLargerThanTheRendererDrawsIsOneClearLine) {
  const std::string bad = ::testing::TempDir() + "pvb_big_scenario_" + std::to_string(::getpid()) + ".yaml";
  write_file(bad, "route: {waypoints_m: [[0, 0], [5, 0]]}\npv_arrays:\n  - {rows: 50, tables_per_row: 50}\n");
  const Result r = run("record --scenario " + bad + " --out " + fresh("big") + " --frames 2");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(r.output.find("pvbench: error: " + bad + ":2: pv_arrays: expected at most 20000 geoms"),
            std::string::npos)
      << r.output;
}

// A scene at the size limit is drawn whole: MuJoCo says nothing (it warns
// when its visual scene is full and leaves geoms out), and no command leaves
// MuJoCo's MUJOCO_LOG.TXT in the working directory.
TEST(RecordCli, SceneAtTheSizeLimitRendersWholeAndLeavesNoMujocoLog) {
  const std::string cwd = fresh("limit_cwd");
  std::system(("mkdir -p " + cwd).c_str());
  write_file(cwd + "/limit.yaml",
             "route: {waypoints_m: [[-0.5, -3.1], [9.5, -2.95]]}\n"
             "pv_arrays:\n  - {origin_m: [-1.0, -1.2], rows: 10, tables_per_row: 10, panels_per_table: 30, "
             "panel_lines: 1}\n"  // 100 tables x 37 geoms
             "vegetation: {shrubs: 50, area_m: [-30, -30, 30, 30], keep_out_m: 0}\n");  // 100 geoms
  const Result r = run_in(cwd, "record --scenario limit.yaml --out seq --frames 1");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("MuJoCo"), std::string::npos) << r.output;
  EXPECT_NE(::access((cwd + "/MUJOCO_LOG.TXT").c_str(), F_OK), 0);
  EXPECT_EQ(data_lines(cwd + "/seq/rgb.txt"), 1u);
}

// A disk that fills up while the textures and images are written (every
// file capped at 64 KiB): one error naming the file, which is not left
// half-written, and the lists name no frame that is not whole.
TEST(RecordCli, FullDiskIsOneErrorNamingTheFileAndLeavesNoPartialFile) {
  const std::string d = fresh("full");
  const Result r =
      test::run_pvbench_with_file_limit("record --scenario " + kStation + " --out " + d + " --frames 3", 64);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  std::smatch m;
  ASSERT_TRUE(
      std::regex_search(r.output, m,
                        std::regex("pvbench: error: (" + d +
                                   "/[^:]+\\.png): (write failed: File too large|cannot write image)")))
      << r.output;
  EXPECT_NE(::access(m[1].str().c_str(), F_OK), 0) << "a partial file is left under its final name";
  EXPECT_EQ(data_lines(d + "/associations.txt"), 0u);
}

// record and run take 64-bit scenario seeds; "-1" is an error, not
// 18446744073709551615.
TEST(RecordCli, SeedMustBeAWholeNumberInRange) {
  for (const char* cmd : {"record", "run"}) {
    const Result r = run(std::string(cmd) + " --scenario " + kStation + " --out " + fresh("seed") +
                         " --frames 2 --seed=-1");
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_EQ(r.output, std::string("pvbench: error: pvbench ") + cmd +
                            ": --seed: expected a whole number in [0, 18446744073709551615], got -1\n");
  }
}

// A recording is never written into another one: the second run used to
// shrink rgb.txt and leave the first run's images orphaned.  --overwrite
// empties an earlier pvbench output first; a folder of anything else is
// never emptied.
TEST(RecordCli, ExistingOutputIsRefusedUnlessOverwriteEmptiesAnEarlierRecording) {
  const std::string& full = station_run();
  Result r = run("record --scenario " + kStation + " --out " + full + " --frames 5 --seed 7");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(r.output.find("pvbench: error: " + full + ": the output folder is not empty"), std::string::npos)
      << r.output;
  EXPECT_EQ(dataset::read_tum_list(full + "/rgb.txt").size(), kStationFrames);

  const std::string d = fresh("overwrite");
  ASSERT_EQ(run("record --scenario " + kStation + " --out " + d + " --frames 6").code, 0);
  r = run("record --scenario " + kStation + " --out " + d + " --frames 3 --overwrite");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(dataset::read_tum_list(d + "/rgb.txt").size(), 3u);
  std::size_t images = 0;
  for (const std::string& f : list_files(d)) images += f.rfind("./rgb/", 0) == 0 ? 1 : 0;
  EXPECT_EQ(images, 3u) << "images of the earlier recording are left behind";

  const std::string mine = fresh("not_ours");
  std::system(("mkdir -p " + mine).c_str());
  write_file(mine + "/notes.txt", "the user's\n");
  r = run("record --scenario " + kStation + " --out " + mine + " --frames 3 --overwrite");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("holds files pvbench did not write (1 entry: notes.txt, no .pvbench marker)"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(read_file(mine + "/notes.txt"), "the user's\n");
}

// The same station at two hours, side by side; the recording's meta.json
// says which world it was: both seeds, the sun, the trackers' angle.
TEST(RecordCli, DaysOfAStationAreRecordedWithTheirWorldAndShownSideBySide) {
  const std::string days = std::string(PVB_SOURCE_DIR) + "/scenes/days/";
  const std::string d = fresh("days");
  Result r = run("record --scenario " + days + "tracker_station_0800.yaml --out " + d + " --frames 2");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string meta = read_file(d + "/meta.json");
  EXPECT_NE(meta.find("\"station_seed\": 11, \"day_seed\": 10800"), std::string::npos) << meta;
  EXPECT_NE(meta.find("\"sun\": {\"source\": \"site\""), std::string::npos) << meta;
  EXPECT_NE(meta.find("\"mount\": \"single_axis\", \"rotation_deg\": 25.97"), std::string::npos) << meta;
  const std::string sheet = ::testing::TempDir() + "pvb_sheet_" + std::to_string(::getpid()) + ".png";
  r = run("sheet --scenario " + days + "tracker_station_0800.yaml --scenario " + days +
          "tracker_station_1600.yaml --frame 3 --columns 2 --out " + sheet);
  ASSERT_EQ(r.code, 0) << r.output;
  const cv::Mat img = cv::imread(sheet);
  ASSERT_FALSE(img.empty());
  EXPECT_GT(img.cols, img.rows);  // two tiles in a row
  EXPECT_NE(r.output.find("tracker_station_1600: sun 247/63, trackers -25"), std::string::npos) << r.output;
  r = run("sheet --scenario " + days + "tracker_station_0800.yaml --frame 100000 --out " + sheet);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("--frame: expected a frame below the scenario's 751, got 100000"), std::string::npos)
      << r.output;
}

// SIGHUP (the terminal closed) stops like Ctrl-C: it used to kill the
// recording and leave no meta.json.
TEST(RecordCli, HangUpStopsAtTheNextFrameAndWritesMeta) {
  const std::string d = fresh("sighup");
  const std::string log = ::testing::TempDir() + "pvb_rec_sighup_" + std::to_string(::getpid()) + ".txt";
  const pid_t pid =
      test::spawn_pvbench({"record", "--scenario", kStation, "--out", d, "--frames", "600"}, log);
  ASSERT_GE(pid, 0);
  ASSERT_TRUE(test::wait_until(
      pid, [&] { return data_lines(d + "/associations.txt") >= 2; }, 300))
      << "pvbench ended early or wrote nothing: " << read_file(log);
  ASSERT_EQ(::kill(pid, SIGHUP), 0);
  int status = 0;
  for (int i = 0; i < 1200 && ::waitpid(pid, &status, WNOHANG) == 0; ++i) ::usleep(100000);
  if (::waitpid(pid, nullptr, WNOHANG) == 0) {  // still running after 120 s
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    FAIL() << "pvbench did not stop within 120 s of SIGHUP";
  }
  ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal: " << read_file(log);
  EXPECT_EQ(WEXITSTATUS(status), 130) << read_file(log);
  const std::string meta = read_file(d + "/meta.json");
  EXPECT_NE(meta.find("\"interrupted\": true"), std::string::npos) << meta;
}

// Every Nth frame: the frames a full recording has at those times, byte for
// byte (the noise is seeded per frame), at the lower rate, with the motion
// readings of the frames between.
TEST(RecordCli, EveryNthFrameIsTheFullRecordingsFrameWithTheMotionBetween) {
  const std::string d = fresh("every");
  const Result r = run("record --scenario " + kStation + " --out " + d + " --frames 4 --every 6 --seed " +
                       std::to_string(pvb::test::kStationSeed));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(data_lines(d + "/rgb.txt"), 4);
  for (const char* t : {"0.000000", "0.200000", "0.400000", "0.600000"})
    EXPECT_TRUE(read_file(d + "/rgb/" + t + ".png") == read_file(station_run() + "/rgb/" + t + ".png")) << t;
  EXPECT_NE(read_file(d + "/camera.yaml").find("Camera.fps: 5.0"), std::string::npos);
  EXPECT_NE(read_file(d + "/meta.json").find("\"every\": 6"), std::string::npos);
  // The IMU's readings run on through the frames that were not drawn.
  const std::vector<std::string> imu = [&] {
    std::ifstream in(d + "/imu0/data.csv");
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);)
      if (!l.empty() && l[0] != '#') lines.push_back(l);
    return lines;
  }();
  ASSERT_GT(imu.size(), 50u);
  EXPECT_GT(std::stoll(imu.back().substr(0, imu.back().find(','))), 550'000'000LL);
  const Result fake = run("record --scenario " + kStation + " --out " + fresh("every_fake") +
                          " --frames 4 --every 2 --format fakenect");
  EXPECT_EQ(fake.code, 1);
  EXPECT_NE(fake.output.find("--every: expected 1 with --format fakenect"), std::string::npos) << fake.output;
}

// A recording larger than the disk's free space is refused with one line
// before a frame is drawn: an hour at 240 frames/s is 864 001 frames, about
// a terabyte.
TEST(RecordCli, ARecordingTheDiskCannotHoldIsRefusedBeforeItStarts) {
  const std::string yaml = ::testing::TempDir() + "pvb_rec_disk_" + std::to_string(::getpid()) + ".yaml";
  write_file(yaml, "duration_s: 3600\nroute: {waypoints_m: [[0, 0], [5, 0]]}\ncamera: {fps: 240}\n");
  const std::string d = fresh("disk");
  std::filesystem::create_directories(d);
  if (std::filesystem::space(d).available > 1.5e12) GTEST_SKIP() << "this disk holds a terabyte";
  const Result r = run("record --scenario " + yaml + " --out " + d);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(r.output.find("pvbench: error: " + d + ": expected a disk with about "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" free for 864001 frames (fewer with --frames or --every), got "), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(d + "/rgb.txt"));
}
