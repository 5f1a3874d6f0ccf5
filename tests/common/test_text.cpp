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

TEST(Text, NumberFormatting) {
  EXPECT_EQ(pvb::format_number("%.2f mm", 3.14159), "3.14 mm");
  EXPECT_EQ(pvb::format_number("%+.1f", 2.0), "+2.0");
  EXPECT_EQ(pvb::format_g(0.0123456789), "0.0123457");
  EXPECT_EQ(pvb::format_g(1234567.0, 3), "1.23e+06");
  EXPECT_EQ(pvb::format_fixed(2.5, 2), "2.50");
  EXPECT_EQ(pvb::format_fixed(-0.004, 2), "-0.00");
  // The largest double in %f has 309 digits: nothing is cut.
  EXPECT_EQ(pvb::format_fixed(1e308, 1).size(), 311u);
}
