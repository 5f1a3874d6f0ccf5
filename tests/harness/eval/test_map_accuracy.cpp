// Map accuracy on synthetic surfaces: a map sampled from the surface itself
// scores 0 and 100 %, a map shifted by 1 cm scores 1 cm, half a map covers
// half the surface, a surface mapped twice is ghosting (between two merged
// maps when each drew one layer), and the per-class and per-range splits
// partition the points.
#include "pvb/eval/map_accuracy.hpp"

#include <gtest/gtest.h>

#include <random>

namespace {

using pvb::eval::MapPoint;
using pvb::eval::SurfacePoint;

constexpr int kPanel = 1, kWall = 2;

/// A horizontal 1 m x 1 m panel at z = 1 and a vertical 1 m x 1 m wall at
/// x = 3, sampled every 5 mm; ranges 1.5 m (panel) and 3.5 m (wall).
std::vector<SurfacePoint> two_surfaces() {
  std::vector<SurfacePoint> s;
  for (int i = 0; i < 200; ++i)
    for (int j = 0; j < 200; ++j) {
      s.push_back({Eigen::Vector3d(0.005 * i, 0.005 * j, 1.0), Eigen::Vector3d::UnitZ(), kPanel, 1.5});
      s.push_back({Eigen::Vector3d(3.0, 0.005 * i, 0.005 * j), Eigen::Vector3d::UnitX(), kWall, 3.5});
    }
  return s;
}

/// The surface's own points, moved by `offset_m` along their normals.
std::vector<MapPoint> map_from(const std::vector<SurfacePoint>& s, double offset_m, int every = 1) {
  std::vector<MapPoint> m;
  for (std::size_t i = 0; i < s.size(); i += static_cast<std::size_t>(every))
    m.push_back({s[i].p_w + offset_m * s[i].n_w, s[i].range_m});
  return m;
}

}  // namespace

TEST(MapAccuracy, TheSurfaceItselfIsPerfect) {
  const auto s = two_surfaces();
  const auto r = pvb::eval::evaluate_map(map_from(s, 0.0), s);
  EXPECT_LT(r.all.accuracy.median, 1e-9);
  EXPECT_LT(r.all.accuracy.p95, 1e-9);
  for (double c : r.all.completeness_at) EXPECT_DOUBLE_EQ(c, 1.0);
  for (double f : r.all.fscore_at) EXPECT_DOUBLE_EQ(f, 1.0);
  EXPECT_LT(r.all.chamfer_m, 1e-9);
  EXPECT_EQ(r.all.ghosting, 0.0);
  EXPECT_GT(r.all.ghosting_judged, s.size() / 2);
}

TEST(MapAccuracy, AMapShiftedByOneCentimetreScoresOneCentimetre) {
  const auto s = two_surfaces();
  const auto r = pvb::eval::evaluate_map(map_from(s, 0.01), s);
  EXPECT_NEAR(r.all.accuracy.mean, 0.01, 1e-6);
  EXPECT_NEAR(r.all.accuracy.median, 0.01, 1e-6);
  EXPECT_NEAR(r.all.accuracy.rmse, 0.01, 1e-6);
  EXPECT_DOUBLE_EQ(r.all.completeness_at[1], 1.0);  // 2 cm
  EXPECT_DOUBLE_EQ(r.all.precision_at[1], 1.0);
  EXPECT_NEAR(r.all.chamfer_m, 0.01, 1e-6);
  EXPECT_EQ(r.all.ghosting, 0.0);  // one layer, only displaced
}

TEST(MapAccuracy, HalfTheMapCoversHalfTheSurface) {
  const auto s = two_surfaces();
  std::vector<MapPoint> half;
  for (const auto& m : map_from(s, 0.0))
    if (m.p_w.y() < 0.5) half.push_back(m);
  const auto r = pvb::eval::evaluate_map(half, s);
  // Rows are 5 mm apart: 1 cm reaches 2 rows past the cut, 10 cm 20 (of 200).
  EXPECT_NEAR(r.all.completeness_at[0], 0.51, 0.006);
  EXPECT_NEAR(r.all.completeness_at[3], 0.60, 0.006);
  EXPECT_LT(r.all.accuracy.p95, 1e-9);  // what is there is exact
}

