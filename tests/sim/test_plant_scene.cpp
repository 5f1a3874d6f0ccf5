// A plant's scene: tables drawn as one slab each, and frames culled to the
// camera's view that match frames drawn whole.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/sim/textures.hpp"
#include "pvb/sim/truth_surface.hpp"

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

namespace {

/// Renders `sim`'s camera every 12th of 240 frames culled and drawn whole,
/// which must agree exactly: a geom left out lay wholly outside the view
/// and its shadow with it.  Returns the most geoms one frame left out.
int expect_culled_matches_whole(sim::Simulator& sim, int* fence_pixels, double relief_detail_m = 0) {
  sim::Renderer culled(sim.model(), sim::GlBackend::kAuto, 320, 240), whole(sim.model(), sim::GlBackend::kAuto, 320, 240);
  whole.set_culling(false);
  culled.set_relief_detail_m(relief_detail_m);
  whole.set_relief_detail_m(relief_detail_m);
  // Every relief tile in full: the same depth within the camera's range.
  sim::Renderer full(sim.model(), sim::GlBackend::kAuto, 320, 240);
  const float range_m = static_cast<float>(sim.scenario().camera.depth_range_m.y());
  culled.set_ground_stream(sim.ground_stream());
  whole.set_ground_stream(sim.ground_stream());
  // The fence's sections are meshes, culled by their bounding spheres.
  std::vector<int> fence;
  for (int g = 0; g < sim.model()->ngeom; ++g) {
    const char* name = mj_id2name(sim.model(), mjOBJ_GEOM, g);
    if (name && std::string(name).rfind("fence", 0) == 0) fence.push_back(g);
  }
  int most_culled = 0;
  for (int i = 0; i < 240; ++i) {
    if (i % 12 == 0) {
      cv::Mat rgb_c, depth_c, ids_c, rgb_w, depth_w, ids_w;
      culled.set_shadow_floor_z_m(sim.shadow_floor_z_m());
      culled.render(sim.model(), sim.data(), sim.camera_id(), &rgb_c, &depth_c);
      most_culled = std::max(most_culled, culled.culled_geoms());
      culled.render_geom_ids(sim.model(), sim.data(), sim.camera_id(), &ids_c);
      whole.render(sim.model(), sim.data(), sim.camera_id(), &rgb_w, &depth_w);
      whole.render_geom_ids(sim.model(), sim.data(), sim.camera_id(), &ids_w);
      EXPECT_EQ(cv::norm(rgb_c, rgb_w, cv::NORM_INF), 0.0) << "frame " << i;
      EXPECT_EQ(cv::norm(depth_c, depth_w, cv::NORM_INF), 0.0) << "frame " << i;
      EXPECT_EQ(cv::norm(ids_c, ids_w, cv::NORM_INF), 0.0) << "frame " << i;
      EXPECT_EQ(whole.culled_geoms(), 0);
      if (relief_detail_m > 0) {
        cv::Mat rgb_f, depth_f;
        full.set_shadow_floor_z_m(sim.shadow_floor_z_m());
        full.render(sim.model(), sim.data(), sim.camera_id(), &rgb_f, &depth_f);
        const cv::Mat in_range = (depth_f <= range_m) | (depth_c <= range_m);
        EXPECT_EQ(cv::countNonZero((depth_f != depth_c) & in_range), 0) << "frame " << i;
        EXPECT_GT(cv::norm(rgb_f, rgb_c, cv::NORM_L1), 0.0) << "frame " << i;  // the far tiles are drawn
      }
      for (const int g : fence) *fence_pixels += cv::countNonZero(ids_c == g);
    }
    sim.advance();
  }
  return most_culled;
}

}  // namespace

TEST(PlantScene, CulledFramesMatchFramesDrawnWhole) {
  sim::Simulator sim(small_plant());
  int fence_pixels = 0;
  EXPECT_GT(expect_culled_matches_whole(sim, &fence_pixels), sim.model()->ngeom / 2);
  EXPECT_GT(fence_pixels, 100);  // the fence was in view, and matched
}

