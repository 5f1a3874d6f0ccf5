#include <gtest/gtest.h>

#include <string>

#include "pvb/common/error.hpp"
#include "pvb/suite/seeds.hpp"

using pvb::suite::parse_seed_list;
using Seeds = std::vector<std::uint64_t>;

namespace {
std::string error_of(const std::string& text, std::size_t max_seeds = 100000) {
  try {
    parse_seed_list(text, "--seeds", max_seeds);
  } catch (const pvb::ConfigError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(SeedList, RangesListsAndMixtures) {
  EXPECT_EQ(parse_seed_list("1-5"), (Seeds{1, 2, 3, 4, 5}));
  EXPECT_EQ(parse_seed_list("1,3,5"), (Seeds{1, 3, 5}));
  EXPECT_EQ(parse_seed_list("1-3,9"), (Seeds{1, 2, 3, 9}));
  EXPECT_EQ(parse_seed_list("7"), (Seeds{7}));
  EXPECT_EQ(parse_seed_list("0-0"), (Seeds{0}));
  EXPECT_EQ(parse_seed_list(" 4 , 2-3 "), (Seeds{4, 2, 3}));  // order kept, spaces allowed
  EXPECT_EQ(parse_seed_list("1-20").size(), 20u);
  EXPECT_EQ(parse_seed_list("18446744073709551615"), (Seeds{18446744073709551615ull}));
}

TEST(SeedList, ClearErrors) {
  EXPECT_EQ(error_of(""),
            "command line: --seeds: expected a seed list like 1-20, 1,3,5 or 1-5,9, got an empty list");
  EXPECT_EQ(
      error_of("1,,3"),
      "command line: --seeds: expected a seed list like 1-20, 1,3,5 or 1-5,9 (an empty item), got 1,,3");
  EXPECT_EQ(error_of("a-3"),
            "command line: --seeds: expected a seed list like 1-20, 1,3,5 or 1-5,9, got 'a-3'");
  EXPECT_EQ(error_of("-3"),
            "command line: --seeds: expected a seed list like 1-20, 1,3,5 or 1-5,9, got '-3'");
  EXPECT_EQ(error_of("1-2-3"),
            "command line: --seeds: expected a seed list like 1-20, 1,3,5 or 1-5,9, got '1-2-3'");
  EXPECT_EQ(
      error_of("18446744073709551616"),
      "command line: --seeds: expected a seed list like 1-20, 1,3,5 or 1-5,9, got '18446744073709551616'");
  EXPECT_EQ(error_of("1.5"),
            "command line: --seeds: expected a seed list like 1-20, 1,3,5 or 1-5,9, got '1.5'");
  EXPECT_EQ(error_of("5-1"), "command line: --seeds: expected a range a-b with a <= b, got '5-1'");
  EXPECT_EQ(error_of("1-3,2"), "command line: --seeds: expected each seed once, got seed 2 twice");
  EXPECT_EQ(error_of("1-11", 10), "command line: --seeds: expected at most 10 seeds, got 1-11");
  EXPECT_EQ(error_of("1-5,6-11", 10), "command line: --seeds: expected at most 10 seeds, got 1-5,6-11");
  EXPECT_EQ(error_of("0-18446744073709551615"),
            "command line: --seeds: expected at most 100000 seeds, got 0-18446744073709551615");
}
