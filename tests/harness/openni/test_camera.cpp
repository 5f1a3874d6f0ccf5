// pvbench camera end to end through OpenNI2: the simulator's virtual device
// (sim://) -> PE-SLAM -> ATE, recording an .oni on the way; the replay of
// that .oni gives the same poses; unplugging keeps the trajectory; bad
// inputs give one error line and a non-zero exit.
//
// PVB_CAMERA_FRAMES sets the run length: the default CI set uses a short
// drive, the scenario-full build 300 frames.
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
#include "pvb/openni/oni_file.hpp"

namespace {

const std::string kBin = std::string(PVB_BINARY_DIR) + "/bin/pvbench";
constexpr int kFrames = PVB_CAMERA_FRAMES;

using Result = pvb::test::RunResult;
using pvb::test::data_lines;
using pvb::test::expect_one_error_line;
using pvb::test::json_number;

Result run(const std::string& args) { return pvb::test::run_pvbench_from_source("", args); }

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_cam_" + name + "_" + std::to_string(kFrames) + "_" +
                        std::to_string(::getpid());
  std::system(("rm -rf " + d + " && mkdir -p " + d).c_str());
  return d;
}

// A settings file for runs that must get past the settings check.
std::string settings_file(const std::string& dir) {
  const std::string path = dir + "/settings.yaml";
  std::ofstream(path)
      << "%YAML:1.0\nCamera.fx: 525.0\nCamera.fy: 525.0\nCamera.cx: 319.5\nCamera.cy: 239.5\n"
         "Camera.k1: 0.0\nCamera.k2: 0.0\nCamera.p1: 0.0\nCamera.p2: 0.0\nCamera.k3: 0.0\n"
         "Camera.width: 640\nCamera.height: 480\nCamera.fps: 30.0\nCamera.bf: 40.0\nCamera.RGB: 1\n"
         "ThDepth: 40.0\nDepthMapFactor: 1000.0\nORBextractor.nFeatures: 1000\n"
         "ORBextractor.scaleFactor: 1.2\nORBextractor.nLevels: 8\nORBextractor.iniThFAST: 20\n"
         "ORBextractor.minThFAST: 7\n";
  return path;
}

}  // namespace

// The acceptance run: sim:// device -> SLAM -> ATE, recording an
// .oni; then the replay of that .oni gives the same poses, and the same
// recording cut in half is refused.  One test, so the live run is made once.
TEST(PVB_CAMERA_SUITE, SimDeviceTracksRecordsAndReplaysIdentically) {
  const std::string dir = fresh("live");
  const std::string oni = dir + "/run.oni";
  const std::string out = dir + "/out";
  const Result live = run("camera --uri sim://scenes/pv_station.yaml --frames " + std::to_string(kFrames) +
                          " --record " + oni + " --sync --out " + out);
  ASSERT_EQ(live.code, 0) << live.output;

  // Outputs and accuracy.
  for (const char* f : {"camera.yaml", "CameraTrajectory.txt", "KeyFrameTrajectory.txt", "map.ply",
                        "stats.json", "groundtruth.txt"})
    EXPECT_TRUE(std::ifstream(out + "/" + f).good()) << f;
  EXPECT_EQ(data_lines(out + "/groundtruth.txt").size(), static_cast<std::size_t>(kFrames));
  const std::size_t tracked = data_lines(out + "/CameraTrajectory.txt").size();
  EXPECT_GE(tracked, static_cast<std::size_t>(kFrames * 9 / 10)) << live.output;
  const std::string stats = pvb::read_file(out + "/stats.json");
  EXPECT_EQ(json_number(stats, "frames"), kFrames);
  const double ate = json_number(stats, "ate_rmse_m");
  ASSERT_GE(ate, 0.0) << stats;
  EXPECT_LE(ate, 0.02) << stats;
  EXPECT_GT(json_number(stats, "keyframes"), 0) << stats;
  const std::string ply = pvb::read_file(out + "/map.ply");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(ply, m, std::regex("element vertex ([0-9]+)")));
  EXPECT_GT(std::stoi(m[1]), 100);

  // Every frame landed in the recording.
  const pvb::openni::OniFileSummary s = pvb::openni::scan_oni_file(oni);
  EXPECT_TRUE(s.has_end);
  EXPECT_EQ(s.broken_at, 0u);
  EXPECT_EQ(s.end_bytes, s.size_bytes);  // no padding after the end record
  EXPECT_EQ(s.frames_of(pvb::openni::kOniNodeDepth), static_cast<std::uint32_t>(kFrames));
  EXPECT_EQ(s.frames_of(pvb::openni::kOniNodeImage), static_cast<std::uint32_t>(kFrames));

  // The replay gives the same poses, bit for bit (same text).
  const std::string rep = dir + "/replay";
  const Result replay =
      run("camera --oni " + oni + " --settings " + out + "/camera.yaml --sync --out " + rep);
  ASSERT_EQ(replay.code, 0) << replay.output;
  EXPECT_EQ(json_number(pvb::read_file(rep + "/stats.json"), "frames"), kFrames) << replay.output;
  const std::vector<std::string> a = data_lines(out + "/CameraTrajectory.txt");
  const std::vector<std::string> b = data_lines(rep + "/CameraTrajectory.txt");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_FALSE(a.empty());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "line " << i;
  EXPECT_EQ(pvb::read_file(out + "/KeyFrameTrajectory.txt"), pvb::read_file(rep + "/KeyFrameTrajectory.txt"));

  // A truncated copy: one error line, non-zero exit.
  for (const double share : {0.5, 0.9}) {
    const std::string cut = dir + "/cut.oni";
    std::ifstream in(oni, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary)
        .write(bytes.data(), static_cast<std::streamsize>(static_cast<double>(bytes.size()) * share));
    expect_one_error_line(
        run("camera --oni " + cut + " --settings " + out + "/camera.yaml --out " + dir + "/c"), "truncated");
  }
  // The recording is large (about 1 MB a frame): keep it only to look at a failure.
  if (!::testing::Test::HasFailure()) std::system(("rm -rf " + dir).c_str());
}

