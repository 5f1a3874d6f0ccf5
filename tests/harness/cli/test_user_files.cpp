// A user's files are never replaced: nothing is written into a recording a
// command reads, no output lands on another output of the same command,
// --overwrite removes only what pvbench wrote; and input that would crash a
// library later is one error line before any folder is made.  Every case
// is refused before any work (fast: no frame is rendered).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "pvb/common/io_paths.hpp"
#include "pvb/common/text.hpp"
#include "pvb/run/output_names.hpp"
#include "run_pvbench.hpp"
#include "shared_data.hpp"

using namespace pvb;
namespace fs = std::filesystem;

namespace {

const std::string kStation = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_user_files_" + name + "_" + std::to_string(::getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

/// A copy of the two-frame TUM sequence with the files a pvbench recording
/// adds beside its lists, each holding its own name.
std::string recording(const std::string& name, const std::vector<std::string>& extra) {
  const std::string d = fresh(name) + "/seq";
  fs::copy(test::shared_path("data/tum/fr1_xyz_pair"), d, fs::copy_options::recursive);
  fs::create_directories(d + "/imu0");
  for (const std::string& f : extra) write_file(d + "/" + f, f + "\n");
  return d;
}

void expect_one_error(const test::RunResult& r, const std::string& says) {
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(r.output.find("pvbench: error: " + says), std::string::npos) << r.output;
}

}  // namespace

// `slam --save-map` into the folder it reads as a sequence replaced the
// recording's own files (robot.yaml, imu0/truth.csv, which slam reads, the
// contact sheet ...): refused whatever file it names, and so is an output
// folder inside it.
TEST(UserFiles, NothingIsWrittenIntoTheSequenceFolder) {
  const std::vector<std::string> files = {"odom.txt",         "robot.yaml",       "imu.yaml",  "imu0/truth.csv",
                                          "wheels_truth.csv", "robot_truth.yaml", "scene.xml", "contact_sheet.png"};
  const std::string seq = recording("into_seq", files);
  const std::string settings = test::shared_path("data/tum/TUM1.yaml");
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    expect_one_error(test::run_pvbench("slam --sequence " + seq + " --settings " + settings + " --out " + seq +
                                       "/../out --save-map " + seq + "/" + f),
                     seq + "/" + f + ": lies in the --sequence folder (" + seq + "), a recording this command reads");
    EXPECT_EQ(read_file(seq + "/" + f), f + "\n");
  }
  expect_one_error(test::run_pvbench("slam --sequence " + seq + " --settings " + settings + " --out " + seq + "/slam"),
                   seq + "/slam: the --out folder lies in the --sequence folder");
  EXPECT_FALSE(fs::exists(seq + "/slam"));
  expect_one_error(test::run_pvbench("match --sequence " + seq + " --frames 0,1 --settings " + settings +
                                     " --runs 1 --json " + seq + "/robot.yaml"),
                   seq + "/robot.yaml: lies in the --sequence folder");
}

// --save-map onto a file the command writes into its own --out folder was
// not refused ("map saved to D/stats.json", and the map was gone): two
// outputs on one file are refused before any work.
TEST(UserFiles, AMapIsNeverSavedOntoAnotherOutputOfTheCommand) {
  const std::string d = fresh("own_outputs");
  const std::string seq = recording("own_seq", {});
  const std::string slam = "slam --sequence " + seq + " --settings " + test::shared_path("data/tum/TUM1.yaml");
  for (const char* f : {"stats.json", "CameraTrajectory.txt", "PointCloud_live.ply"}) {
    expect_one_error(test::run_pvbench(slam + " --out " + d + "/s --save-map " + d + "/s/" + f),
                     d + "/s/" + f + ": is " + f + " of the --out folder, which this command writes; give --save-map");
    EXPECT_FALSE(fs::exists(d + "/s")) << "the run began";
  }
  for (const char* f : {"odom.txt", "imu0/data.csv", "metrics.json", "baseline/timing.csv", "tilt_error.png"}) {
    expect_one_error(
        test::run_pvbench("run --scenario " + kStation + " --out " + d + "/r --save-map " + d + "/r/" + f),
        d + "/r/" + f + ": is " + f + " of the --out folder, which this command writes");
    EXPECT_FALSE(fs::exists(d + "/r")) << "the run began";
  }
  if (test::run_pvbench("camera --help").code != 0) GTEST_SKIP() << "pvbench built without OpenNI2";
  for (const char* f : {"odom.txt", "stats.json"}) {
    expect_one_error(test::run_pvbench_from_source("", "camera --uri sim://scenes/pv_station.yaml --out " + d +
                                                           "/c --save-map " + d + "/c/" + f),
                     d + "/c/" + f + ": is " + f + " of the --out folder, which this command writes");
    EXPECT_FALSE(fs::exists(d + "/c")) << "the device was opened";
  }
}

