// The true surface sampled along a route: exact (ground samples lie on
// z = 0, within the depth buffer's precision), labelled, with unit normals,
// one per voxel, and the same on every run.
#include "pvb/sim/truth_surface.hpp"

#include "pvb/scenes/ground_relief.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

namespace {

pvb::scenes::Scenario scenario(const std::string& name) {
  return pvb::scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + name + ".yaml");
}

std::map<pvb::sim::SurfaceClass, int> count_classes(const std::vector<pvb::sim::TruthSample>& s) {
  std::map<pvb::sim::SurfaceClass, int> n;
  for (const auto& t : s) ++n[t.cls];
  return n;
}

}  // namespace

TEST(TruthSurface, PvStationSamplesAreExactLabelledAndDeterministic) {
  pvb::sim::TruthSurfaceOptions o;
  o.frames = 60;
  o.every = 20;
  const auto s = pvb::sim::sample_truth_surface(scenario("pv_station"), pvb::sim::GlBackend::kAuto, o);
  ASSERT_GT(s.size(), 50000u);
  const auto classes = count_classes(s);
  EXPECT_GT(classes.count(pvb::sim::SurfaceClass::kGround), 0u);
  EXPECT_GT(classes.count(pvb::sim::SurfaceClass::kPanel), 0u);
  std::set<std::tuple<long, long, long>> voxels;
  double worst_ground_z = 0;
  for (const auto& t : s) {
    EXPECT_NEAR(t.n_w.norm(), 1.0, 1e-9);
    EXPECT_GE(t.range_m, 0.5);
    EXPECT_LE(t.range_m, 4.5 * 1.6);  // depth range 4.5 m, at the image corner
    voxels.insert({std::lround(std::floor(t.p_w.x() / o.voxel_m)), std::lround(std::floor(t.p_w.y() / o.voxel_m)),
                   std::lround(std::floor(t.p_w.z() / o.voxel_m))});
    if (t.cls == pvb::sim::SurfaceClass::kGround) {
      worst_ground_z = std::max(worst_ground_z, std::abs(t.p_w.z()));
      EXPECT_NEAR(t.n_w.z(), 1.0, 1e-9);
    }
  }
  EXPECT_EQ(voxels.size(), s.size());  // one sample per voxel
  EXPECT_LT(worst_ground_z, 0.002) << "ground samples must lie on z = 0";
  const auto again = pvb::sim::sample_truth_surface(scenario("pv_station"), pvb::sim::GlBackend::kAuto, o);
  ASSERT_EQ(again.size(), s.size());
  for (std::size_t i = 0; i < s.size(); i += 997) EXPECT_EQ(again[i].p_w, s[i].p_w);
}

TEST(TruthSurface, WallPassSeesTheWall) {
  pvb::sim::TruthSurfaceOptions o;
  o.frames = 30;
  o.every = 15;
  const auto s = pvb::sim::sample_truth_surface(scenario("wall_pass"), pvb::sim::GlBackend::kAuto, o);
  const auto classes = count_classes(s);
  ASSERT_GT(classes.count(pvb::sim::SurfaceClass::kWall), 0u);
  EXPECT_GT(classes.at(pvb::sim::SurfaceClass::kWall), 1000);
  EXPECT_EQ(classes.count(pvb::sim::SurfaceClass::kOther), 0u) << "every seen geom has a class";
}

// On a relief the ground's samples lie on GroundRelief's surface, labelled
// ground, with its triangles' normals (not the direction to the camera).
TEST(TruthSurface, RoughStationGroundLiesOnTheRelief) {
  pvb::sim::TruthSurfaceOptions o;
  o.frames = 60;
  o.every = 30;
  const pvb::scenes::Scenario rough = scenario("rough_station");
  const pvb::scenes::GroundRelief relief(rough);
  const auto s = pvb::sim::sample_truth_surface(rough, pvb::sim::GlBackend::kAuto, o);
  const auto classes = count_classes(s);
  ASSERT_GT(classes.count(pvb::sim::SurfaceClass::kGround), 0u);
  EXPECT_GT(classes.at(pvb::sim::SurfaceClass::kGround), 20000);
  EXPECT_EQ(classes.count(pvb::sim::SurfaceClass::kOther), 0u) << "every seen geom has a class";
  double worst = 0, worst_normal = 0;
  int tilted = 0, ground = 0;
  for (const auto& t : s) {
    if (t.cls != pvb::sim::SurfaceClass::kGround) continue;
    ++ground;
    worst = std::max(worst, std::abs(t.p_w.z() - relief.height_m(t.p_w.x(), t.p_w.y())));
    // A sample near a triangle's edge may take its neighbour's normal: judged by the median below.
    worst_normal = std::max(worst_normal, (t.n_w - relief.normal(t.p_w.x(), t.p_w.y())).norm());
    tilted += t.n_w.z() < 1.0 - 1e-6 ? 1 : 0;
  }
  EXPECT_LT(worst, 0.002) << "ground samples must lie on the relief";
  EXPECT_LT(worst_normal, 0.2);
  EXPECT_EQ(tilted, ground) << "every ground normal is the relief's, none the plane's";
}
