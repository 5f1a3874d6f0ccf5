// Outputs that never land on inputs (io_paths.hpp), output folders that one
// process at a time writes (output_folder.hpp), and the temporary files of
// killed writes cleaned at the next write of the same file.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/io_paths.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"

using namespace pvb;
namespace fs = std::filesystem;

namespace {

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_io_paths_" + name + "_" + std::to_string(::getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// A process id that no longer exists (a child that ended and was reaped).
pid_t gone_pid() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  waitpid(pid, nullptr, 0);
  return pid;
}

}  // namespace

TEST(SameFile, ThroughLinksAndSpellings) {
  const std::string d = fresh("same");
  write_file(d + "/a.txt", "a");
  write_file(d + "/b.txt", "b");
  ASSERT_EQ(::symlink("a.txt", (d + "/link.txt").c_str()), 0);
  ASSERT_EQ(::link((d + "/a.txt").c_str(), (d + "/hard.txt").c_str()), 0);
  EXPECT_TRUE(same_file(d + "/a.txt", d + "/link.txt"));
  EXPECT_TRUE(same_file(d + "/a.txt", d + "/hard.txt"));
  EXPECT_TRUE(same_file(d + "/./a.txt", d + "/../" + d.substr(d.rfind('/') + 1) + "/a.txt"));
  EXPECT_FALSE(same_file(d + "/a.txt", d + "/b.txt"));
  // paths that do not exist yet compare by their canonical form
  EXPECT_TRUE(same_file(d + "/new.txt", d + "/./new.txt"));
  EXPECT_FALSE(same_file(d + "/new.txt", d + "/other.txt"));
  EXPECT_FALSE(same_file(d + "/new.txt", d + "/a.txt"));
}

TEST(IsInside, AFolderHoldsWhatLiesBelowIt) {
  const std::string d = fresh("inside");
  fs::create_directories(d + "/out/sub");
  ASSERT_EQ(::symlink("out", (d + "/alias").c_str()), 0);
  EXPECT_TRUE(is_inside(d + "/out/sub/x.yaml", d + "/out"));
  EXPECT_TRUE(is_inside(d + "/out", d + "/out/"));
  EXPECT_TRUE(is_inside(d + "/alias/x.yaml", d + "/out"));
  EXPECT_FALSE(is_inside(d + "/outside.yaml", d + "/out"));
  EXPECT_FALSE(is_inside(d + "/out2/x", d + "/out"));
}

TEST(IoPlan, AnOutputThatIsAnInputIsRefusedNamingBoth) {
  const std::string d = fresh("plan");
  write_file(d + "/scene.yaml", "name: x\n");
  ASSERT_EQ(::symlink("scene.yaml", (d + "/link.yaml").c_str()), 0);
  IoPlan plan;
  plan.input("the --scenario file", d + "/scene.yaml").output_file("--save-map", d + "/link.yaml");
  EXPECT_EQ(message_of([&] { plan.check(); }),
            d + "/link.yaml: is the --scenario file (" + d +
                "/scene.yaml), an input of this command; give --save-map another path");
  EXPECT_EQ(read_file(d + "/scene.yaml"), "name: x\n");
  // another file of the same folder is fine
  IoPlan other;
  other.input("the --scenario file", d + "/scene.yaml").output_file("--save-map", d + "/map.pvbmap");
  EXPECT_EQ(message_of([&] { other.check(); }), "");
}

TEST(IoPlan, AnInputInsideAnExistingOutputFolderIsRefused) {
  const std::string d = fresh("folder");
  fs::create_directories(d + "/out");
  write_file(d + "/out/map.pvbmap", "m");
  IoPlan plan;
  plan.input("the --map file", d + "/out/map.pvbmap").output_folder("--out", d + "/out");
  EXPECT_EQ(message_of([&] { plan.check(); }),
            d + "/out: the --out folder holds the --map file (" + d +
                "/out/map.pvbmap), an input of this command, which --overwrite "
                "would remove; give --out another folder");
  IoPlan fresh_folder;
  fresh_folder.input("the --map file", d + "/out/map.pvbmap").output_folder("--out", d + "/new");
  EXPECT_EQ(message_of([&] { fresh_folder.check(); }), "");
}

