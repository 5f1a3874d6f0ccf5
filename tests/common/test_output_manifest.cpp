// What pvbench wrote into its output folders (the .pvbench list), what
// --overwrite removes by it, the outputs a command must never write twice
// (reserve_output), and the IoPlan's checks of outputs against the folders
// the command reads as recordings and the files it writes itself.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/io_paths.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"

using namespace pvb;
namespace fs = std::filesystem;

namespace {

std::string manifest_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_manifest_" + name + "_" + std::to_string(::getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

/// The error `fn` throws, "" when none.
template <typename Fn>
std::string thrown_by(Fn fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

/// A file written by hand, as a user would (not through pvbench's writers).
void users_file(const std::string& path) { std::ofstream(path) << "the user's\n"; }

bool has(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

}  // namespace

// The list names every file written below the folder, relative to it; a
// file no list names (one a user added, in a sub-folder too) refuses the
// folder with one line naming it, and nothing is removed.
TEST(OutputManifest, OverwriteRemovesOnlyWhatTheListNames) {
  const std::string d = manifest_dir("only") + "/out";
  prepare_output_folder(d, false, "test");
  write_file(d + "/stats.json", "{}\n");
  fs::create_directories(d + "/imu0");
  OutputFile(d + "/imu0/data.csv").append("t\n");
  const std::string list = read_file(d + "/.pvbench");
  EXPECT_TRUE(has(list, "\nfile stats.json\n")) << list;
  EXPECT_TRUE(has(list, "\nfile imu0/data.csv\n")) << list;

  users_file(d + "/imu0/notes.txt");
  const std::string refused = thrown_by([&] { prepare_output_folder(d, true, "test"); });
  EXPECT_TRUE(has(refused, d + ": the output folder holds imu0/notes.txt, which pvbench did not write")) << refused;
  EXPECT_TRUE(has(thrown_by([&] { check_output_folder(d, true); }), "imu0/notes.txt")) << refused;
  EXPECT_TRUE(fs::exists(d + "/stats.json"));
  EXPECT_EQ(read_file(d + "/imu0/notes.txt"), "the user's\n");

  fs::remove(d + "/imu0/notes.txt");
  EXPECT_EQ(thrown_by([&] { prepare_output_folder(d, true, "test"); }), "");
  EXPECT_FALSE(fs::exists(d + "/stats.json"));
  EXPECT_FALSE(fs::exists(d + "/imu0")) << "a folder left empty goes too";
  EXPECT_TRUE(fs::exists(d + "/.pvbench"));
}

// A folder below with a list of its own (a sweep's seed, written by its own
// process) is emptied by its list; a killed write's temporary file goes with
// the file it was for; an empty folder holds nothing to lose.
TEST(OutputManifest, ListsOfFoldersBelowAndTemporaryFilesCount) {
  const std::string d = manifest_dir("nested") + "/out";
  prepare_output_folder(d, false, "test");
  write_file(d + "/aggregate.md", "# sweep\n");
  fs::create_directories(d + "/seed_1/baseline");
  std::ofstream(d + "/seed_1/.pvbench") << "written by pvbench run\nfile metrics.json\nfile baseline/timing.csv\n";
  users_file(d + "/seed_1/metrics.json");
  users_file(d + "/seed_1/baseline/timing.csv");
  users_file(d + "/aggregate.md.tmp.4194305.0");
  fs::create_directories(d + "/empty");
  EXPECT_EQ(thrown_by([&] { prepare_output_folder(d, true, "test"); }), "");
  for (const char* gone : {"aggregate.md", "seed_1", "aggregate.md.tmp.4194305.0", "empty"})
    EXPECT_FALSE(fs::exists(d + "/" + gone)) << gone;
  // A look-alike of a temporary name is no temporary file.
  write_file(d + "/aggregate.md", "# sweep\n");
  users_file(d + "/aggregate.md.tmp.x.0");
  EXPECT_TRUE(has(thrown_by([&] { prepare_output_folder(d, true, "test"); }), "holds aggregate.md.tmp.x.0"));
}

// A folder pvbench made before it kept lists (its marker names no file) is
// not emptied: every file in it is unknown.
TEST(OutputManifest, AMarkerWithoutAListEmptiesNothing) {
  const std::string d = manifest_dir("old");
  std::ofstream(d + "/.pvbench") << "written by pvbench run 0.1.0\n";
  users_file(d + "/CameraTrajectory.txt");
  EXPECT_TRUE(has(thrown_by([&] { check_output_folder(d, true); }), "holds CameraTrajectory.txt, which pvbench"));
  EXPECT_TRUE(fs::exists(d + "/CameraTrajectory.txt"));
}

// A failed command says so at the end of each list it began.
TEST(OutputManifest, AFailedCommandEndsItsListsWithTheError) {
  const std::string d = manifest_dir("failed") + "/out";
  prepare_output_folder(d, false, "test");
  write_file(d + "/a.txt", "a\n");
  mark_output_folders_failed("boom: OpenCV(4.6.0) assertion");
  const std::string list = read_file(d + "/.pvbench");
  EXPECT_TRUE(has(list, "file a.txt\nfailed: boom: OpenCV(4.6.0) assertion\n")) << list;
}

// A path reserved for one output (--save-map) is written once: another
// output of the command on it is refused, and the first one stays.
TEST(OutputManifest, AReservedOutputIsNeverWrittenTwice) {
  const std::string d = manifest_dir("reserved");
  reserve_output(d + "/map.pvbmap", "--save-map");
  write_file(d + "/./map.pvbmap", "the map");
  const std::string again = thrown_by([&] { write_file(d + "/map.pvbmap", "stats"); });
  EXPECT_TRUE(has(again, "map.pvbmap: is the --save-map file, and this command writes it as another of its "
                         "outputs too"))
      << again;
  EXPECT_TRUE(has(thrown_by([&] { OutputFile f(d + "/map.pvbmap"); }), "is the --save-map file")) << again;
  EXPECT_EQ(read_file(d + "/map.pvbmap"), "the map");
  EXPECT_EQ(thrown_by([&] { write_file(d + "/other.txt", "x"); write_file(d + "/other.txt", "y"); }), "");
}

// A folder read as a recording takes no output, whatever file it names
// (odom.txt, robot.yaml, imu0/truth.csv: files no list of inputs names),
// nor an output folder; and no output may be a file the command writes
// into its own output folder.
TEST(IoPlanRecordings, NothingIsWrittenIntoARecordingNorOntoTheCommandsOwnOutputs) {
  const std::string d = manifest_dir("plan");
  fs::create_directories(d + "/seq/imu0");
  for (const char* f : {"odom.txt", "robot.yaml", "imu0/truth.csv", "scene.xml"}) {
    users_file(d + "/seq/" + f);
    IoPlan plan;
    plan.input_folder("the --sequence folder", d + "/seq").output_file("--save-map", d + "/seq/" + f);
    EXPECT_TRUE(has(thrown_by([&] { plan.check(); }),
                    d + "/seq/" + f + ": lies in the --sequence folder (" + d +
                        "/seq), a recording this command reads, and nothing is written into a recording; "
                        "give --save-map another path"))
        << f;
  }
  IoPlan new_file;
  new_file.input_folder("the --sequence folder", d + "/seq").output_file("--save-map", d + "/seq/new.pvbmap");
  EXPECT_TRUE(has(thrown_by([&] { new_file.check(); }), "lies in the --sequence folder")) << "a new file too";
  IoPlan folder;
  folder.input_folder("the --sequence folder", d + "/seq").output_folder("--out", d + "/seq/slam");
  EXPECT_TRUE(has(thrown_by([&] { folder.check(); }), "the --out folder lies in the --sequence folder"));

  const std::vector<std::string> writes = {"stats.json", "imu0/", "PointCloud*.ply", "*.png"};
  for (const char* f : {"stats.json", "imu0/data.csv", "PointCloud_live.ply", "ate.png"}) {
    IoPlan own;
    own.output_folder("--out", d + "/out", writes).output_file("--save-map", d + "/out/" + f);
    EXPECT_TRUE(has(thrown_by([&] { own.check(); }),
                    d + "/out/" + f + ": is " + f + " of the --out folder, which this command writes"))
        << f;
  }
  IoPlan fine;
  fine.output_folder("--out", d + "/out", writes).output_file("--save-map", d + "/out/noon.pvbmap");
  EXPECT_EQ(thrown_by([&] { fine.check(); }), "");
}

TEST(IoPlanRecordings, WrittenNamesAreNamesFoldersAndOneWildcard) {
  const std::vector<std::string> w = {"stats.json", "imu0/", "PointCloud*.ply", "*.svg"};
  for (const char* yes : {"stats.json", "imu0/data.csv", "imu0", "PointCloud.ply", "PointCloud_live.ply", "x.svg"})
    EXPECT_TRUE(is_written_name(yes, w)) << yes;
  for (const char* no : {"stats.json.bak", "imu00/x", "Cloud.ply", "sub/x.svg", "map.pvbmap", "PointCloud.plyx"})
    EXPECT_FALSE(is_written_name(no, w)) << no;
}
