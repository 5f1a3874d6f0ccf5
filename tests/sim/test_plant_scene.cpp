// A plant's scene: tables drawn as one slab each, and frames culled to the
// camera's view that match frames drawn whole.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/simulator.hpp"

namespace pvb::test {
namespace plant_scene_test {

/// Two blocks of trackers, in the sun, with shadows, fenced; the route
/// turns in the headland from the first aisle into the second.
scenes::Scenario small_plant() {
  return scenes::parse_scenario(R"(
name: small_plant
seed: 5
duration_s: 60
ground: {size_m: [300, 300], tiling: repeat}
site: {latitude_deg: 37.1, longitude_deg: -2.4, date: 2026-06-21, time: "17:00", utc_offset_h: 2}
plant: {origin_m: [-60, -20], mount: single_axis, rows: 8, blocks: 2, blocks_along: 2, modules_per_table: 12}
route: {pattern: lawnmower, aisles: 3, offset_m: 2.2, start_m: 38}
light: {shadows: true, shadow_follows_robot: true}
camera: {width: 320, height: 240, fx: 262.5, fy: 262.5, depth_noise: {sunlight: off}}
)",
                                "small_plant.yaml");
}

TEST(PlantScene, EachTableIsOneSlab) {
  const scenes::Scenario s = small_plant();
  sim::Simulator sim(s);
  int slabs = 0;
  for (int g = 0; g < sim.model()->ngeom; ++g) {
    const char* name = mj_id2name(sim.model(), mjOBJ_GEOM, g);
    if (name && std::string(name).find("slab") != std::string::npos) ++slabs;
  }
  EXPECT_EQ(slabs, 2 * 8 * 3);  // blocks x rows x tables, not a geom a module
}

TEST(PlantScene, CulledFramesMatchFramesDrawnWhole) {
  sim::Simulator sim(small_plant());
  sim::Renderer culled(sim.model(), sim::GlBackend::kAuto, 320, 240), whole(sim.model(), sim::GlBackend::kAuto, 320, 240);
  whole.set_culling(false);
  // The fence's sections are meshes, culled by their bounding spheres.
  std::vector<int> fence;
  for (int g = 0; g < sim.model()->ngeom; ++g) {
    const char* name = mj_id2name(sim.model(), mjOBJ_GEOM, g);
    if (name && std::string(name).rfind("fence", 0) == 0) fence.push_back(g);
  }
  ASSERT_FALSE(fence.empty());
  int most_culled = 0, fence_pixels = 0;
  for (int i = 0; i < 240; ++i) {
    if (i % 12 == 0) {
      cv::Mat rgb_c, depth_c, ids_c, rgb_w, depth_w, ids_w;
      culled.render(sim.model(), sim.data(), sim.camera_id(), &rgb_c, &depth_c);
      most_culled = std::max(most_culled, culled.culled_geoms());
      culled.render_geom_ids(sim.model(), sim.data(), sim.camera_id(), &ids_c);
      whole.render(sim.model(), sim.data(), sim.camera_id(), &rgb_w, &depth_w);
      whole.render_geom_ids(sim.model(), sim.data(), sim.camera_id(), &ids_w);
      // Exact: a geom left out lay wholly outside the view and its shadow with it.
      EXPECT_EQ(cv::norm(rgb_c, rgb_w, cv::NORM_INF), 0.0) << "frame " << i;
      EXPECT_EQ(cv::norm(depth_c, depth_w, cv::NORM_INF), 0.0) << "frame " << i;
      EXPECT_EQ(cv::norm(ids_c, ids_w, cv::NORM_INF), 0.0) << "frame " << i;
      EXPECT_EQ(whole.culled_geoms(), 0);
      for (const int g : fence) fence_pixels += cv::countNonZero(ids_c == g);
    }
    sim.advance();
  }
  EXPECT_GT(most_culled, sim.model()->ngeom / 2);
  EXPECT_GT(fence_pixels, 100);  // the fence was in view, and matched
}

}  // namespace plant_scene_test
}  // namespace pvb::test
