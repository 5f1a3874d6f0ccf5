// Files written as a run goes, and whole files written through a temporary:
// a write that fails (a full disk, played by a file size limit) is an error
// naming the file at once, and leaves no half-written line or file behind.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <functional>
#include <string>
#include <thread>

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

/// True when no temporary file of `path` (PATH.tmp.*) is left beside it.
bool no_temporaries_of(const std::string& path) {
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(path).parent_path()))
    if (e.path().string().rfind(path + ".tmp", 0) == 0) return false;
  return true;
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
  EXPECT_TRUE(no_temporaries_of(path));
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
  EXPECT_TRUE(no_temporaries_of(path));
}

// Whole-file outputs never replace what is not a regular file: a device, a
// FIFO or a standard stream is written through, a symbolic link is followed
// to its target and stays a link, a folder is refused.
namespace {

struct stat lstat_of(const std::string& path) {
  struct stat st {};
  EXPECT_EQ(::lstat(path.c_str(), &st), 0) << path;
  return st;
}

}  // namespace

TEST(WriteFile, CharacterDeviceIsWrittenThroughNotReplaced) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  // /dev/full fails every write as a full disk does, and stays a device.
  EXPECT_EQ(error_of([&] { write_file("/dev/full", "{}\n"); }), "/dev/full: write failed: No space left on device");
  EXPECT_TRUE(S_ISCHR(lstat_of("/dev/full").st_mode));
  EXPECT_EQ(error_of([&] { write_file("/dev/null", "{}\n"); }), "(no error)");
  EXPECT_TRUE(S_ISCHR(lstat_of("/dev/null").st_mode));
}

TEST(WriteFile, FifoIsWrittenThroughAndStaysAFifo) {
  const std::string fifo = temp_path("fifo");
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] {  // read_file() takes regular files only
    std::ifstream in(fifo);
    got.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  });
  write_file(fifo, "through the pipe\n");
  reader.join();
  EXPECT_EQ(got, "through the pipe\n");
  EXPECT_TRUE(S_ISFIFO(lstat_of(fifo).st_mode));
  std::filesystem::remove(fifo);
}

TEST(WriteFile, SymbolicLinkIsFollowedAndStaysALink) {
  const std::string target = temp_path("link_target");
  const std::string link = temp_path("link");
  std::filesystem::remove(link);
  write_file(target, "old\n");
  std::filesystem::create_symlink(target, link);
  write_file(link, "new\n");
  EXPECT_TRUE(S_ISLNK(lstat_of(link).st_mode));
  EXPECT_EQ(read_file(target), "new\n");
  // A link to a file not yet there creates the file, and the link stays.
  std::filesystem::remove(target);
  write_file(link, "created\n");
  EXPECT_TRUE(S_ISLNK(lstat_of(link).st_mode));
  EXPECT_EQ(read_file(target), "created\n");
  std::filesystem::remove(link);
  std::filesystem::remove(target);
}

TEST(WriteFile, StandardOutputIsWrittenThroughItsDescriptor) {
  // In a child whose standard output is a file: /dev/stdout must append to
  // that open file, not truncate, replace or re-open it by name.
  const std::string log = temp_path("stdout");
  write_file(log, "");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_APPEND);
    if (fd < 0 || ::dup2(fd, STDOUT_FILENO) < 0) ::_exit(2);
    if (::write(STDOUT_FILENO, "before\n", 7) != 7) ::_exit(3);
    try {
      write_file("/dev/stdout", "report\n");
    } catch (...) {
      ::_exit(4);
    }
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_EQ(read_file(log), "before\nreport\n");
  std::filesystem::remove(log);
}

TEST(WriteFile, FolderIsRefused) {
  const std::string dir = temp_path("dir");
  std::filesystem::create_directories(dir);
  EXPECT_EQ(error_of([&] { write_file(dir, "x"); }),
            dir + ": is a folder; expected a regular file, a new file, a character device or a FIFO");
  EXPECT_TRUE(std::filesystem::is_directory(dir));
  std::filesystem::remove_all(dir);
}

TEST(WriteFile, ExistingTemporaryNameIsNeverOpened) {
  // Whatever lies beside the file under a temporary-looking name (here a
  // FIFO that would block an open for writing) is left alone.
  const std::string path = temp_path("beside");
  const std::string fifo = path + ".tmp";
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  write_file(path, "content\n");
  EXPECT_EQ(read_file(path), "content\n");
  EXPECT_TRUE(S_ISFIFO(lstat_of(fifo).st_mode));
  std::filesystem::remove(fifo);
  EXPECT_TRUE(no_temporaries_of(path));
  std::filesystem::remove(path);
}
