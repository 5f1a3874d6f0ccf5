// The tracker's local map: which of the keyframes observing a frame's
// points it keeps.
#include <gtest/gtest.h>

#include "pvb/slam/core/tracking.hpp"

namespace pvb::slam {
namespace tracking_test {

/// The ids of `shared` kept under least_shared_kept(shared, n), ascending.
std::vector<std::uint64_t> kept(const std::vector<std::pair<int, std::uint64_t>>& shared, int n) {
  const std::pair<int, std::uint64_t> least = least_shared_kept(shared, n);
  std::vector<std::uint64_t> ids;
  for (const auto& s : shared)
    if (s >= least) ids.push_back(s.second);
  std::sort(ids.begin(), ids.end());
  return ids;
}

TEST(LocalMap, KeepsTheKeyframesSharingTheMostPointsTheNewerOnTies) {
  // (points shared, keyframe id): 7 and 3 share the most, then 5, 2 and 9
  // share 20 each.
  const std::vector<std::pair<int, std::uint64_t>> shared{{20, 5}, {300, 7}, {20, 2}, {4, 1}, {250, 3}, {20, 9}};
  EXPECT_EQ(kept(shared, 2), (std::vector<std::uint64_t>{3, 7}));
  EXPECT_EQ(kept(shared, 3), (std::vector<std::uint64_t>{3, 7, 9}));     // the newest of the three tied
  EXPECT_EQ(kept(shared, 4), (std::vector<std::uint64_t>{3, 5, 7, 9}));
  EXPECT_EQ(kept(shared, 5), (std::vector<std::uint64_t>{2, 3, 5, 7, 9}));
  EXPECT_EQ(kept(shared, 6), (std::vector<std::uint64_t>{1, 2, 3, 5, 7, 9}));
  EXPECT_EQ(kept(shared, 60), (std::vector<std::uint64_t>{1, 2, 3, 5, 7, 9}));
  EXPECT_EQ(kept(shared, 0), (std::vector<std::uint64_t>{1, 2, 3, 5, 7, 9}));  // 0: no bound
  EXPECT_EQ(least_shared_kept({}, 3), (std::pair<int, std::uint64_t>{0, 0}));
}

TEST(LocalMap, TheBoundHoldsHoweverManyKeyframesSeeThePoints) {
  // An aisle's vanishing point: 900 keyframes share 12 points each, the 40
  // newest share 200: the 40 and the 20 newest of the rest are kept.
  std::vector<std::pair<int, std::uint64_t>> shared;
  for (std::uint64_t id = 0; id < 940; ++id) shared.emplace_back(id >= 900 ? 200 : 12, id);
  const std::vector<std::uint64_t> ids = kept(shared, 60);
  ASSERT_EQ(ids.size(), 60u);
  EXPECT_EQ(ids.front(), 880u);
  EXPECT_EQ(ids.back(), 939u);
}

}  // namespace tracking_test
}  // namespace pvb::slam
