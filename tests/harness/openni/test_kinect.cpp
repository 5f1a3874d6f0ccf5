// A Kinect v1 end to end without a Kinect: a fakenect dump of pv_station
// from the simulator, played by Debian's fakenect library through our
// OpenNI2 plug-in (freenect://0), libOpenNI2 and `pvbench camera --sync`.
// The same command through the real libfreenect ends with "no Kinect found";
// broken dumps end with one error line and keep the trajectory so far.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_output.hpp"
#include "pvb/common/text.hpp"
#include "station_sequence.hpp"

namespace {

constexpr int kFrames = PVB_KINECT_FRAMES;  // the acceptance drive: 60 in the default set, 150 in scenario-full

using Result = pvb::test::RunResult;
using pvb::test::data_lines;
using pvb::test::expect_one_error_line;
using pvb::test::json_number;

Result run(const std::string& env, const std::string& args) {
  return pvb::test::run_pvbench_from_source(env + " timeout 300", args);
}

std::string fakenect_env(const std::string& dump) {
  return "LD_LIBRARY_PATH=" + std::string(PVB_FAKENECT_LIBRARY_DIR) + " FAKENECT_PATH=" + dump;
}

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_kinect_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + d + " && mkdir -p " + d).c_str());
  return d;
}

/// The station's first `frames` frames as a fakenect dump: the shared one
/// when it has them, else one recorded into `dir`.
std::string station_dump(const std::string& dir, int frames) {
  if (frames == pvb::test::kStationFakenectFrames) return pvb::test::station_fakenect_dump();
  const std::string dump = dir + "/dump";
  const Result rec = run("", "record --scenario scenes/pv_station.yaml --format fakenect --frames " +
                                 std::to_string(frames) + " --out " + dump);
  EXPECT_EQ(rec.code, 0) << rec.output;
  return dump;
}

/// The file named on line `line` (1-based) of the dump's INDEX.txt.
std::string index_entry(const std::string& dump, int line) {
  std::ifstream in(dump + "/INDEX.txt");
  std::string name;
  for (int i = 0; i < line; ++i) std::getline(in, name);
  return name;
}

/// Replaces the file on line `line` of the dump's INDEX.txt with `content`,
/// or removes it when `content` is null.
std::string break_entry(const std::string& dump, int line, const std::string* content) {
  const std::string name = index_entry(dump, line);
  const std::string path = dump + "/" + name;
  std::remove(path.c_str());
  if (content) std::ofstream(path, std::ios::binary) << *content;
  return name;
}

}  // namespace

TEST(PVB_KINECT_SUITE, FakenectDumpTracksDeterministicallyAndItsOniReplaysTheSame) {
  const std::string dir = fresh("accept");
  const std::string dump = station_dump(dir, kFrames);
  const std::string oni = dir + "/run.oni";
  const Result first =
      run(fakenect_env(dump), "camera --uri freenect://0 --sync --record " + oni + " --out " + dir + "/a");
  ASSERT_EQ(first.code, 0) << first.output;
  const std::string stats = pvb::read_file(dir + "/a/stats.json");
  EXPECT_EQ(json_number(stats, "frames"), kFrames) << stats;
  EXPECT_EQ(json_number(stats, "lost_frames"), 0) << stats;
  EXPECT_EQ(json_number(stats, "dropped_colour") + json_number(stats, "dropped_depth"), 0) << stats;
  const std::vector<std::string> a = data_lines(dir + "/a/CameraTrajectory.txt");
  EXPECT_EQ(a.size(), static_cast<std::size_t>(kFrames));  // every frame tracked
  const double ate = json_number(stats, "ate_rmse_m");
  ASSERT_GE(ate, 0.0) << stats;
  EXPECT_LE(ate, 0.02) << stats;

  const Result second = run(fakenect_env(dump), "camera --uri freenect://0 --sync --out " + dir + "/b");
  ASSERT_EQ(second.code, 0) << second.output;
  EXPECT_EQ(data_lines(dir + "/b/CameraTrajectory.txt"), a);

  const Result replay =
      run("", "camera --oni " + oni + " --settings " + dir + "/a/camera.yaml --sync --out " + dir + "/c");
  ASSERT_EQ(replay.code, 0) << replay.output;
  EXPECT_EQ(data_lines(dir + "/c/CameraTrajectory.txt"), a);
  std::system(("rm -rf " + dir).c_str());  // the .oni, and on the longer drive its own dump
}