TEST(PVB_CAMERA_SUITE, UnpluggedCameraKeepsTheTrajectorySoFar) {
  const std::string d = fresh("unplug");
  const Result r =
      run("camera --uri 'sim://scenes/pv_station.yaml?unplug_after=12' --frames 40 --sync --out " + d);
  expect_one_error_line(r, "disconnected");
  const std::vector<std::string> poses = data_lines(d + "/CameraTrajectory.txt");
  EXPECT_GT(poses.size(), 5u) << r.output;
  EXPECT_LE(poses.size(), 12u);
  EXPECT_EQ(data_lines(d + "/groundtruth.txt").size(), 12u);
  EXPECT_TRUE(std::ifstream(d + "/KeyFrameTrajectory.txt").good());
  EXPECT_TRUE(std::ifstream(d + "/map.ply").good());
}

// A camera that stops sending but stays connected: after --timeout-ms
// without a frame the run ends with one error line and keeps what it
// tracked.
TEST(PVB_CAMERA_SUITE, HungCameraTimesOutAndKeepsTheTrajectory) {
  const std::string d = fresh("stall");
  const Result r =
      run("camera --uri 'sim://scenes/pv_station.yaml?stall_after=8' --sync --timeout-ms 1500 --out " + d);
  expect_one_error_line(r, "no frame for 1500 ms");
  EXPECT_EQ(data_lines(d + "/groundtruth.txt").size(), 8u);
  EXPECT_GT(data_lines(d + "/CameraTrajectory.txt").size(), 4u) << r.output;
  EXPECT_TRUE(std::ifstream(d + "/stats.json").good());
}

// Ctrl-C while the camera is hung ends the run at once (not after
// --timeout-ms, here 10 minutes), as a normal stop: exit 0, outputs written.
// A watchdog kills pvbench after 120 s, which fails the test.  (--foreground:
// otherwise timeout passes the signal on to its process group as well, and
// pvbench would see a second SIGINT, which ends it at once by design.)
TEST(PVB_CAMERA_SUITE, CtrlCWhileWaitingForFramesStopsAtOnce) {
  const std::string d = fresh("sigint");
  const std::string log = d + "/out.txt";
  const std::string script =
      "cd " + std::string(PVB_SOURCE_DIR) + " && (timeout --foreground -s KILL 120 " + kBin +
      " camera --uri 'sim://scenes/pv_station.yaml?stall_after=8' --sync --timeout-ms 600000 --out " + d +
      " > " + log +
      " 2>&1 & pid=$!; "
      "for i in $(seq 1 600); do [ \"$(grep -vc '^#' " +
      d +
      "/groundtruth.txt 2>/dev/null)\" = 8 ] && break; sleep 0.2; done; "
      "sleep 1; kill -INT $pid; wait $pid; echo \"exit $?\" >> " +
      log + ")";
  std::system(script.c_str());
  const std::string out = pvb::read_file(log);
  EXPECT_NE(out.find("exit 0"), std::string::npos) << out;
  EXPECT_NE(out.find("stopped by a signal"), std::string::npos) << out;
  EXPECT_EQ(data_lines(d + "/groundtruth.txt").size(), 8u);
  EXPECT_EQ(json_number(pvb::read_file(d + "/stats.json"), "frames"), 8) << out;
}