// --overwrite removed the files a user had put into an earlier output
// folder: it removes what pvbench wrote (the folder's .pvbench list) and
// refuses a folder holding anything else, naming it.
TEST(UserFiles, OverwriteKeepsAUsersFile) {
  const std::string d = fresh("overwrite");
  const std::string seq = recording("overwrite_seq", {});
  const std::string slam = "slam --sequence " + seq + " --settings " + test::shared_path("data/tum/TUM1.yaml") +
                           " --sync --no-dense --out " + d + "/out";
  ASSERT_EQ(test::run_pvbench(slam).code, 0);
  EXPECT_NE(read_file(d + "/out/.pvbench").find("\nfile stats.json\n"), std::string::npos);
  write_file(d + "/out/notes.txt", "the user's notes\n");
  expect_one_error(test::run_pvbench(slam + " --overwrite"),
                   d + "/out: the output folder holds notes.txt, which pvbench did not write");
  EXPECT_EQ(read_file(d + "/out/notes.txt"), "the user's notes\n");
  EXPECT_TRUE(fs::exists(d + "/out/stats.json")) << "removed before the refusal";
  fs::remove(d + "/out/notes.txt");
  const test::RunResult again = test::run_pvbench(slam + " --overwrite --dump-map --dump-matches");
  EXPECT_EQ(again.code, 0) << again.output;
  // Every file slam wrote is one the IoPlan refuses as --save-map.
  std::istringstream list(read_file(d + "/out/.pvbench"));
  int files = 0;
  for (std::string line; std::getline(list, line);) {
    if (line.rfind("file ", 0) != 0) continue;
    ++files;
    EXPECT_TRUE(is_written_name(line.substr(5), run::offline_slam_output_names())) << line;
  }
  EXPECT_GE(files, 6);
}

// A D435 with a disparity range as wide as its infrared image aborted
// (exit 134, an uncaught cv::Exception) and left a half-written folder.
TEST(UserFiles, ADisparityRangeAsWideAsTheImageIsOneLineAndNoFolder) {
  const std::string d = fresh("d435");
  for (const std::string& stereo : {std::string("ir_width: 32, ir_height: 32"), std::string("disparities: 64, ir_width: 32")}) {
    write_file(d + "/d435.yaml", "base: " + kStation + "\ncamera: {model: d435, stereo: {" + stereo + "}}\n");
    expect_one_error(test::run_pvbench("record --scenario " + d + "/d435.yaml --out " + d + "/rec --frames 2"),
                     d + "/d435.yaml:2: camera.stereo.");
    EXPECT_FALSE(fs::exists(d + "/rec"));
  }
}

// A fakenect dump takes a Kinect's 640x480 frames: a 320x240 scenario was
// named by its name: key, after an empty INDEX.txt had been written.
TEST(UserFiles, AFakenectDumpOfTheWrongSizeNamesTheFileAndWritesNothing) {
  const std::string d = fresh("fakenect");
  write_file(d + "/small.yaml", "name: tiny\nroute: {waypoints_m: [[0, 0], [5, 0]]}\n"
                                "camera: {width: 320, height: 240, fx: 262.5, fy: 262.5}\n");
  expect_one_error(
      test::run_pvbench("record --scenario " + d + "/small.yaml --format fakenect --out " + d + "/dump --frames 2"),
      d + "/small.yaml: camera.width/height: expected 640x480 for --format fakenect");
  EXPECT_FALSE(fs::exists(d + "/dump"));
}

// System.Sensors given a number said "expected a string (a file path, or
// none)": it names the setups it takes and what it got.
TEST(UserFiles, ASensorSetupThatIsNoStringNamesTheSetups) {
  const std::string d = fresh("sensors");
  write_file(d + "/settings.yaml", read_file(test::shared_path("data/tum/TUM1.yaml")) + "System.Sensors: 1\n");
  expect_one_error(test::run_pvbench("slam --sequence " + test::shared_path("data/tum/fr1_xyz_pair") +
                                     " --settings " + d + "/settings.yaml --out " + d + "/out"),
                   d + "/settings.yaml: System.Sensors: expected camera, camera+imu, camera+imu+wheels or "
                       "camera+accel, got 1");
}
