// pvbench camera end to end through OpenNI2: the simulator's virtual device
// (sim://) -> PE-SLAM -> ATE, recording an .oni on the way; the replay of
// that .oni gives the same poses; unplugging keeps the trajectory; bad
// inputs give one error line and a non-zero exit.
//
// PVB_CAMERA_FRAMES sets the run length: the default CI set uses a short
// drive, the scenario-full build the 300 frames.
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

#include "pvb/common/text.hpp"
#include "pvb/openni/oni_file.hpp"

namespace {

const std::string kBin = std::string(PVB_BINARY_DIR) + "/bin/pvbench";
constexpr int kFrames = PVB_CAMERA_FRAMES;

struct Result {
  int code = -1;
  std::string output;
};

// Runs pvbench from the source folder (so that sim://scenes/... resolves as
// in the command line).
Result run(const std::string& args) {
  const std::string log = ::testing::TempDir() + "pvb_cam_" + std::to_string(::getpid()) + ".txt";
  const std::string cmd = "cd " + std::string(PVB_SOURCE_DIR) + " && " + kBin + " " + args + " > " + log + " 2>&1";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, pvb::read_file(log)};
}

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_cam_" + name + "_" + std::to_string(kFrames) + "_" +
                        std::to_string(::getpid());
  std::system(("rm -rf " + d + " && mkdir -p " + d).c_str());
  return d;
}

std::vector<std::string> data_lines(const std::string& path) {
  std::vector<std::string> out;
  std::ifstream in(path);
  for (std::string l; std::getline(in, l);)
    if (!l.empty() && l[0] != '#') out.push_back(l);
  return out;
}

double json_number(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\": ([-0-9.eE+]+)");
  std::smatch m;
  if (!std::regex_search(json, m, re)) return -1;
  return std::stod(m[1]);
}

// Lines of output that say "error".
std::vector<std::string> error_lines(const std::string& output) {
  std::vector<std::string> out;
  std::istringstream in(output);
  for (std::string l; std::getline(in, l);)
    if (l.find("error") != std::string::npos) out.push_back(l);
  return out;
}

void expect_one_error_line(const Result& r, const std::string& must_contain) {
  EXPECT_NE(r.code, 0) << r.output;
  const std::vector<std::string> errors = error_lines(r.output);
  ASSERT_EQ(errors.size(), 1u) << r.output;
  EXPECT_NE(errors[0].find(must_contain), std::string::npos) << errors[0];
}

// The live run, made once: sim:// device, recording, synchronous SLAM.
struct LiveRun {
  std::string dir, oni;
  Result result;
};
const LiveRun& live_run() {
  static const LiveRun run_once = [] {
    LiveRun l;
    l.dir = fresh("live");
    l.oni = l.dir + "/run.oni";
    l.result = run("camera --uri sim://scenes/pv_station.yaml --frames " + std::to_string(kFrames) + " --record " +
                   l.oni + " --sync --out " + l.dir + "/out");
    return l;
  }();
  return run_once;
}

}  // namespace

TEST(CameraCli, SimDeviceTracksWithinTwoCentimetres) {
  const LiveRun& l = live_run();
  ASSERT_EQ(l.result.code, 0) << l.result.output;
  const std::string out = l.dir + "/out";
  for (const char* f : {"camera.yaml", "CameraTrajectory.txt", "KeyFrameTrajectory.txt", "map.ply", "stats.json",
                        "groundtruth.txt"})
    EXPECT_TRUE(std::ifstream(out + "/" + f).good()) << f;
  EXPECT_EQ(data_lines(out + "/groundtruth.txt").size(), static_cast<std::size_t>(kFrames));
  const std::size_t tracked = data_lines(out + "/CameraTrajectory.txt").size();
  EXPECT_GE(tracked, static_cast<std::size_t>(kFrames * 9 / 10)) << l.result.output;
  const std::string stats = pvb::read_file(out + "/stats.json");
  EXPECT_EQ(json_number(stats, "frames"), kFrames);
  const double ate = json_number(stats, "ate_rmse_m");
  ASSERT_GE(ate, 0.0) << stats;
  EXPECT_LE(ate, 0.02) << stats;
  EXPECT_GT(json_number(stats, "keyframes"), 0) << stats;
  // the map: a PLY header with as many vertices as lines
  const std::string ply = pvb::read_file(out + "/map.ply");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(ply, m, std::regex("element vertex ([0-9]+)")));
  EXPECT_GT(std::stoi(m[1]), 100);
}