TEST(MapAccuracy, ASurfaceMappedTwiceIsGhosting) {
  const auto s = two_surfaces();
  std::vector<MapPoint> twice = map_from(s, 0.0, 2);
  for (const auto& m : map_from(s, 0.06, 2)) twice.push_back(m);  // a second layer 6 cm off
  const auto r = pvb::eval::evaluate_map(twice, s);
  EXPECT_GT(r.all.ghosting, 0.95);
  // Layers closer than 2 tau (4 cm) are one layer.
  std::vector<MapPoint> thick = map_from(s, 0.0, 2);
  for (const auto& m : map_from(s, 0.03, 2)) thick.push_back(m);
  EXPECT_LT(pvb::eval::evaluate_map(thick, s).all.ghosting, 0.05);
}

/// `m` labelled as coming from map `source`.
std::vector<MapPoint> from_source(std::vector<MapPoint> m, int source) {
  for (MapPoint& p : m) p.source = source;
  return m;
}

TEST(MapAccuracy, TwoSessionsDrawingASurfaceApartAreGhostingBetweenMaps) {
  const auto s = two_surfaces();
  std::vector<MapPoint> merged = from_source(map_from(s, 0.0), 0);
  for (const auto& m : from_source(map_from(s, 0.06), 1)) merged.push_back(m);  // the second session 6 cm off
  const auto apart = pvb::eval::evaluate_map(merged, s);
  EXPECT_EQ(apart.sources, 2);
  EXPECT_GT(apart.all.ghosting_between, 0.95);
  EXPECT_GT(apart.all.ghosting_between_judged, s.size() / 2);
  // The same two sessions in register: one surface, however many maps drew it.
  std::vector<MapPoint> together = from_source(map_from(s, 0.0), 0);
  for (const auto& m : from_source(map_from(s, 0.005), 1)) together.push_back(m);
  const auto one = pvb::eval::evaluate_map(together, s);
  EXPECT_EQ(one.all.ghosting_between, 0.0);
  EXPECT_GT(one.all.ghosting_between_judged, s.size() / 2);
  // Where only one session drew the surface there is nothing to judge between maps.
  std::vector<MapPoint> split;
  for (const auto& m : map_from(s, 0.0)) split.push_back(from_source({m}, m.p_w.y() < 0.5 ? 0 : 1).front());
  EXPECT_LT(pvb::eval::evaluate_map(split, s).all.ghosting_between_judged, s.size() / 10);
}

TEST(MapAccuracy, ASingleMapHasNoGhostingBetweenMaps) {
  const auto s = two_surfaces();
  std::vector<MapPoint> twice = map_from(s, 0.0, 2);
  for (const auto& m : map_from(s, 0.06, 2)) twice.push_back(m);
  const auto r = pvb::eval::evaluate_map(twice, s);
  EXPECT_EQ(r.sources, 1);
  EXPECT_GT(r.all.ghosting, 0.95);  // mapped twice, but by one map
  EXPECT_EQ(r.all.ghosting_between_judged, 0u);
}

TEST(MapAccuracy, ClassesAndRangesSplitThePoints) {
  const auto s = two_surfaces();
  std::vector<MapPoint> m = map_from(s, 0.0);
  for (auto& p : m)  // the wall mapped 2 cm off, the panel exact
    if (p.p_w.x() > 2.5) p.p_w.x() += 0.02;
  const auto r = pvb::eval::evaluate_map(m, s);
  ASSERT_EQ(r.per_class.size(), 2u);
  EXPECT_LT(r.per_class.at(kPanel).accuracy.median, 1e-9);
  EXPECT_NEAR(r.per_class.at(kWall).accuracy.median, 0.02, 1e-6);
  EXPECT_EQ(r.per_class.at(kPanel).accuracy.count + r.per_class.at(kWall).accuracy.count, m.size());
  // Range bins [1, 2) and [3, 4) hold the panel and the wall.
  EXPECT_EQ(r.per_range[1].accuracy.count, s.size() / 2);
  EXPECT_NEAR(r.per_range[3].accuracy.median, 0.02, 1e-6);
  EXPECT_EQ(r.per_range[0].accuracy.count, 0u);
}

TEST(MapAccuracy, EmptyInputs) {
  const auto s = two_surfaces();
  const auto r = pvb::eval::evaluate_map({}, s);
  EXPECT_EQ(r.all.accuracy.count, 0u);
  EXPECT_EQ(r.all.completeness_at[3], 0.0);
  EXPECT_THROW(pvb::eval::evaluate_map(map_from(s, 0.0), {}), std::invalid_argument);
}