// On a relief under varied soil, tiles and backdrop pieces are height
// fields culled by their size, and the sun's shadows are swept down to the
// ground under the shadow map, metres below z = 0 on this 8 % slope.
// Tiles beyond 7.6 m are drawn as their far versions, in both renders, and
// change no depth within the camera's range.
TEST(PlantScene, CulledFramesOnARoughPlantMatchFramesDrawnWhole) {
  scenes::Scenario s = small_plant();
  s.ground.tiling = scenes::GroundTiling::kVaried;
  s.ground.soil_images = 4;
  scenes::Relief r;
  r.slope_percent = 8;
  r.slope_azimuth_deg = 0;
  s.ground.relief = r;
  sim::Simulator sim(s);
  const scenes::GroundRelief ground(s);
  ASSERT_TRUE(ground.tiled());
  EXPECT_LT(sim.shadow_floor_z_m(), -3.0);
  int fence_pixels = 0;
  EXPECT_GT(expect_culled_matches_whole(sim, &fence_pixels, 7.6), sim.model()->ngeom / 2);
}

// A ground longer than 60 m is drawn as a coarser grid of quads (5 m on
// this 300 m ground, against 1 m before): its soil's faint specular
// highlight, lit at the quads' corners, is all that changes.
TEST(PlantScene, AWideGroundsCoarseGridChangesOnlyItsHighlight) {
  const scenes::Scenario s = small_plant();
  sim::Simulator sim(s);
  const sim::SceneAssets coarse = sim::build_scene(s, sim::SceneDetail::kFull, sim::TextureEncoding::kPixels);
  sim::SceneAssets fine = coarse;
  const std::string before = "name=\"ground\" type=\"plane\" size=\"150 150 5\"";
  const std::size_t at = fine.xml.find(before);
  ASSERT_NE(at, std::string::npos) << "the ground's grid is not 5 m";
  fine.xml.replace(at, before.size(), "name=\"ground\" type=\"plane\" size=\"150 150 1\"");
  const sim::ModelPtr fine_model = sim::compile_scene(fine);
  sim::DataPtr fine_data(mj_makeData(fine_model.get()));
  sim::Renderer a(sim.model(), sim::GlBackend::kAuto, 320, 240),
      b(fine_model.get(), sim::GlBackend::kAuto, 320, 240);
  const float range_m = static_cast<float>(s.camera.depth_range_m.y());
  double worst_mean = 0, worst_max = 0;
  for (int i = 0; i < 240; ++i) {
    if (i % 40 == 0) {
      std::copy(sim.data()->qpos, sim.data()->qpos + sim.model()->nq, fine_data->qpos);
      mj_forward(fine_model.get(), fine_data.get());
      cv::Mat rgb_a, depth_a, rgb_b, depth_b;
      a.render(sim.model(), sim.data(), sim.camera_id(), &rgb_a, &depth_a);
      b.render(fine_model.get(), fine_data.get(), sim.camera_id(), &rgb_b, &depth_b);
      cv::Mat diff;
      cv::absdiff(rgb_a, rgb_b, diff);
      const cv::Scalar mean = cv::mean(diff);
      worst_mean = std::max(worst_mean, (mean[0] + mean[1] + mean[2]) / 3);
      worst_max = std::max(worst_max, cv::norm(diff, cv::NORM_INF));
      // Depth: the same plane in other triangles, to the depth buffer's
      // precision within the camera's range (0.09 mm measured).
      const cv::Mat in_range = (depth_a <= range_m) | (depth_b <= range_m);
      EXPECT_LT(cv::norm(depth_a, depth_b, cv::NORM_INF, in_range), 2e-4) << "frame " << i;
    }
    sim.advance();
  }
  // Colour: 0.033 levels on average and 2 at most, measured.
  EXPECT_GT(worst_max, 0.0);  // the highlight did change
  EXPECT_LE(worst_max, 3.0);
  EXPECT_LT(worst_mean, 0.1);
}

/// The small plant on varied soil of shared images: roads drawn as planes.
scenes::Scenario small_plant_on_varied_soil() {
  scenes::Scenario s = small_plant();
  s.ground.tiling = scenes::GroundTiling::kVaried;
  s.ground.soil_images = 4;
  return s;
}

