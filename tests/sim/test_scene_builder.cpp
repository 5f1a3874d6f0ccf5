#include <gtest/gtest.h>

#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/scene_builder.hpp"

using namespace pvb;

namespace {
scenes::Scenario station() { return scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml"); }
}  // namespace

TEST(SceneBuilder, StationCompilesWithTheExpectedContent) {
  const scenes::Scenario s = station();
  const sim::SceneAssets a = sim::build_scene(s);
  const sim::ModelPtr m = sim::compile_scene(a);
  const scenes::PvArray& arr = s.pv_arrays[0];
  int panels = 0;
  for (int g = 0; g < m->ngeom; ++g) {
    const char* name = mj_id2name(m.get(), mjOBJ_GEOM, g);
    if (name != nullptr && std::string(name).find('p') != std::string::npos && name[0] == 'a') ++panels;
  }
  EXPECT_EQ(panels, arr.rows * arr.tables_per_row * arr.panels_per_table * arr.panel_lines);
  EXPECT_GE(mj_name2id(m.get(), mjOBJ_GEOM, "wall0"), 0);
  EXPECT_GE(mj_name2id(m.get(), mjOBJ_CAMERA, sim::kCameraName), 0);
  EXPECT_EQ(m->vis.quality.offsamples, 0);  // single-sample depth
  EXPECT_LT(m->ngeom, 200);                 // keeps rendering fast
  // the frame period is a whole number of physics steps
  EXPECT_NEAR(m->opt.timestep * a.substeps, 1.0 / s.camera.fps, 1e-12);
}

TEST(SceneBuilder, SameScenarioGivesTheSameBytes) {
  const sim::SceneAssets a = sim::build_scene(station()), b = sim::build_scene(station());
  EXPECT_EQ(a.xml, b.xml);
  ASSERT_EQ(a.files.size(), b.files.size());
  for (std::size_t i = 0; i < a.files.size(); ++i) EXPECT_EQ(a.files[i].second, b.files[i].second) << a.files[i].first;
  scenes::Scenario other = station();
  other.seed = 8;
  EXPECT_NE(sim::build_scene(other).files[0].second, a.files[0].second);  // textures follow the seed
}

TEST(SceneBuilder, WallFinishPicksTheMaterial) {
  scenes::Scenario s = station();
  ASSERT_EQ(s.walls.size(), 1u);
  scenes::Wall plain = s.walls[0];
  plain.finish = scenes::WallFinish::kPlaster;
  s.walls.push_back(plain);
  const sim::SceneAssets a = sim::build_scene(s);
  const sim::ModelPtr m = sim::compile_scene(a);
  const int brick = mj_name2id(m.get(), mjOBJ_MATERIAL, "brick");
  const int plaster = mj_name2id(m.get(), mjOBJ_MATERIAL, "plaster");
  ASSERT_GE(brick, 0);
  ASSERT_GE(plaster, 0);
  EXPECT_EQ(m->geom_matid[mj_name2id(m.get(), mjOBJ_GEOM, "wall0")], brick);
  EXPECT_EQ(m->geom_matid[mj_name2id(m.get(), mjOBJ_GEOM, "wall1")], plaster);
  EXPECT_EQ(m->mat_texid[plaster], -1);  // untextured: one flat colour
}

TEST(SceneBuilder, BoxQuadsSetMujocoTessellation) {
  scenes::Scenario s = station();
  EXPECT_EQ(s.light.box_quads, 1);  // one quad per face: same image, a fifth less render time (docs/run.md)
  EXPECT_EQ(sim::compile_scene(sim::build_scene(s))->vis.quality.numquads, 1);
  s.light.box_quads = 4;  // MuJoCo's own default
  EXPECT_EQ(sim::compile_scene(sim::build_scene(s))->vis.quality.numquads, 4);
}