TEST(PVB_CAMERA_SUITE, BadUriIsOneErrorLine) {
  const std::string d = fresh("baduri");
  expect_one_error_line(run("camera --uri sim://scenes/no_such_scenario.yaml --out " + d),
                        "no_such_scenario.yaml");
  expect_one_error_line(run("camera --uri 'sim://scenes/pv_station.yaml?fps=3' --out " + d), "fps");
  expect_one_error_line(
      run("camera --uri 'nonsense://device' --settings " + settings_file(d) + " --out " + d + "/out"),
      "nonsense://device");
  // a real camera needs calibrated intrinsics
  expect_one_error_line(run("camera --uri 'nonsense://device' --out " + d), "--settings");
}

TEST(PVB_CAMERA_SUITE, MissingOniIsOneErrorLine) {
  const std::string d = fresh("missing");
  expect_one_error_line(run("camera --oni " + d + "/none.oni --settings " + settings_file(d) + " --out " + d + "/out"),
                        "none.oni");
}

// --record to a path OpenNI2's recorder cannot create (under a regular file,
// in a missing folder, a folder) is one error line: the recorder used to
// crash (SIGSEGV) on the first two.
TEST(PVB_CAMERA_SUITE, UnwritableRecordTargetIsOneErrorLine) {
  const std::string d = fresh("unwritable");
  const std::string plain = d + "/plain";
  pvb::write_file(plain, "x");
  const std::string cmd =
      "camera --uri 'sim://scenes/pv_station.yaml?frames=3' --sync --out " + d + "/out --record ";
  expect_one_error_line(run(cmd + plain + "/run.oni"), "is not a folder");
  expect_one_error_line(run(cmd + d + "/missing/run.oni"), "does not exist");
  expect_one_error_line(run(cmd + d), "is a folder");
  EXPECT_EQ(pvb::read_file(plain), "x");
}