// A plant's roads are gravel beyond the route's tiles too: planes between
// the soil's backdrop and the tiles, as wide as the roads.
TEST(PlantScene, RoadsAreGravelWhereverTheyRun) {
  const scenes::Scenario s = small_plant_on_varied_soil();
  sim::Simulator sim(s);
  const mjModel* m = sim.model();
  const scenes::PvArray& frame = s.pv_arrays[static_cast<std::size_t>(s.plant->first_array)];
  const std::vector<sim::GroundTile> tiles = sim::ground_tiles(s);
  const auto off_the_tiles = [&](const Eigen::Vector2d& p) {
    return std::all_of(tiles.begin(), tiles.end(), [&](const sim::GroundTile& t) {
      return (t.centre_m - p).lpNorm<Eigen::Infinity>() > sim::kGroundTileM / 2 + 0.01;
    });
  };
  // Straight down from a metre up: the first geom drawn that the ray meets,
  // by its material's name.  MuJoCo's rays meet every plane whatever its
  // group, so the ground's collision plane is made invisible to them.
  const sim::ModelPtr drawn(mj_copyModel(nullptr, m));
  const int ground = mj_name2id(m, mjOBJ_GEOM, "ground");
  drawn->geom_matid[ground] = -1;
  drawn->geom_rgba[4 * ground + 3] = 0;
  const auto material_below = [&](const Eigen::Vector2d& p) {
    const mjtNum pnt[3] = {p.x(), p.y(), 1.0}, down[3] = {0, 0, -1};
    int g = -1;
    mj_ray(drawn.get(), sim.data(), pnt, down, nullptr, 1, -1, &g);
    return g < 0 || m->geom_matid[g] < 0 ? std::string()
                                         : std::string(mj_id2name(m, mjOBJ_MATERIAL, m->geom_matid[g]));
  };
  const std::string gravel = "groundt" + std::to_string(s.ground.soil_images);
  int on_road = 0, soil_beside = 0;
  for (const Eigen::Vector4d& r : s.plant->roads_uv) {
    const bool along_u = r[2] - r[0] >= r[3] - r[1];
    for (double t = 1.0; t < (along_u ? r[2] - r[0] : r[3] - r[1]) - 1.0; t += 5.0) {
      const Eigen::Vector2d centre = along_u ? Eigen::Vector2d(r[0] + t, 0.5 * (r[1] + r[3]))
                                             : Eigen::Vector2d(0.5 * (r[0] + r[2]), r[1] + t);
      const Eigen::Vector2d p = scenes::array_to_world(frame, centre.x(), centre.y());
      if (!off_the_tiles(p)) continue;
      EXPECT_EQ(material_below(p), gravel) << "road at (" << p.transpose() << ")";
      ++on_road;
      // Half a metre beside the road, clear of every road: no gravel.
      const Eigen::Vector2d beside =
          along_u ? Eigen::Vector2d(centre.x(), r[3] + 0.5) : Eigen::Vector2d(r[2] + 0.5, centre.y());
      const Eigen::Vector2d q = scenes::array_to_world(frame, beside.x(), beside.y());
      bool clear = off_the_tiles(q);
      for (const Eigen::Vector4d& o : s.plant->roads_uv)
        clear = clear && !(beside.x() >= o[0] - 0.1 && beside.x() <= o[2] + 0.1 && beside.y() >= o[1] - 0.1 &&
                           beside.y() <= o[3] + 0.1);
      if (!clear) continue;
      const std::string beside_road = material_below(q);
      EXPECT_NE(beside_road, gravel) << "beside the road at (" << q.transpose() << ")";
      soil_beside += beside_road == "ground";
    }
  }
  EXPECT_GT(on_road, 100);
  EXPECT_GT(soil_beside, 50);  // the soil's backdrop half a metre off the road
}

