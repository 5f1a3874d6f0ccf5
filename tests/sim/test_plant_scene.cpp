// A plant's scene: tables drawn as one slab each, and frames culled to the
// camera's view that match frames drawn whole.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/scene_builder.hpp"
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

/// The dust variant of each slab of array 0, by row, from the scene's MJCF.
std::map<int, std::set<int>> slab_variants_by_row(const std::string& yaml) {
  const scenes::Scenario s = scenes::parse_scenario(yaml, "rows.yaml");
  const sim::SceneAssets a = sim::build_scene(s, sim::SceneDetail::kGeometry);
  const std::regex slab("name=\"a0r([0-9]+)t[0-9]+slab\"[^>]*material=\"a0slab([0-9])\"");
  std::map<int, std::set<int>> out;
  for (std::sregex_iterator it(a.xml.begin(), a.xml.end(), slab), end; it != end; ++it)
    out[std::stoi((*it)[1])].insert(std::stoi((*it)[2]));
  return out;
}

// Soiling that varies from row to row: every table of a row has the row's
// dust, the rows differ, and the same rows are the dirty ones every day.
TEST(PlantScene, RowSoilingGivesEveryTableOfARowTheRowsDust) {
  const std::string plant = "ground: {size_m: [300, 300], tiling: repeat}\nstation_seed: 9\n"
                            "plant: {origin_m: [-60, -60], rows: 16, row_soiling: 0.6}\n"
                            "route: {pattern: along_row, aisle: 1}\n";
  const auto day1 = slab_variants_by_row("seed: 1\n" + plant), day2 = slab_variants_by_row("seed: 2\n" + plant);
  ASSERT_EQ(day1.size(), 16u);
  std::set<int> rows_dust;
  for (const auto& [row, variants] : day1) {
    EXPECT_EQ(variants.size(), 1u) << "row " << row;
    rows_dust.insert(*variants.begin());
  }
  EXPECT_GE(rows_dust.size(), 3u);
  EXPECT_EQ(day1, day2);
  // Without it each table draws its own: some row mixes variants.
  const auto mixed = slab_variants_by_row("seed: 1\n" + std::string("ground: {size_m: [300, 300], tiling: repeat}\n"
                                          "plant: {origin_m: [-60, -60], rows: 16}\nroute: {pattern: along_row, aisle: 1}\n"));
  EXPECT_TRUE(std::any_of(mixed.begin(), mixed.end(), [](const auto& r) { return r.second.size() > 1; }));
}

// Broken modules: the number asked for, each over one module of a table,
// in the same places every day.
TEST(PlantScene, BrokenModulesAreShatteredPanesWhereTheStationPutsThem) {
  const auto panes = [](int seed) {
    const scenes::Scenario s = scenes::parse_scenario(
        "seed: " + std::to_string(seed) + "\nstation_seed: 4\nground: {size_m: [400, 300], tiling: repeat}\n"
        "plant: {origin_m: [-60, -60], rows: 10, blocks: 2, blocks_along: 2, broken_modules: 7}\n"
        "route: {pattern: along_row, aisle: 1}\n", "broken.yaml");
    const sim::SceneAssets a = sim::build_scene(s, sim::SceneDetail::kGeometry);
    const std::regex pane("<geom name=\"(a[0-9]+r[0-9]+t[0-9]+)broken[0-9]+_[0-9]+\"[^>]*material=\"broken\"");
    std::multiset<std::string> tables;
    for (std::sregex_iterator it(a.xml.begin(), a.xml.end(), pane), end; it != end; ++it) tables.insert((*it)[1]);
    return std::make_pair(tables, a.xml.find("<geom name=\"a0r") != std::string::npos);
  };
  const auto [day1, drawn] = panes(1);
  ASSERT_TRUE(drawn);
  EXPECT_EQ(day1.size(), 2u * 7u);  // two blocks of 7
  EXPECT_EQ(day1, panes(2).first);
}

}  // namespace plant_scene_test
}  // namespace pvb::test