// A recording never lands on an input (also through a link) nor replaces an
// existing file: the input .oni used to be overwritten (60 MB became 2 KB).
// The device's end of stream (a sim:// device of 3 frames) ends the run
// that recorded it, with its frames and exit 0, not a wait for --timeout-ms.
TEST(PVB_CAMERA_SUITE, RecordingNeverReplacesAnInputOrAnExistingFile) {
  const std::string d = fresh("noclobber");
  const std::string oni = d + "/in.oni";
  const Result live = run("camera --uri 'sim://scenes/pv_station.yaml?frames=3' --sync --timeout-ms 60000 --record " +
                          oni + " --out " + d + "/live");
  ASSERT_EQ(live.code, 0) << live.output;
  EXPECT_EQ(json_number(pvb::read_file(d + "/live/stats.json"), "frames"), 3) << live.output;
  EXPECT_EQ(data_lines(d + "/live/groundtruth.txt").size(), 3u);
  const std::string bytes = pvb::read_file(oni);
  ASSERT_GT(bytes.size(), 100000u);
  ASSERT_EQ(std::system(("ln -s in.oni " + d + "/link.oni").c_str()), 0);
  const std::string replay = "camera --oni " + oni + " --settings " + d + "/live/camera.yaml --sync --out " +
                             d + "/replay --record ";
  expect_one_error_line(run(replay + oni), "is the --oni recording");
  expect_one_error_line(run(replay + d + "/link.oni"), "is the --oni recording");
  expect_one_error_line(run(replay + d + "/live/camera.yaml"), "is the --settings file");
  expect_one_error_line(run(replay + d + "/replay/stats.json"), "is an output of this run");
  expect_one_error_line(run(replay + d + "/live/stats.json"), "already exists");
  EXPECT_TRUE(pvb::read_file(oni) == bytes) << "the input recording changed";
  // the scenario of a sim:// run (a copy: a broken build must not truncate the shipped one)
  const std::string scenario = d + "/scene.yaml";
  const std::string scenario_text = pvb::read_file(std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml");
  pvb::write_file(scenario, scenario_text);
  expect_one_error_line(
      run("camera --uri 'sim://" + scenario + "?frames=3' --sync --out " + d + "/x --record " + scenario),
      "is the scenario");
  EXPECT_EQ(pvb::read_file(scenario), scenario_text);
  if (!::testing::Test::HasFailure()) std::system(("rm -rf " + d).c_str());
}

// Every refusal of a --record path comes before a device is opened: an
// error thrown while libOpenNI2 played a recording back crashed its
// teardown now and then (a segfault instead of the error line, about one
// run in ten on a loaded machine).  A device that does not exist shows the
// order: the existing file is named, not the missing device.
TEST(PVB_CAMERA_SUITE, RecordPathIsRefusedBeforeAnyDeviceOpens) {
  const std::string d = fresh("refusefirst");
  pvb::write_file(d + "/old.oni", "x");
  const Result r = run("camera --uri no-such-device --settings " + std::string(PVB_SOURCE_DIR) +
                       "/configs/tum/TUM3.yaml --out " + d + "/out --record " + d + "/old.oni");
  expect_one_error_line(r, "already exists");
  EXPECT_EQ(r.output.find("no-such-device"), std::string::npos) << r.output;
  EXPECT_EQ(pvb::read_file(d + "/old.oni"), "x");
}

// A bad --frames or --timeout-ms is one error line, exit 1, before anything
// is written: "-3" used to wrap around and run the whole stream.
TEST(PVB_CAMERA_SUITE, BadCountsAreOneErrorLine) {
  const std::string d = fresh("counts");
  for (const char* bad :
       {"--frames -3", "--frames abc", "--frames 1.5", "--timeout-ms 0", "--timeout-ms -1"}) {
    const Result r =
        run("camera --uri 'sim://scenes/pv_station.yaml?frames=3' --sync --out " + d + "/out " + bad);
    EXPECT_EQ(r.code, 1) << bad << ": " << r.output;
    expect_one_error_line(r, "expected a whole number in [");
  }
  EXPECT_FALSE(std::ifstream(d + "/out/stats.json").good());
}

// Depth that is all zeros (nothing within the depth range): SLAM never
// initialises.  The run says so in one line and exits non-zero, and keeps
// what it wrote.
TEST(PVB_CAMERA_SUITE, NeverInitialisedIsOneErrorLineAndKeepsTheOutputs) {
  const std::string d = fresh("zerodepth");
  pvb::write_file(d + "/zero.yaml",
                  "route: {waypoints_m: [[0, 0], [5, 0]]}\ncamera: {depth_range_m: [0.05, 0.06]}\n");
  const Result r = run("camera --uri 'sim://" + d + "/zero.yaml?frames=6' --sync --out " + d + "/out");
  expect_one_error_line(r, "SLAM never initialised in 6 frames");
  EXPECT_EQ(r.code, 1);
  const std::string stats = pvb::read_file(d + "/out/stats.json");
  EXPECT_EQ(json_number(stats, "frames"), 6) << stats;
  EXPECT_EQ(json_number(stats, "not_initialized_frames"), 6) << stats;
  EXPECT_EQ(data_lines(d + "/out/groundtruth.txt").size(), 6u);
  EXPECT_TRUE(std::ifstream(d + "/out/map.ply").good());
}

// An error in the user's --settings file names that file, not the copy
// written into the output folder.
TEST(PVB_CAMERA_SUITE, SettingsErrorsNameTheUsersFile) {
  const std::string d = fresh("settings");
  const std::string good = pvb::read_file(settings_file(d));
  const std::string user = d + "/mine.yaml";
  pvb::write_file(user, std::regex_replace(good, std::regex("Camera.fx: 525.0\n"), ""));
  const Result r = run("camera --uri 'nonsense://device' --settings " + user + " --out " + d + "/out");
  expect_one_error_line(r, user + ": Camera.fx");
  EXPECT_EQ(r.output.find("out/camera.yaml"), std::string::npos) << r.output;
}

// Ctrl-C while the device is being set up (the sim:// scene built, the
// driver loaded) killed the run: exit 130, no message, only camera.yaml
// written.  A stop signal from the moment the output folder is made ends
// the run as the end of its stream would: exit 0, every output written.
TEST(PVB_CAMERA_SUITE, CtrlCDuringSetUpEndsTheRunWithItsOutputs) {
  const std::string d = fresh("sigint_setup");
  const std::string out = d + "/out", log = d + "/log.txt";
  const std::string script =
      "cd " + std::string(PVB_SOURCE_DIR) + " && (timeout --foreground -s KILL 120 " + kBin +
      " camera --uri 'sim://scenes/pv_station.yaml?frames=8' --sync --out " + out + " > " + log +
      " 2>&1 & pid=$!; for i in $(seq 1 2400); do [ -e " + out +
      "/camera.yaml ] && break; sleep 0.05; done; kill -INT $pid; wait $pid; echo \"exit $?\" >> " + log + ")";
  std::system(script.c_str());
  const std::string said = pvb::read_file(log);
  EXPECT_NE(said.find("exit 0"), std::string::npos) << said;
  EXPECT_NE(said.find("stopped by a signal"), std::string::npos) << said;
  for (const char* f : {"stats.json", "CameraTrajectory.txt", "KeyFrameTrajectory.txt", "map.ply"})
    EXPECT_TRUE(std::ifstream(out + "/" + f).good()) << f << "\n" << said;
}
