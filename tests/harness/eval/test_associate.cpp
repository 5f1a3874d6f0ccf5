#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "pvb/eval/associate.hpp"

using namespace pvb;
using namespace pvb::eval;

namespace {
Trajectory stamps(const std::vector<std::int64_t>& t_ns, const std::string& name) {
  Trajectory t;
  t.source = name;
  for (std::int64_t s : t_ns) t.poses.push_back({s, geom::SE3d::Identity()});
  return t;
}
constexpr std::int64_t kMs = 1000000;
}  // namespace

TEST(Associate, JitterAndMissingPoses) {
  // Ground truth at 30 Hz-ish, estimate with +-5 ms jitter and frames 3 and 7 missing.
  std::vector<std::int64_t> g, e;
  for (int i = 0; i < 10; ++i) g.push_back(1000 * kMs + i * 33 * kMs);
  for (int i = 0; i < 10; ++i)
    if (i != 3 && i != 7) e.push_back(g[i] + ((i % 2) ? 5 : -4) * kMs);
  const auto pairs = associate(stamps(g, "gt"), stamps(e, "est"));
  ASSERT_EQ(pairs.size(), 8u);
  std::size_t k = 0;
  for (int i = 0; i < 10; ++i) {
    if (i == 3 || i == 7) continue;
    EXPECT_EQ(pairs[k].gt, static_cast<std::size_t>(i));
    EXPECT_EQ(pairs[k].est, k);
    ++k;
  }
}

TEST(Associate, ClosestFirstAndOneToOne) {
  // Two estimates compete for gt 100 ms; the closer (103) wins, the other (110)
  // takes the remaining candidate 120 (10 ms) even though 100 was closer to it.
  const auto pairs = associate(stamps({100 * kMs, 120 * kMs}, "gt"), stamps({103 * kMs, 110 * kMs}, "est"));
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].gt, 0u);
  EXPECT_EQ(pairs[0].est, 0u);
  EXPECT_EQ(pairs[1].gt, 1u);
  EXPECT_EQ(pairs[1].est, 1u);
  // Strictly below max_diff: 20 ms apart does not associate at 0.02 s.
  EXPECT_TRUE(associate(stamps({100 * kMs}, "gt"), stamps({120 * kMs}, "est")).empty());
  EXPECT_EQ(associate(stamps({100 * kMs}, "gt"), stamps({119 * kMs}, "est")).size(), 1u);
}

TEST(Associate, TimeOffset) {
  std::vector<std::int64_t> g, e;
  for (int i = 0; i < 20; ++i) {
    g.push_back(5000 * kMs + i * 50 * kMs);
    e.push_back(i * 50 * kMs + 2 * kMs);  // estimate clock starts at 0
  }
  EXPECT_TRUE(associate(stamps(g, "gt"), stamps(e, "est")).empty());
  AssociationOptions o;
  o.offset_s = 5.0;
  const auto pairs = associate(stamps(g, "gt"), stamps(e, "est"), o);
  ASSERT_EQ(pairs.size(), 20u);
  for (std::size_t i = 0; i < pairs.size(); ++i) EXPECT_EQ(pairs[i].gt, pairs[i].est);
}

TEST(Associate, NoOverlapErrorGivesRangesAndHints) {
  try {
    associate_or_throw(stamps({1000 * kMs, 2000 * kMs}, "gt.txt"), stamps({9000 * kMs, 9500 * kMs}, "est.txt"));
    FAIL() << "no error";
  } catch (const EvalError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("[1.000000, 2.000000]"), std::string::npos) << msg;
    EXPECT_NE(msg.find("[9.000000, 9.500000]"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--offset"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--max-diff"), std::string::npos) << msg;
  }
}

// Times near the end of int64 with an offset: the sum saturates instead of
// wrapping round to a time that would pair with a negative ground truth.
TEST(Associate, OffsetSumsDoNotWrap) {
  const std::int64_t t_est = 9'000'000'000'000'000'000;  // 9e9 s
  const std::int64_t offset = 9'000'000'000'000'000'000;
  const std::int64_t wrapped =
      static_cast<std::int64_t>(static_cast<std::uint64_t>(t_est) + static_cast<std::uint64_t>(offset));
  AssociationOptions o;
  o.offset_s = 9e9;
  EXPECT_TRUE(associate(stamps({wrapped}, "gt"), stamps({t_est}, "est"), o).empty());
  EXPECT_TRUE(
      associate(stamps({std::numeric_limits<std::int64_t>::max() - 5 * kMs}, "gt"), stamps({t_est}, "est"), o)
          .empty());
}

TEST(Associate, WindowOutOfRangeIsAnError) {
  const Trajectory a = stamps({0, 33 * kMs}, "a");
  for (const double bad : {0.0, -1.0, 2e9, std::nan("")}) {
    AssociationOptions o;
    o.max_diff_s = bad;
    EXPECT_THROW(associate(a, a, o), EvalError) << bad;
  }
  AssociationOptions o;
  o.offset_s = 1e300;
  EXPECT_THROW(associate(a, a, o), EvalError);
}