TEST(PVB_KINECT_SUITE, RealLibfreenectWithoutAKinectSaysSo) {
  const std::string dir = fresh("nodevice");
  const Result r = run("FAKENECT_PATH=", "camera --uri freenect://0 --sync --settings " + std::string(PVB_SOURCE_DIR) +
                                             "/configs/kinect/kinect_v1.yaml --out " + dir + "/out");
  expect_one_error_line(r, "no Kinect found");
}

TEST(PVB_KINECT_SUITE, BrokenDumpsEndWithOneErrorAndKeepTheTrajectory) {
  const std::string dir = fresh("broken");
  const std::string& dump = pvb::test::station_fakenect_dump();
  const int frame = 20, line_of_depth = 3 * frame + 2;  // a, d, r per frame
  struct Case {
    const char* what;
    int line;
    std::string content;
    bool remove;
    const char* expect;
  };
  const std::string full_depth = pvb::read_file(dump + "/" + index_entry(dump, line_of_depth));
  const Case cases[] = {
      {"truncated", line_of_depth, full_depth.substr(0, full_depth.size() / 3), false, "truncated"},
      {"missing", line_of_depth + 1, "", true, "missing"},
      {"resolution", line_of_depth + 1, "P6 320 240 255\n" + std::string(320 * 240 * 3, 'x'), false, "320x240"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const std::string copy = dir + "/" + c.what;
    std::system(("cp -rs " + dump + " " + copy).c_str());  // links: break_entry replaces a link, not its file
    const std::string name = break_entry(copy, c.line, c.remove ? nullptr : &c.content);
    const Result r = run(fakenect_env(copy), "camera --uri freenect://0 --sync --out " + copy + "/out");
    expect_one_error_line(r, c.expect);
    EXPECT_NE(r.output.find(name), std::string::npos) << r.output;
    EXPECT_EQ(data_lines(copy + "/out/CameraTrajectory.txt").size(), static_cast<std::size_t>(frame))
        << r.output;
  }
  std::system(("rm -rf " + dir).c_str());
}

TEST(PVB_KINECT_SUITE, IndexPastTheDevicesAndBadUrisSaySo) {
  const std::string dir = fresh("index");
  const std::string& dump = pvb::test::station_fakenect_dump();
  const std::string settings = " --settings " + std::string(PVB_SOURCE_DIR) + "/configs/kinect/kinect_v1.yaml";
  expect_one_error_line(run(fakenect_env(dump), "camera --uri freenect://1" + settings + " --out " + dir + "/a"),
                        "no Kinect 1 (libfreenect sees 1)");
  expect_one_error_line(run(fakenect_env(dump), "camera --uri freenect://x" + settings + " --out " + dir + "/b"),
                        "is not freenect://<index>");
  expect_one_error_line(run(fakenect_env(dir + "/nothing"), "camera --uri freenect://0" + settings + " --out " +
                                                                 dir + "/c"),
                        "INDEX.txt");
  std::system(("rm -rf " + dir).c_str());
}

namespace {

TEST(PVB_KINECT_SUITE, ADumpOfAnotherRunLocalisesInAMapSavedByRun) {
  // The map from the simulator in memory (pvbench run), the query from a
  // Kinect v1 dump of the same station with other noise and dust: the
  // real-Kinect path must find itself in the map, judged in its frame.
  const std::string d = fresh("map");
  const std::string noon = "scenes/days/pv_station_1200.yaml";
  const Result map = run("", "run --scenario " + noon + " --frames 90 --sync --no-map-eval --save-map " + d +
                                 "/noon.pvbmap --out " + d + "/map");
  ASSERT_EQ(map.code, 0) << map.output;
  const Result rec = run("", "record --scenario " + noon + " --seed 2 --format fakenect --frames 60 --out " + d + "/dump");
  ASSERT_EQ(rec.code, 0) << rec.output;
  const Result cam = run(fakenect_env(d + "/dump"), "camera --uri freenect://0 --sync --map " + d +
                                                        "/noon.pvbmap --map-mode localise --out " + d + "/cam");
  ASSERT_EQ(cam.code, 0) << cam.output;
  const std::string stats = pvb::read_file(d + "/cam/stats.json");
  const std::size_t loc = stats.find("\"localisation\": {");
  ASSERT_NE(loc, std::string::npos) << stats;
  const std::string l = stats.substr(loc);
  EXPECT_EQ(json_number(l, "wrong_place"), 0.0) << l;
  EXPECT_GE(json_number(l, "first_pose_frame"), 0.0) << l;
  EXPECT_LE(json_number(l, "first_pose_frame"), 30.0) << l;
  EXPECT_GE(json_number(l.substr(l.find("\"fine\"")), "share"), 0.95) << l;
}

}  // namespace