TEST(IoPlan, TwoOutputsOnOneFileAreRefused) {
  const std::string d = fresh("twice");
  IoPlan plan;
  plan.output_file("--json", d + "/x").output_file("--plot", d + "/./x");
  EXPECT_TRUE(contains(message_of([&] { plan.check(); }), "--json and --plot name the same file"));
}

TEST(IoPlan, AnOutputFileMustGoIntoAnExistingFolderOrAnOutputFolder) {
  const std::string d = fresh("place");
  write_file(d + "/file", "f");
  fs::create_directories(d + "/dir");
  const auto check_one = [&](const std::string& path) {
    return message_of([&] { IoPlan().output_file("--save-map", path).check(); });
  };
  EXPECT_TRUE(contains(check_one(d + "/missing/map.pvbmap"), "the folder " + d + "/missing does not exist"));
  EXPECT_TRUE(contains(check_one(d + "/file/map.pvbmap"), d + "/file is not a folder"));
  EXPECT_TRUE(contains(check_one(d + "/dir"), "the --save-map output is a folder"));
  EXPECT_EQ(check_one(d + "/dir/map.pvbmap"), "");
  EXPECT_EQ(check_one("/dev/null"), "");
  // inside an output folder the command creates
  IoPlan in_out;
  in_out.output_folder("--out", d + "/new").output_file("--save-map", d + "/new/map.pvbmap");
  EXPECT_EQ(message_of([&] { in_out.check(); }), "");
}

TEST(IoPlan, StreamsAreNeverComparedWithInputs) {
  IoPlan plan;
  plan.input("the --gt trajectory", "/dev/null").output_file("--json", "/dev/null");
  EXPECT_EQ(message_of([&] { plan.check(); }), "");
}

TEST(OutputFolder, AFolderAnotherProcessWritesIsRefusedUntilItEnds) {
  const std::string d = fresh("lock") + "/out";
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = fork();
  if (child == 0) {
    prepare_output_folder(d, false, "test");
    (void)!::write(ready[1], "x", 1);
    ::pause();
    _exit(0);
  }
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1);
  const std::string busy = message_of([&] { prepare_output_folder(d, true, "test"); });
  EXPECT_TRUE(contains(busy, "another pvbench process is writing this output folder")) << busy;
  EXPECT_TRUE(contains(message_of([&] { check_output_folder(d, true); }), "another pvbench process")) << busy;
  ::kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  EXPECT_EQ(message_of([&] { prepare_output_folder(d, true, "test"); }), "");
  // this process holds it now, and may prepare it again
  EXPECT_EQ(message_of([&] { check_output_folder(d, true); }), "");
  EXPECT_EQ(message_of([&] { prepare_output_folder(d, true, "test"); }), "");
  ::close(ready[0]);
  ::close(ready[1]);
}

TEST(WriteFile, TemporaryFilesOfAKilledWriteAreRemovedAtTheNextWrite) {
  const std::string d = fresh("stale");
  const std::string target = d + "/map.pvbmap";
  const std::string stale = target + ".tmp." + std::to_string(gone_pid()) + ".0";
  const std::string live = target + ".tmp." + std::to_string(::getppid()) + ".3";  // a process that runs
  const std::string other = d + "/other.pvbmap.tmp." + std::to_string(gone_pid()) + ".0";
  const std::string lookalike = target + ".tmp.notapid.0";
  for (const std::string& f : {stale, live, other, lookalike}) write_file(f, "partial");
  write_file(target, "whole");
  EXPECT_EQ(read_file(target), "whole");
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(other));
  EXPECT_TRUE(fs::exists(lookalike));
}
