// Where a recording may be written (no OpenNI2): the refusal to record
// onto a file of the run (through links and spellings), and
// the creation of a new file, refused wherever OpenNI2's recorder would
// crash (under a regular file, in a missing folder) or overwrite something.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/openni/record_target.hpp"

using namespace pvb::openni;

namespace {

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_rectarget_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + d + " && mkdir -p " + d).c_str());
  return d;
}

// The message create_new_recording_file gives for `path`, or "" when it created the file.
std::string create_error(const std::string& path) {
  try {
    create_new_recording_file(path);
  } catch (const pvb::IoError& e) {
    return e.what();
  }
  return "";
}

bool exists(const std::string& path) { return ::access(path.c_str(), F_OK) == 0; }

}  // namespace

TEST(RecordTarget, RecordingOntoAFileOfTheRunIsRefusedNamingIt) {
  const std::string d = fresh("inputs");
  pvb::write_file(d + "/in.oni", "recording");
  ASSERT_EQ(::symlink("in.oni", (d + "/link.oni").c_str()), 0);
  try {
    check_record_not_on(d + "/link.oni", {{"", "nothing"}, {d + "/in.oni", "the --oni recording"}});
    ADD_FAILURE() << "not refused";
  } catch (const pvb::IoError& e) {
    EXPECT_EQ(std::string(e.what()),
              d + "/link.oni: is the --oni recording (" + d + "/in.oni); record to a new file");
  }
  // an output that does not exist yet
  EXPECT_THROW(check_record_not_on(d + "/out/stats.json", {{d + "/out/./stats.json", "an output"}}),
               pvb::IoError);
  EXPECT_NO_THROW(
      check_record_not_on(d + "/new.oni", {{d + "/in.oni", "the --oni recording"}, {"", "none"}}));
  EXPECT_EQ(pvb::read_file(d + "/in.oni"), "recording");
}

TEST(RecordTarget, NewFileIsCreatedEmpty) {
  const std::string d = fresh("new");
  EXPECT_EQ(create_error(d + "/run.oni"), "");
  EXPECT_EQ(pvb::read_file(d + "/run.oni"), "");
}

TEST(RecordTarget, PathsOpenNi2CannotWriteAreOneLineEach) {
  const std::string d = fresh("bad");
  pvb::write_file(d + "/plain", "x");
  EXPECT_EQ(create_error(d + "/plain/run.oni"),
            d + "/plain/run.oni: cannot record: " + d + "/plain is not a folder");
  EXPECT_EQ(create_error(d + "/missing/run.oni"),
            d + "/missing/run.oni: cannot record: the folder " + d + "/missing does not exist");
  EXPECT_EQ(create_error(d), d + ": is a folder; --record takes the path of a new .oni file");
  EXPECT_EQ(create_error(d + "/"), d + "/: is a folder; --record takes the path of a new .oni file");
  EXPECT_FALSE(exists(d + "/missing"));
}

TEST(RecordTarget, AnExistingFileOrLinkIsNeverReplaced) {
  const std::string d = fresh("exists");
  pvb::write_file(d + "/old.oni", "keep me");
  EXPECT_EQ(
      create_error(d + "/old.oni"),
      d + "/old.oni: already exists; a recording never replaces a file (remove it or record to a new name)");
  EXPECT_EQ(pvb::read_file(d + "/old.oni"), "keep me");
  // a link is not followed, not even a dangling one
  ASSERT_EQ(::symlink("old.oni", (d + "/link.oni").c_str()), 0);
  EXPECT_NE(create_error(d + "/link.oni").find("already exists"), std::string::npos);
  ASSERT_EQ(::symlink("target.oni", (d + "/dangling.oni").c_str()), 0);
  EXPECT_NE(create_error(d + "/dangling.oni").find("already exists"), std::string::npos);
  EXPECT_FALSE(exists(d + "/target.oni"));
  EXPECT_EQ(pvb::read_file(d + "/old.oni"), "keep me");
}
