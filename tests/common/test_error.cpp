#include <gtest/gtest.h>

#include "pvb/common/error.hpp"

TEST(Error, ConfigErrorNamesFileKeyAndExpectation) {
  const pvb::ConfigError e("a.yaml", "camera.fx", "a number > 0", "-3");
  EXPECT_STREQ(e.what(), "a.yaml: camera.fx: expected a number > 0, got -3");
  EXPECT_EQ(e.key(), "camera.fx");
}

TEST(Error, IoErrorNamesFileAndLine) {
  const pvb::IoError e("traj.txt", "expected 8 numbers", 12);
  EXPECT_STREQ(e.what(), "traj.txt:12: expected 8 numbers");
  const pvb::IoError e2("x.png", "cannot read");
  EXPECT_STREQ(e2.what(), "x.png: cannot read");
}

TEST(Error, ConfigErrorWithoutAKeyHasNoEmptyField) {
  const pvb::ConfigError e("command line", "", "a seed list");
  EXPECT_STREQ(e.what(), "command line: expected a seed list");
}
