// VoxelMap: the same voxels as voxel_filter(), and remove() undoes add()
// exactly whatever came in between.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>
#include <algorithm>

#include "pvb/common/error.hpp"
#include "pvb/slam/dense/voxel_map.hpp"

namespace {

using pvb::slam::dense::CloudPoint;
using pvb::slam::dense::PointCloud;
using pvb::slam::dense::VoxelMap;

PointCloud random_cloud(unsigned seed, std::size_t n, float offset_m) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-0.5f, 0.5f);
  std::uniform_int_distribution<int> col(0, 255);
  PointCloud c(n);
  for (CloudPoint& p : c)
    p = {pos(rng) + offset_m, pos(rng), pos(rng), static_cast<std::uint8_t>(col(rng)),
         static_cast<std::uint8_t>(col(rng)), static_cast<std::uint8_t>(col(rng))};
  return c;
}

TEST(VoxelMap, GivesTheVoxelsOfTheVoxelFilter) {
  const PointCloud cloud = random_cloud(1, 20000, 0.f);
  VoxelMap map(0.05);
  map.add(cloud);
  const PointCloud a = map.cloud();
  const PointCloud b = pvb::slam::dense::voxel_filter(cloud, 0.05);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(map.voxels(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    // same voxel order and means (micrometre sums against float sums)
    EXPECT_NEAR(a[i].x, b[i].x, 2e-6);
    EXPECT_NEAR(a[i].y, b[i].y, 2e-6);
    EXPECT_NEAR(a[i].z, b[i].z, 2e-6);
    EXPECT_NEAR(a[i].r, b[i].r, 1);
  }
}

TEST(VoxelMap, RemoveUndoesAddExactly) {
  const PointCloud a = random_cloud(2, 5000, 0.f), b = random_cloud(3, 5000, 0.3f);
  VoxelMap only_b(0.02);
  only_b.add(b);
  VoxelMap map(0.02);
  map.add(a);
  map.add(b);
  EXPECT_GT(map.voxels(), only_b.voxels());
  map.remove(a);
  EXPECT_EQ(map.voxels(), only_b.voxels());
  EXPECT_TRUE(map.cloud() == only_b.cloud());  // bit for bit
  map.add(a);                                  // back in: refills the emptied voxels
  map.remove(b);
  map.remove(a);
  EXPECT_EQ(map.voxels(), 0u);
  EXPECT_TRUE(map.cloud().empty());
  EXPECT_THROW(map.remove(random_cloud(4, 10, 0.f)), pvb::Error);  // points that were never added
}

TEST(VoxelMap, SkipsNonFinitePointsAndRefusesABadLeaf) {
  VoxelMap map(0.02);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  map.add({{nan, 0, 0, 1, 2, 3}, {0.011f, 0.001f, 0.001f, 10, 20, 30}});
  ASSERT_EQ(map.voxels(), 1u);
  EXPECT_FLOAT_EQ(map.cloud()[0].x, 0.011f);
  EXPECT_THROW(VoxelMap(0.0), pvb::Error);
  EXPECT_THROW(map.add({{1e5f, 0, 0, 0, 0, 0}}), pvb::Error);  // 5e6 voxels out: beyond the key range
}

/// A walk along x: each step a cloud 0.5 m further on, so that older
/// blocks fall behind the robot.
std::vector<PointCloud> walk(int steps) {
  std::vector<PointCloud> clouds;
  for (int i = 0; i < steps; ++i) clouds.push_back(random_cloud(100 + i, 3000, 0.5f * i));
  return clouds;
}

TEST(VoxelMap, ABudgetSpillsBlocksAndGivesTheSameMapBitForBit) {
  const std::vector<PointCloud> clouds = walk(40);
  VoxelMap unbounded(0.02);
  pvb::slam::dense::SpillOptions spill;
  spill.budget_bytes = 400 * 1024;
  VoxelMap bounded(0.02, spill);
  std::size_t peak = 0;
  for (const PointCloud& c : clouds) {
    unbounded.add(c);
    bounded.add(c);
    peak = std::max(peak, bounded.spill_stats().resident_bytes);
  }
  // The robot comes back: the first clouds leave and enter again (read back).
  for (int i = 0; i < 5; ++i) {
    const PointCloud moved = random_cloud(100 + i, 3000, 0.5f * i + 0.003f);
    for (VoxelMap* m : {&unbounded, &bounded}) m->remove(clouds[i]), m->add(moved);
  }
  const pvb::slam::dense::SpillStats st = bounded.spill_stats();
  EXPECT_GT(st.writes, 0u);
  EXPECT_GT(st.reads, 0u);
  EXPECT_GT(st.disk_bytes, 0u);
  EXPECT_LT(peak, 2 * spill.budget_bytes);               // the index and the call's own blocks on top
  EXPECT_GT(unbounded.memory_bytes(), 4 * spill.budget_bytes);  // the budget did bind
  EXPECT_EQ(bounded.voxels(), unbounded.voxels());
  EXPECT_TRUE(bounded.cloud() == unbounded.cloud());
  PointCloud slabs;
  std::size_t pieces = 0;
  bounded.for_each_slab([&](const PointCloud& s) { pvb::slam::dense::append(slabs, s), ++pieces; });
  EXPECT_GT(pieces, 10u);
  EXPECT_TRUE(slabs == unbounded.cloud());
}

TEST(VoxelMap, SpilledSumsComeBackExactlyFarFromTheOrigin) {
  // Sums far from the origin and at negative indices: the spilled record
  // keeps them relative to the voxel centre, and must give them back exactly.
  pvb::slam::dense::SpillOptions spill;
  spill.budget_bytes = 1;  // everything spills after every call
  VoxelMap bounded(0.02, spill), unbounded(0.02);
  for (float x : {-20000.f, -3.3f, 0.f, 7.1f, 20000.f}) {
    const PointCloud c = random_cloud(7, 500, x);
    bounded.add(c), unbounded.add(c), bounded.add(c), unbounded.add(c);
  }
  EXPECT_EQ(bounded.spill_stats().resident_bytes, bounded.memory_bytes());
  EXPECT_TRUE(bounded.cloud() == unbounded.cloud());
}

}  // namespace
