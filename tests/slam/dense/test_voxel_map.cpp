// VoxelMap: the same voxels as voxel_filter(), and remove() undoes add()
// exactly whatever came in between.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

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
  const VoxelMap::Handle ha = map.add(a);
  const VoxelMap::Handle hb = map.add(b);
  EXPECT_GT(map.voxels(), only_b.voxels());
  map.remove(a, ha);
  EXPECT_EQ(map.voxels(), only_b.voxels());
  EXPECT_TRUE(map.cloud() == only_b.cloud());  // bit for bit
  const VoxelMap::Handle ha2 = map.add(a);     // back in: refills the emptied voxels
  map.remove(b, hb);
  map.remove(a, ha2);
  EXPECT_EQ(map.voxels(), 0u);
  EXPECT_TRUE(map.cloud().empty());
  EXPECT_THROW(map.remove(random_cloud(4, 10, 0.f), hb), pvb::Error);  // a handle of another cloud
}

TEST(VoxelMap, SkipsNonFinitePointsAndRefusesABadLeaf) {
  VoxelMap map(0.02);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const VoxelMap::Handle h = map.add({{nan, 0, 0, 1, 2, 3}, {0.011f, 0.001f, 0.001f, 10, 20, 30}});
  EXPECT_EQ(h[0], VoxelMap::kNoCell);
  ASSERT_EQ(map.voxels(), 1u);
  EXPECT_FLOAT_EQ(map.cloud()[0].x, 0.011f);
  EXPECT_THROW(VoxelMap(0.0), pvb::Error);
  EXPECT_THROW(map.add({{1e5f, 0, 0, 0, 0, 0}}), pvb::Error);  // 5e6 voxels out: beyond the key range
}

}  // namespace