// The cull leaves out ground tiles beyond 10 m here, but keeps road pieces
// in view however far: pixels of pieces wholly beyond 10 m.
TEST(PlantScene, TheCullKeepsRoadsFarAlongThem) {
  sim::Simulator sim(small_plant_on_varied_soil());
  const mjModel* m = sim.model();
  sim::Renderer culled(m, sim::GlBackend::kAuto, 320, 240);
  const double far_m = 10.0;
  culled.set_far_tile_cull_m(far_m);
  culled.set_ground_stream(sim.ground_stream());
  std::vector<int> roads;
  for (int g = 0; g < m->ngeom; ++g) {
    const char* name = mj_id2name(m, mjOBJ_GEOM, g);
    if (name && std::string(name).rfind(sim::kRoadPlanePrefix, 0) == 0) roads.push_back(g);
  }
  int far_road_pixels = 0;
  for (int i = 0; i < 240; ++i) {
    if (i % 40 == 0) {
      cv::Mat ids;
      culled.render_geom_ids(m, sim.data(), sim.camera_id(), &ids);
      const Eigen::Map<const Eigen::Vector3d> eye(sim.data()->cam_xpos + 3 * sim.camera_id());
      for (const int g : roads) {
        const Eigen::Map<const Eigen::Vector3d> c(sim.data()->geom_xpos + 3 * g);
        if ((c - eye).norm() > far_m + std::hypot(m->geom_size[3 * g], m->geom_size[3 * g + 1]))
          far_road_pixels += cv::countNonZero(ids == g);
      }
    }
    sim.advance();
  }
  EXPECT_GT(far_road_pixels, 100);
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

/// A plant of one block of 10 rows with `missing` modules gone.
scenes::Scenario holed_plant(int seed, int station_seed, int missing) {
  return scenes::parse_scenario(
      "seed: " + std::to_string(seed) + "\nstation_seed: " + std::to_string(station_seed) +
          "\nground: {size_m: [300, 200], tiling: repeat}\nduration_s: 2\n"
          "plant: {origin_m: [-60, -40], rows: 10, broken_modules: 5, missing_modules: " +
          std::to_string(missing) + "}\nroute: {pattern: along_row, aisle: 1}\n",
      "missing.yaml");
}

/// The modules gone from each table drawn a module at a time: every
/// (line, column) of the table that has no geom of its own.
std::map<std::string, std::set<std::pair<int, int>>> gone_modules(const mjModel* m,
                                                                  const scenes::PvArray& a) {
  std::map<std::string, std::set<std::pair<int, int>>> present;
  const std::regex module("(a[0-9]+r[0-9]+t[0-9]+)p([0-9]+)_([0-9]+)");
  for (int g = 0; g < m->ngeom; ++g) {
    const char* name = mj_id2name(m, mjOBJ_GEOM, g);
    std::cmatch hit;
    if (name && std::regex_match(name, hit, module))
      present[hit[1]].insert({std::stoi(hit[2]), std::stoi(hit[3])});
  }
  std::map<std::string, std::set<std::pair<int, int>>> gone;
  for (const auto& [table, modules] : present)
    for (int line = 0; line < a.panel_lines; ++line)
      for (int c = 0; c < a.panels_per_table; ++c)
        if (modules.count({line, c}) == 0) gone[table].insert({line, c});
  return gone;
}

/// The first geom a ray meets, from `from` along `dir`, the robot excluded.
int first_geom_hit(const mjModel* m, mjData* d, const Eigen::Vector3d& from, const Eigen::Vector3d& dir) {
  int geom = -1;
  mj_ray(m, d, from.data(), dir.data(), nullptr, 1, -1, &geom);
  return geom;
}

// A missing module leaves a gap where the station's seed puts it: its table
// is drawn a module at a time without the module and its backsheet, so a
// ray down through the gap meets what lies under the table (a rail, the
// ground), while one through the next module meets that module.  The same
// station on another day has the same gaps; another station has others.
TEST(PlantScene, MissingModulesLeaveGapsWhereTheStationPutsThem) {
  const scenes::Scenario s = holed_plant(1, 4, 6);
  const scenes::PvArray& a = s.pv_arrays.at(0);
  sim::Simulator sim(s);
  const mjModel* m = sim.model();
  const auto gone = gone_modules(m, a);
  std::size_t holes = 0;
  for (const auto& [table, modules] : gone) holes += modules.size();
  EXPECT_EQ(holes, 6u);
  for (const auto& [table, modules] : gone) {
    EXPECT_EQ(mj_name2id(m, mjOBJ_GEOM, (table + "slab").c_str()), -1) << table;
    const auto [line, col] = *modules.begin();
    // The module beside the gap, in the same line.
    const int next_col = col + 1 < a.panels_per_table ? col + 1 : col - 1;
    ASSERT_EQ(modules.count({line, next_col}), 0u) << table;
    const std::string next = table + "p" + std::to_string(line) + "_" + std::to_string(next_col);
    const int g = mj_name2id(m, mjOBJ_GEOM, next.c_str());
    ASSERT_GE(g, 0) << next;
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> R(sim.data()->geom_xmat + 9 * g);
    const Eigen::Vector3d centre = Eigen::Map<const Eigen::Vector3d>(sim.data()->geom_xpos + 3 * g);
    const Eigen::Vector3d up = R.col(2).z() > 0 ? R.col(2) : Eigen::Vector3d(-R.col(2));
    const Eigen::Vector3d hole = centre + (col - next_col) * 2 * m->geom_size[3 * g] * R.col(0);
    EXPECT_EQ(first_geom_hit(m, sim.data(), centre + up, -up), g) << next;
    const int under = first_geom_hit(m, sim.data(), hole + up, -up);
    EXPECT_NE(under, -1) << table;
    EXPECT_NE(sim::classify_geom(m, under), sim::SurfaceClass::kPanel) << table;
    EXPECT_NE(std::string(mj_id2name(m, mjOBJ_MATERIAL, m->geom_matid[under])), "backsheet") << table;
  }
  // A whole table's slab is a panel surface too.
  const int slab = mj_name2id(m, mjOBJ_GEOM, "a0r0t0slab");
  ASSERT_GE(slab, 0);
  EXPECT_EQ(sim::classify_geom(m, slab), sim::SurfaceClass::kPanel);
  // The gaps are the station's: the same on another day, others elsewhere.
  const auto gone_on = [](const scenes::Scenario& other) {
    const sim::SceneAssets assets = sim::build_scene(other, sim::SceneDetail::kGeometry);
    std::set<std::string> tables;
    const std::regex module("<geom name=\"(a[0-9]+r[0-9]+t[0-9]+)p[0-9]+_[0-9]+\"");
    for (std::sregex_iterator it(assets.xml.begin(), assets.xml.end(), module), end; it != end; ++it)
      tables.insert((*it)[1]);
    return tables;
  };
  std::set<std::string> tables;
  for (const auto& [table, modules] : gone) tables.insert(table);
  EXPECT_EQ(gone_on(holed_plant(2, 4, 6)), tables);
  EXPECT_NE(gone_on(holed_plant(1, 5, 6)), tables);
}

/// How well two grey images of one size agree: their normalised correlation.
double agreement(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat r;
  cv::matchTemplate(a, b, r, cv::TM_CCOEFF_NORMED);
  return r.at<float>(0, 0);
}

// Every row has its number on a sign at both ends: a plate seen from in
// front (the headland) shows its row's label the right way round, at the
// west end and at the east; its back shows the label mirrored in the
// plate's frame, so that it reads the right way round from behind too.
TEST(PlantScene, RowSignsShowTheirRowsNumberTheRightWayRound) {
  const std::string plant = "ground: {size_m: [120, 120], tiling: repeat}\nseed: 4\nduration_s: 2\n"
                            "plant: {origin_m: [-20, -10], rows: 4, tables_per_row: 1, modules_per_table: 12, "
                            "dock: false, combiner_rows: 0}\n";
  const scenes::Scenario bare = scenes::parse_scenario(plant + "route: {pattern: along_row, aisle: 1}\n", "s.yaml");
  ASSERT_EQ(bare.plant->row_signs.size(), 8u);  // two a row
  ASSERT_EQ(bare.plant->sign_labels.size(), 4u);
  EXPECT_EQ(bare.plant->sign_labels[2], "B1 R003");
  const cv::Mat atlas = sim::make_sign_atlas(bare.plant->sign_labels);
  for (const int k : {4, 5}) {  // row 3's west sign and its east sign
    const scenes::RowSign& sign = bare.plant->row_signs[static_cast<std::size_t>(k)];
    EXPECT_EQ(sign.label, 2);
    const double yaw = sign.yaw_deg * M_PI / 180.0;
    const Eigen::Vector2d out(std::cos(yaw), std::sin(yaw));
    const Eigen::Vector2d a = sign.centre_m + 2.2 * out, b = sign.centre_m + 1.0 * out;
    char route[160];
    std::snprintf(route, sizeof route, "route: {waypoints_m: [[%.3f, %.3f], [%.3f, %.3f]]}\n", a.x(), a.y(), b.x(),
                  b.y());
    sim::Simulator sim(scenes::parse_scenario(plant + route, "s.yaml"));
    sim::Renderer r(sim.model(), sim::GlBackend::kAuto, sim.scenario().camera.width, sim.scenario().camera.height);
    cv::Mat rgb, depth, ids;
    r.render(sim.model(), sim.data(), sim.camera_id(), &rgb, &depth);
    r.render_geom_ids(sim.model(), sim.data(), sim.camera_id(), &ids);
    const int plate = mj_name2id(sim.model(), mjOBJ_GEOM, ("sign" + std::to_string(k)).c_str());
    ASSERT_GE(plate, 0);
    const cv::Rect box = cv::boundingRect(ids == plate);
    ASSERT_GT(box.width, 60) << "sign " << k;
    // The plate as seen, against the label's cell of the atlas.
    cv::Mat grey, seen, want, mirrored, upside_down;
    cv::cvtColor(rgb(box), grey, cv::COLOR_RGB2GRAY);
    cv::cvtColor(atlas(cv::Rect((sign.label % sim::kSignAtlasColumns) * sim::kSignCellWidthPx,
                                (sign.label / sim::kSignAtlasColumns) * sim::kSignCellHeightPx,
                                sim::kSignCellWidthPx, sim::kSignCellHeightPx)),
                 want, cv::COLOR_RGB2GRAY);
    cv::resize(grey, seen, want.size(), 0, 0, cv::INTER_AREA);
    cv::flip(want, mirrored, 1);
    cv::flip(want, upside_down, 0);
    const double right = agreement(seen, want);
    std::printf("sign %d: agreement %.3f, mirrored %.3f, upside down %.3f\n", k, right, agreement(seen, mirrored),
                agreement(seen, upside_down));
    // The frame and the centred words agree with their mirror image about
    // 0.75; the label read the right way round agrees above 0.9.
    EXPECT_GT(right, 0.85) << "sign " << k;
    EXPECT_GT(right, agreement(seen, mirrored) + 0.1) << "sign " << k;
    EXPECT_GT(right, agreement(seen, upside_down) + 0.3) << "sign " << k;
    // The back: the same cell, its texture coordinate u running the other
    // way along the plate's width than on the front.  (MuJoCo turns a mesh
    // to its principal axes: the thinnest is the plate's normal, the widest
    // its width.)
    const mjModel* m = sim.model();
    const int mesh = m->geom_dataid[plate], n = m->mesh_vertnum[mesh];
    const float* vert = m->mesh_vert + 3 * m->mesh_vertadr[mesh];
    ASSERT_GE(m->mesh_texcoordadr[mesh], 0);
    const float* tex = m->mesh_texcoord + 2 * m->mesh_texcoordadr[mesh];
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
    for (int i = 0; i < n; ++i) {
      lo = lo.cwiseMin(Eigen::Vector3f(vert[3 * i], vert[3 * i + 1], vert[3 * i + 2]));
      hi = hi.cwiseMax(Eigen::Vector3f(vert[3 * i], vert[3 * i + 1], vert[3 * i + 2]));
    }
    int thin = 0, wide = 0;
    (hi - lo).minCoeff(&thin);
    (hi - lo).maxCoeff(&wide);
    int runs[2] = {0, 0};  // per face: +1 where u grows with the width axis, -1 where it falls
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const int face = vert[3 * i + thin] > 0 ? 1 : 0;
        const float dw = vert[3 * j + wide] - vert[3 * i + wide], du = tex[2 * j] - tex[2 * i];
        if ((vert[3 * j + thin] > 0 ? 1 : 0) != face || std::abs(dw) < 1e-4f) continue;
        runs[face] = (du > 0) == (dw > 0) ? 1 : -1;
      }
    EXPECT_EQ(runs[0] * runs[1], -1) << "sign " << k;
  }
}

