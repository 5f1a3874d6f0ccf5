// Files written as a run goes, and whole files written through a temporary:
// a write that fails (a full disk, played by a file size limit) is an error
// naming the file at once, and leaves no half-written line or file behind.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

#include "file_size_limit.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/text.hpp"

using namespace pvb;

namespace {

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "pvb_output_file_" + name + "_" + std::to_string(::getpid());
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const IoError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(OutputFile, AppendsAreWrittenAtOnce) {
  const std::string path = temp_path("append");
  OutputFile f(path);
  f.append("line 1\n");
  EXPECT_EQ(read_file(path), "line 1\n");  // before close: nothing waits in a buffer
  f.append("line 2\n");
  f.close();
  EXPECT_EQ(read_file(path), "line 1\nline 2\n");
  EXPECT_EQ(f.size(), 14);
  std::filesystem::remove(path);
}

TEST(OutputFile, OpenFailureNamesTheFile) {
  const std::string path = temp_path("missing_dir") + "/sub/file.txt";
  EXPECT_NE(error_of([&] { OutputFile f(path); }).find(path + ": cannot open for writing"),
            std::string::npos);
}

TEST(OutputFile, FullDiskIsAnErrorNamingTheFileAndKeepsWholeLines) {
  const std::string path = temp_path("full");
  OutputFile f(path);
  std::string err;
  {
    const test::FileSizeLimit limit(100);
    f.append(std::string(59, 'a') + "\n");
    err = error_of([&] { f.append(std::string(59, 'b') + "\n"); });
  }
  EXPECT_EQ(err, path + ": write failed: File too large");
  // Cut back to the last whole append, and still usable once there is room.
  EXPECT_EQ(read_file(path), std::string(59, 'a') + "\n");
  f.append("c\n");
  EXPECT_EQ(read_file(path), std::string(59, 'a') + "\nc\n");
  std::filesystem::remove(path);
}

TEST(OutputFile, DevFullReportsNoSpace) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  OutputFile f("/dev/full");
  EXPECT_EQ(error_of([&] { f.append("x\n"); }), "/dev/full: write failed: No space left on device");
}

TEST(WriteFile, FullDiskLeavesTheOldFileAndNoTemporary) {
  const std::string path = temp_path("whole");
  write_file(path, "old content\n");
  std::string err;
  {
    const test::FileSizeLimit limit(1000);
    err = error_of([&] { write_file(path, std::string(5000, 'x')); });
  }
  EXPECT_EQ(err, path + ": write failed: File too large");
  EXPECT_EQ(read_file(path), "old content\n");
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  std::filesystem::remove(path);
}

TEST(WriteFile, NewFileIsNotCreatedWhenTheWriteFails) {
  const std::string path = temp_path("new");
  std::filesystem::remove(path);
  {
    const test::FileSizeLimit limit(1000);
    EXPECT_NE(error_of([&] { write_file(path, std::string(5000, 'x')); }), "(no error)");
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}