TEST(CameraCli, RecordingHoldsEveryFrame) {
  const LiveRun& l = live_run();
  ASSERT_EQ(l.result.code, 0) << l.result.output;
  const pvb::openni::OniFileSummary s = pvb::openni::scan_oni_file(l.oni);
  EXPECT_TRUE(s.has_end);
  EXPECT_EQ(s.broken_at, 0u);
  EXPECT_EQ(s.frames_of(pvb::openni::kOniNodeDepth), static_cast<std::uint32_t>(kFrames));
  EXPECT_EQ(s.frames_of(pvb::openni::kOniNodeImage), static_cast<std::uint32_t>(kFrames));
}

TEST(CameraCli, ReplayOfTheRecordingGivesTheSamePoses) {
  const LiveRun& l = live_run();
  ASSERT_EQ(l.result.code, 0) << l.result.output;
  const std::string d = fresh("replay");
  const Result r = run("camera --oni " + l.oni + " --settings " + l.dir + "/out/camera.yaml --sync --out " + d);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(json_number(pvb::read_file(d + "/stats.json"), "frames"), kFrames) << r.output;
  const std::vector<std::string> live = data_lines(l.dir + "/out/CameraTrajectory.txt");
  const std::vector<std::string> replay = data_lines(d + "/CameraTrajectory.txt");
  ASSERT_EQ(live.size(), replay.size());
  ASSERT_FALSE(live.empty());
  for (std::size_t i = 0; i < live.size(); ++i) ASSERT_EQ(live[i], replay[i]) << "line " << i;
  EXPECT_EQ(pvb::read_file(l.dir + "/out/KeyFrameTrajectory.txt"), pvb::read_file(d + "/KeyFrameTrajectory.txt"));
}

TEST(CameraCli, UnpluggedCameraKeepsTheTrajectorySoFar) {
  const std::string d = fresh("unplug");
  const Result r = run("camera --uri 'sim://scenes/pv_station.yaml?unplug_after=12' --frames 40 --sync --out " + d);
  expect_one_error_line(r, "disconnected");
  const std::vector<std::string> poses = data_lines(d + "/CameraTrajectory.txt");
  EXPECT_GT(poses.size(), 5u) << r.output;
  EXPECT_LE(poses.size(), 12u);
  EXPECT_EQ(data_lines(d + "/groundtruth.txt").size(), 12u);
  EXPECT_TRUE(std::ifstream(d + "/KeyFrameTrajectory.txt").good());
}

TEST(CameraCli, BadUriIsOneErrorLine) {
  const std::string d = fresh("baduri");
  expect_one_error_line(run("camera --uri sim://scenes/no_such_scenario.yaml --out " + d), "no_such_scenario.yaml");
  expect_one_error_line(run("camera --uri 'nonsense://device' --settings " + std::string(PVB_SOURCE_DIR) +
                            "/configs/no_file.yaml --out " + d),
                        "no_file.yaml");
  expect_one_error_line(run("camera --uri 'sim://scenes/pv_station.yaml?fps=3' --out " + d), "fps");
}

TEST(CameraCli, BadDeviceUriIsOneErrorLine) {
  const LiveRun& l = live_run();
  ASSERT_EQ(l.result.code, 0) << l.result.output;
  const std::string d = fresh("baddev");
  expect_one_error_line(run("camera --uri 'nonsense://device' --settings " + l.dir + "/out/camera.yaml --out " + d),
                        "nonsense://device");
}

TEST(CameraCli, MissingOniIsOneErrorLine) {
  const std::string d = fresh("missing");
  expect_one_error_line(run("camera --oni " + d + "/none.oni --settings x.yaml --out " + d), "none.oni");
}

TEST(CameraCli, TruncatedOniIsOneErrorLine) {
  const LiveRun& l = live_run();
  ASSERT_EQ(l.result.code, 0) << l.result.output;
  const std::string d = fresh("trunc");
  const std::string cut = d + "/cut.oni";
  std::ifstream in(l.oni, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(cut, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  expect_one_error_line(run("camera --oni " + cut + " --settings " + l.dir + "/out/camera.yaml --out " + d + "/o"),
                        "truncated");
}