// Tyre tracks in a share of the aisles and grass under a share of the rows,
// which ones from the station's seed: the same every day, others for
// another station; and a robot in a tracked aisle sees the tracks.
TEST(PlantScene, TyreTracksAndGrassStripsLieWhereTheStationPutsThem) {
  const auto plant = [](int station_seed, int day_seed, const std::string& cover) {
    return scenes::parse_scenario("ground: {size_m: [200, 200], tiling: repeat}\nseed: " + std::to_string(day_seed) +
                                      "\nstation_seed: " + std::to_string(station_seed) +
                                      "\nduration_s: 2\nplant: {origin_m: [-30, -20], rows: 8, tables_per_row: 2, "
                                      "modules_per_table: 12, " + cover + "}\nroute: {pattern: along_row, aisle: 3}\n",
                                  "cover.yaml");
  };
  // Each band's centre, by material.
  const auto bands = [](const scenes::Scenario& s) {
    const sim::ModelPtr m = sim::compile_scene(sim::build_scene(s, sim::SceneDetail::kGeometry));
    std::map<std::string, std::set<std::pair<long, long>>> out;
    for (int g = 0; g < m->ngeom; ++g) {
      const char* mat = m->geom_matid[g] >= 0 ? mj_id2name(m.get(), mjOBJ_MATERIAL, m->geom_matid[g]) : nullptr;
      if (mat && (std::string(mat) == "groundtrack" || std::string(mat) == "groundgrass"))
        out[mat].insert({std::lround(m->geom_pos[3 * g] * 100), std::lround(m->geom_pos[3 * g + 1] * 100)});
    }
    return out;
  };
  const std::string half = "tyre_tracks: 0.5, vegetation_strips: 0.5";
  const auto a = bands(plant(7, 1, half));
  EXPECT_EQ(a.at("groundtrack").size(), 2u * 5u);  // two bands in each of round(0.5 x 9) aisles
  EXPECT_EQ(a.at("groundgrass").size(), 4u);       // half the 8 rows
  EXPECT_EQ(bands(plant(7, 2, half)), a);          // another day: the same
  EXPECT_NE(bands(plant(8, 1, half)), a);          // another station: others
  EXPECT_TRUE(bands(plant(7, 1, "tyre_tracks: 0")).empty());
  // From the aisle, every aisle tracked: the tracks in view.
  sim::Simulator sim(plant(7, 1, "tyre_tracks: 1"));
  sim::Renderer r(sim.model(), sim::GlBackend::kAuto, 320, 240);
  cv::Mat ids;
  r.render_geom_ids(sim.model(), sim.data(), sim.camera_id(), &ids);
  int track_px = 0;
  for (auto it = ids.begin<int>(); it != ids.end<int>(); ++it)
    if (*it >= 0 && sim.model()->geom_matid[*it] == mj_name2id(sim.model(), mjOBJ_MATERIAL, "groundtrack")) ++track_px;
  EXPECT_GT(track_px, 320 * 240 / 50);
  // They are flat bands on flat ground.
  try {
    scenes::parse_scenario("ground: {size_m: [200, 200], relief: {amplitude_cm: 3}}\n"
                           "plant: {origin_m: [-30, -20], rows: 8, tyre_tracks: 0.5}\n",
                           "cover.yaml");
    FAIL() << "tracks on a relief";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("cover.yaml:2: plant: expected tyre_tracks and vegetation_strips on a flat "
                                         "ground"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace plant_scene_test
}  // namespace pvb::test
