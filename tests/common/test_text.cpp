#include <gtest/gtest.h>

#include <cstdio>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

TEST(Text, SplitSkipsEmptyFields) {
  const auto f = pvb::split_ws("  1.0\t2  ,3 \r");
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0], "1.0");
  EXPECT_EQ(f[2], "3");
}

TEST(Text, JsonEscape) { EXPECT_EQ(pvb::json_escape("a\"b\\c\n"), "a\\\"b\\\\c\\n"); }

TEST(Text, WriteThenReadRoundTrips) {
  const std::string path = ::testing::TempDir() + "pvb_text_test.txt";
  pvb::write_file(path, "hello\n");
  EXPECT_EQ(pvb::read_file(path), "hello\n");
  std::remove(path.c_str());
  EXPECT_THROW(pvb::read_file(path), pvb::IoError);
}
