#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <algorithm>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <unistd.h>

#include "pvb/common/text.hpp"
#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/route.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/truth_surface.hpp"

using namespace pvb;

namespace {
scenes::Scenario station() { return scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml"); }
/// A shipped file on the repeated soil every station had before varied soil became the default.
scenes::Scenario on_repeated_soil(scenes::Scenario s) {
  s.ground.tiling = scenes::GroundTiling::kRepeat;
  return s;
}
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

// A scene compiled in memory holds its textures' pixels, no PNG: the same
// pixels as the files', under the same MJCF; written out, they are the
// files' bytes.
TEST(SceneBuilder, PixelTexturesHoldTheFilesPixelsAndAreWrittenAsTheFiles) {
  const sim::SceneAssets files = sim::build_scene(station());
  const sim::SceneAssets pixels =
      sim::build_scene(station(), sim::SceneDetail::kFull, sim::TextureEncoding::kPixels);
  EXPECT_EQ(files.xml, pixels.xml);
  ASSERT_EQ(files.files.size(), pixels.files.size());
  for (std::size_t i = 0; i < files.files.size(); ++i) {
    const auto& [path, bytes] = files.files[i];
    ASSERT_EQ(path, pixels.files[i].first);
    const cv::Mat bgr = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(bgr.empty()) << path;
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    const std::vector<unsigned char>& held = pixels.files[i].second;
    std::int32_t size[2] = {0, 0};
    ASSERT_EQ(held.size(), sizeof size + rgb.total() * 3) << path;
    std::memcpy(size, held.data(), sizeof size);
    EXPECT_EQ(size[0], rgb.cols) << path;
    EXPECT_EQ(size[1], rgb.rows) << path;
    EXPECT_EQ(std::memcmp(held.data() + sizeof size, rgb.data, rgb.total() * 3), 0) << path;
  }
  const std::string dir = ::testing::TempDir() + "pvb_pixel_scene_" + std::to_string(::getpid());
  sim::write_scene(pixels, dir);
  for (const auto& [path, bytes] : files.files)
    EXPECT_TRUE(read_file(dir + "/" + path) == std::string(bytes.begin(), bytes.end())) << path;
  EXPECT_EQ(read_file(dir + "/scene.xml"), files.xml);
}

// The model compiled from pixels has the texels MuJoCo decodes from the files.
TEST(SceneBuilder, PixelTexturesCompileToTheFilesTexels) {
  const sim::ModelPtr from_files = sim::compile_scene(sim::build_scene(station()));
  const sim::ModelPtr from_pixels =
      sim::compile_scene(sim::build_scene(station(), sim::SceneDetail::kFull, sim::TextureEncoding::kPixels));
  ASSERT_EQ(from_files->ntex, from_pixels->ntex);
  ASSERT_EQ(from_files->ntexdata, from_pixels->ntexdata);
  for (int t = 0; t < from_files->ntex; ++t) {
    EXPECT_EQ(from_files->tex_width[t], from_pixels->tex_width[t]) << t;
    EXPECT_EQ(from_files->tex_height[t], from_pixels->tex_height[t]) << t;
    EXPECT_EQ(from_files->tex_adr[t], from_pixels->tex_adr[t]) << t;
  }
  EXPECT_EQ(std::memcmp(from_files->tex_rgb, from_pixels->tex_rgb, from_files->ntexdata), 0);
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

// The sun's shadow map is fixed in the world by default and covers the
// route with kShadowMarginM around it; following the robot is the opt-in.
TEST(SceneBuilder, SunShadowMapIsFixedOverTheRouteUnlessItFollowsTheRobot) {
  scenes::Scenario s = station();
  const sim::SceneAssets a = sim::build_scene(s);
  const sim::ModelPtr m = sim::compile_scene(a);
  ASSERT_EQ(m->nlight, 1);
  EXPECT_EQ(m->light_bodyid[0], 0) << "the sun belongs to the world body";
  EXPECT_EQ(m->light_mode[0], mjCAMLIGHT_FIXED);
  const double half_width_m = m->vis.map.shadowclip * m->stat.extent;
  const int size_px = m->vis.quality.shadowsize;
  const double texel_m = sim::shadow_texel_m(half_width_m, size_px);
  EXPECT_LE(texel_m, sim::kShadowTexelTargetM);
  EXPECT_GT(texel_m, sim::kShadowTexelTargetM / 2) << "no larger map than the texel target needs";
  // every route point lies at least the margin inside the square, whatever its turn
  const Eigen::Vector2d centre(m->light_pos[0], m->light_pos[1]);
  const Eigen::Vector3d to_sun = -Eigen::Vector3d(m->light_dir[0], m->light_dir[1], m->light_dir[2]).normalized();
  const Eigen::Vector2d axis_xy = centre - 20.0 * to_sun.head<2>();  // the light sits 20 m towards the sun
  for (std::size_t i = 0; i + 1 < a.route_xy.size(); i += 2) {
    const Eigen::Vector2d p(a.route_xy[i], a.route_xy[i + 1]);
    EXPECT_LE((p - axis_xy).norm() + sim::kShadowMarginM, half_width_m + 1e-9);
  }

  s.light.shadow_follows_robot = true;
  const sim::ModelPtr f = sim::compile_scene(sim::build_scene(s));
  EXPECT_EQ(f->light_bodyid[0], mj_name2id(f.get(), mjOBJ_BODY, sim::kRobotBody));
  EXPECT_EQ(f->light_mode[0], mjCAMLIGHT_TRACK);
  EXPECT_NEAR(f->vis.map.shadowclip * f->stat.extent, 9.0, 1e-4);
  EXPECT_EQ(f->vis.quality.shadowsize, 1024);

  s.light.shadow_map_px = 512;  // an explicit size wins
  EXPECT_EQ(sim::compile_scene(sim::build_scene(s))->vis.quality.shadowsize, 512);
}

// identical_tables: every table of the array gets the same panel materials
// in the same places, so rows and tables look alike; without it each
// panel's dust variant is drawn on its own and the tables differ.
TEST(SceneBuilder, IdenticalTablesGiveEveryTableTheSamePanels) {
  scenes::Scenario s = station();
  const scenes::PvArray& arr = s.pv_arrays[0];
  ASSERT_GE(arr.rows * arr.tables_per_row, 4);
  // Tables whose panel materials differ from table a0r0t0's, panel by panel.
  const auto tables_unlike_the_first = [&](const scenes::Scenario& sc) {
    const sim::ModelPtr m = sim::compile_scene(sim::build_scene(sc));
    const auto material = [&](int row, int t, int line, int c) {
      const std::string name = "a0r" + std::to_string(row) + "t" + std::to_string(t) + "p" +
                               std::to_string(line) + "_" + std::to_string(c);
      const int id = mj_name2id(m.get(), mjOBJ_GEOM, name.c_str());
      EXPECT_GE(id, 0) << name;
      return id < 0 ? -1 : m->geom_matid[id];
    };
    int unlike = 0;
    for (int row = 0; row < arr.rows; ++row)
      for (int t = 0; t < arr.tables_per_row; ++t) {
        bool same = true;
        for (int line = 0; line < arr.panel_lines; ++line)
          for (int c = 0; c < arr.panels_per_table; ++c)
            same = same && material(row, t, line, c) == material(0, 0, line, c);
        if (!same) ++unlike;
      }
    return unlike;
  };
  EXPECT_EQ(tables_unlike_the_first(s), arr.rows * arr.tables_per_row - 1);
  s.pv_arrays[0].identical_tables = true;
  EXPECT_EQ(tables_unlike_the_first(s), 0);
}

namespace {

scenes::Scenario scene_file(const std::string& name) {
  return scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + name);
}

/// FNV-1a (64 bit) of the scene: the MJCF without its comment line (which
/// names the file's path) and every texture, name and bytes, in order.
std::uint64_t scene_fingerprint(const sim::SceneAssets& a) {
  std::uint64_t h = 14695981039346656037ULL;
  const auto add = [&h](const char* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      h ^= static_cast<unsigned char>(p[i]);
      h *= 1099511628211ULL;
    }
  };
  std::istringstream xml(a.xml);
  for (std::string line; std::getline(xml, line);)
    if (line.find("<!--") == std::string::npos) add(line.data(), line.size());
  for (const auto& [name, bytes] : a.files) {
    add(name.data(), name.size());
    add(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  }
  return h;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

}  // namespace

// Splitting the seed into the station's and the day's changed nothing of
// the scenes there were: pv_station and along_row build the very MJCF and
// textures they built before (fingerprints taken from the build before the
// split; the rendered frames follow from these bytes, and were compared
// with `pvbench record` before and after, docs/scenarios.md).
TEST(SceneBuilder, ExistingScenesAreTheBytesTheyWere) {
  EXPECT_EQ(scene_fingerprint(sim::build_scene(on_repeated_soil(scene_file("pv_station.yaml")))), 0xb96d0ddb6b8770c8ULL);
  EXPECT_EQ(scene_fingerprint(sim::build_scene(on_repeated_soil(scene_file("along_row.yaml")))), 0x9bc4ff330b6ccb88ULL);
  // A station seed equal to the seed is the file without one.
  scenes::Scenario s = scene_file("pv_station.yaml");
  const std::uint64_t plain = scene_fingerprint(sim::build_scene(s));
  s.station_seed = s.seed;
  EXPECT_EQ(scene_fingerprint(sim::build_scene(s)), plain);
}

// Two days of one station: the same MJCF but for what the day changes (the
// panels' angles and dust variants, the tube and backsheet that turn with
// them, the light, the names), and the same textures but for the panels'.
TEST(SceneBuilder, TwoDaysOfOneStationDifferOnlyInPanelsAndLight) {
  const scenes::Scenario morning = scene_file("days/tracker_station_0800.yaml");
  const scenes::Scenario afternoon = scene_file("days/tracker_station_1600.yaml");
  ASSERT_NE(morning.pv_arrays[0].rotation_deg, afternoon.pv_arrays[0].rotation_deg);
  const sim::SceneAssets a = sim::build_scene(morning), b = sim::build_scene(afternoon);
  const std::vector<std::string> la = lines_of(a.xml), lb = lines_of(b.xml);
  ASSERT_EQ(la.size(), lb.size());
  int panel_lines_differing = 0;
  for (std::size_t i = 0; i < la.size(); ++i) {
    if (la[i] == lb[i]) continue;
    const std::string& l = la[i];
    const bool panel = l.find("material=\"a0panel") != std::string::npos;
    const bool turning = l.find("material=\"backsheet\"") != std::string::npos ||
                         (l.find("material=\"steel\"") != std::string::npos && l.find("xyaxes") != std::string::npos);
    const bool day = l.find("<light name=\"sun\"") != std::string::npos || l.find("<headlight") != std::string::npos ||
                     l.find("<mujoco model=") != std::string::npos || l.find("<!--") != std::string::npos;
    EXPECT_TRUE(panel || turning || day) << "line " << i + 1 << " differs:\n" << la[i] << "\n" << lb[i];
    panel_lines_differing += panel ? 1 : 0;
  }
  EXPECT_GT(panel_lines_differing, 0);
  ASSERT_EQ(a.files.size(), b.files.size());
  for (std::size_t i = 0; i < a.files.size(); ++i) {
    const bool panel_texture = a.files[i].first.find("panel") != std::string::npos;
    EXPECT_EQ(a.files[i].second == b.files[i].second, !panel_texture) << a.files[i].first;
  }
  // The plants stand where they stood; a day's growth scales them there.
  scenes::Scenario grown = morning;
  grown.vegetation.growth = 1.5;
  const std::vector<std::string> lg = lines_of(sim::build_scene(grown).xml);
  const auto ground_xy = [](const std::string& line) {  // "x y" of pos="x y z"
    const std::size_t at = line.find("pos=\"") + 5;
    const std::string xyz = line.substr(at, line.find('"', at) - at);
    return xyz.substr(0, xyz.rfind(' '));
  };
  int plants = 0;
  for (std::size_t i = 0; i < la.size(); ++i) {
    const bool shrub = la[i].find("type=\"ellipsoid\"") != std::string::npos && la[i].find("name=\"shrub") != std::string::npos &&
                       la[i].find("b\" class") == std::string::npos;
    const bool trunk = la[i].find("_trunk\"") != std::string::npos;
    if (!shrub && !trunk) continue;
    ++plants;
    EXPECT_NE(la[i], lg[i]);                             // grown
    EXPECT_EQ(ground_xy(la[i]), ground_xy(lg[i])) << la[i];  // where it stood
  }
  EXPECT_GT(plants, 0);
}

TEST(SceneBuilder, AVariedGroundGivesEveryTileAlongTheRouteAnImageOfItsOwn) {
  const scenes::Scenario s = station();
  ASSERT_EQ(s.ground.tiling, scenes::GroundTiling::kVaried);  // the default
  const sim::SceneAssets a = sim::build_scene(s);
  const sim::ModelPtr m = sim::compile_scene(a);
  const int ground = mj_name2id(m.get(), mjOBJ_GEOM, "ground");
  ASSERT_GE(ground, 0);
  EXPECT_EQ(m->geom_group[ground], 3);  // not drawn, still what the robot drives on
  EXPECT_NE(m->geom_contype[ground], 0);
  std::vector<Eigen::Vector2d> centres;
  std::set<int> materials;
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_type[g] != mjGEOM_PLANE || g == ground || std::abs(m->geom_size[3 * g] - 1.5) > 1e-9) continue;
    EXPECT_EQ(m->geom_contype[g], 0);  // drawn only
    centres.emplace_back(m->geom_pos[3 * g], m->geom_pos[3 * g + 1]);
    materials.insert(m->geom_matid[g]);
  }
  EXPECT_GT(centres.size(), 10u);
  EXPECT_EQ(materials.size(), centres.size());
  // No two tiles show the same image: no place looks like another.
  std::set<std::vector<unsigned char>> images;
  for (const auto& [path, bytes] : a.files)
    if (path.rfind("textures/groundt", 0) == 0) {
      EXPECT_TRUE(images.insert(bytes).second) << path;
    }
  EXPECT_EQ(images.size(), centres.size());
  // Every point of the route lies on a tile.
  for (std::size_t k = 0; k + 1 < a.route_xy.size(); k += 2) {
    const Eigen::Vector2d p(a.route_xy[k], a.route_xy[k + 1]);
    EXPECT_TRUE(std::any_of(centres.begin(), centres.end(), [&](const Eigen::Vector2d& c) {
      return (p - c).cwiseAbs().maxCoeff() <= 1.5 + 1e-9;
    })) << p.transpose();
  }
  // The repeated ground has one drawn plane and no tiles.
  const sim::ModelPtr r = sim::compile_scene(sim::build_scene(on_repeated_soil(station())));
  int planes = 0;
  for (int g = 0; g < r->ngeom; ++g) planes += r->geom_type[g] == mjGEOM_PLANE ? 1 : 0;
  EXPECT_EQ(planes, 1);
  EXPECT_EQ(r->geom_group[mj_name2id(r.get(), mjOBJ_GEOM, "ground")], 0);
}

namespace {

scenes::Scenario rough_scene(const std::string& file) {
  return scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + file);
}

/// A geom's lowest and highest z (a box or cylinder standing upright).
std::pair<double, double> upright_z_range(const mjModel* m, const mjData* d, int g) {
  const double half = m->geom_type[g] == mjGEOM_CYLINDER ? m->geom_size[3 * g + 1] : m->geom_size[3 * g + 2];
  return {d->geom_xpos[3 * g + 2] - half, d->geom_xpos[3 * g + 2] + half};
}

}  // namespace

// The relief is a MuJoCo height field whose surface is GroundRelief's:
// rays cast down onto it at seeded random points land at height_m.
TEST(SceneBuilder, ReliefIsAHeightFieldThatMujocoAgreesWith) {
  const scenes::Scenario s = rough_scene("rough_station.yaml");
  const scenes::GroundRelief relief(s);
  const sim::ModelPtr m = sim::compile_scene(sim::build_scene(s));
  sim::DataPtr d(mj_makeData(m.get()));
  mj_forward(m.get(), d.get());
  const int ground = mj_name2id(m.get(), mjOBJ_GEOM, "ground");
  ASSERT_GE(ground, 0);
  ASSERT_EQ(m->geom_type[ground], mjGEOM_HFIELD);
  std::mt19937_64 rng(20261128);
  std::uniform_real_distribution<double> ux(-29.0, 29.0), uy(-19.0, 19.0);
  double worst = 0;
  for (int i = 0; i < 300; ++i) {
    const double x = ux(rng), y = uy(rng);
    const mjtNum from[3] = {x, y, 10.0}, down[3] = {0, 0, -1};
    const mjtNum dist = mj_rayHfield(m.get(), d.get(), ground, from, down);
    ASSERT_GT(dist, 0) << x << " " << y;
    worst = std::max(worst, std::abs((10.0 - dist) - relief.height_m(x, y)));
    // The true surface's normal of the height field is GroundRelief's too.
    const Eigen::Vector3d p(x, y, 10.0 - dist);
    EXPECT_LT((sim::geom_normal(m.get(), d.get(), ground, p, p + Eigen::Vector3d(0, 0, 1)) - relief.normal(x, y)).norm(),
              1e-4);
  }
  EXPECT_LT(worst, 1e-4);  // within 0.1 mm (MuJoCo keeps the samples as floats)
  // The relief is not flat: a few centimetres of roughness over the slope.
  EXPECT_GT(relief.grid().max_m() - relief.grid().min_m(), 1.0);
}

// Posts reach into the ground under them; tables keep their height above
// the ground at their centre; walls, shrubs and trees stand on it.
TEST(SceneBuilder, EverythingStandsOnTheRelief) {
  const scenes::Scenario rough = rough_scene("rough_station.yaml"), flat = station();
  const scenes::GroundRelief relief(rough);
  const sim::ModelPtr mr = sim::compile_scene(sim::build_scene(rough));
  const sim::ModelPtr mf = sim::compile_scene(sim::build_scene(flat));
  sim::DataPtr dr(mj_makeData(mr.get())), df(mj_makeData(mf.get()));
  mj_forward(mr.get(), dr.get());
  mj_forward(mf.get(), df.get());
  const auto z_of = [](const mjModel* m, const mjData* d, const char* name) {
    const int g = mj_name2id(m, mjOBJ_GEOM, name);
    EXPECT_GE(g, 0) << name;
    return g < 0 ? 0.0 : d->geom_xpos[3 * g + 2];
  };
  const scenes::PvArray& a = rough.pv_arrays[0];
  const Eigen::Vector2d centre = scenes::array_to_world(a, a.table_length_m() / 2,
                                                        a.table_depth_m() / 2 * std::cos(a.tilt_deg * M_PI / 180));
  EXPECT_NEAR(z_of(mr.get(), dr.get(), "a0r0t0p1_3") - z_of(mf.get(), df.get(), "a0r0t0p1_3"),
              relief.height_m(centre), 1e-5);
  int posts = 0;
  for (int g = 0; g < mr->ngeom; ++g) {
    const int mat = mr->geom_matid[g];
    if (mat < 0 || std::string(mj_id2name(mr.get(), mjOBJ_MATERIAL, mat)) != "steel" || mr->geom_size[3 * g + 2] < 0.2)
      continue;
    const auto [bottom, top] = upright_z_range(mr.get(), dr.get(), g);
    const double ground = relief.height_m(dr->geom_xpos[3 * g], dr->geom_xpos[3 * g + 1]);
    EXPECT_NEAR(bottom, ground - 0.15, 1e-5);
    EXPECT_GT(top, ground + 0.3);
    ++posts;
  }
  EXPECT_EQ(posts, 16);
  const int wall = mj_name2id(mr.get(), mjOBJ_GEOM, "wall0");
  const scenes::Wall& w = rough.walls[0];
  const double lowest = std::min(relief.height_m(w.start_m), relief.height_m(w.end_m));
  EXPECT_GT(mr->geom_size[3 * wall + 1] * 2, w.height_m + 0.15 - 1e-9);  // a box, local y up
  EXPECT_LT(dr->geom_xpos[3 * wall + 2] - mr->geom_size[3 * wall + 1], lowest - 0.15 + 1e-9);
  EXPECT_NEAR(dr->geom_xpos[3 * wall + 2] + mr->geom_size[3 * wall + 1],
              relief.height_m(0.5 * (w.start_m + w.end_m)) + w.height_m, 1e-5);
  // Plants stand where they stood on flat ground, on the ground there.
  for (const char* plant : {"shrub0", "shrub7", "tree11_crown"}) {
    const int g = mj_name2id(mr.get(), mjOBJ_GEOM, plant);
    ASSERT_GE(g, 0) << plant;
    EXPECT_NEAR(dr->geom_xpos[3 * g + 2] - relief.height_m(dr->geom_xpos[3 * g], dr->geom_xpos[3 * g + 1]),
                z_of(mf.get(), df.get(), plant), 1e-5)
        << plant;
  }
  const int trunk = mj_name2id(mr.get(), mjOBJ_GEOM, "tree11_trunk");
  EXPECT_NEAR(upright_z_range(mr.get(), dr.get(), trunk).first,
              relief.height_m(dr->geom_xpos[3 * trunk], dr->geom_xpos[3 * trunk + 1]) - 0.15, 1e-5);
}

// A route too long for the varied ground's tiles is one error that names
// the way out; on the repeated soil the same route builds.
TEST(SceneBuilder, ARouteTooLongForVariedTilesSaysToRepeat) {
  scenes::Scenario s = scenes::parse_scenario(R"(
name: long_drive
seed: 2
duration_s: 5
ground: {size_m: [400, 40]}
route: {waypoints_m: [[-180, 0], [180, 0]], speed_mps: 0.5}
)",
                                              "long.yaml");
  ASSERT_EQ(s.ground.tiling, scenes::GroundTiling::kVaried);
  try {
    sim::build_scene(s);
    ADD_FAILURE() << "a 360 m route built a varied ground";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("ground.tiling"), std::string::npos) << what;
    EXPECT_NE(what.find("or tiling: repeat"), std::string::npos) << what;
  }
  s.ground.tiling = scenes::GroundTiling::kRepeat;
  EXPECT_NO_THROW(sim::build_scene(s));
}

// rough_station is pv_station on a relief: without it, the same scene.
TEST(SceneBuilder, RoughStationIsPvStationOnARelief) {
  scenes::Scenario rough = rough_scene("rough_station.yaml");
  const scenes::Scenario flat = on_repeated_soil(station());  // the soil a relief takes
  ASSERT_TRUE(rough.ground.relief);
  rough.ground.relief.reset();
  EXPECT_NE(rough.physics.rate_hz, flat.physics.rate_hz);
  rough.name = flat.name;
  rough.source_file = flat.source_file;
  rough.station_seed.reset();
  rough.physics = flat.physics;  // its body: the 600 Hz step and the ramped wheels
  rough.robot = flat.robot;
  EXPECT_EQ(sim::build_scene(rough).xml, sim::build_scene(flat).xml);
}

// The soil's friction, when the day gives it, governs the tyres' contact
// (the ground's priority); without it MuJoCo takes the larger, the tyres'
// 1.2.  The caster stays frictionless either way.
TEST(SceneBuilder, SoilFrictionGovernsTheTyresContact) {
  const auto contact_friction = [](const std::string& file) {
    const sim::ModelPtr m = sim::compile_scene(sim::build_scene(rough_scene(file)));
    sim::DataPtr d(mj_makeData(m.get()));
    for (int i = 0; i < 200; ++i) mj_step(m.get(), d.get());  // settled on its wheels and caster
    const int ground = mj_name2id(m.get(), mjOBJ_GEOM, "ground"), caster = mj_name2id(m.get(), mjOBJ_GEOM, "caster");
    std::vector<double> wheels;
    double caster_mu = -1;
    for (int c = 0; c < d->ncon; ++c) {
      const mjContact& k = d->contact[c];
      if (k.geom1 != ground && k.geom2 != ground) continue;
      if (k.geom1 == caster || k.geom2 == caster)
        caster_mu = k.dim == 1 ? 0.0 : k.friction[0];
      else
        wheels.push_back(k.friction[0]);
    }
    EXPECT_GE(wheels.size(), 2u) << file;
    EXPECT_EQ(caster_mu, 0.0) << file;
    return wheels.empty() ? -1.0 : *std::max_element(wheels.begin(), wheels.end());
  };
  EXPECT_DOUBLE_EQ(contact_friction("rough_station.yaml"), 1.2);
  EXPECT_DOUBLE_EQ(contact_friction("days/rough_station_dry.yaml"), 0.65);
  EXPECT_DOUBLE_EQ(contact_friction("days/rough_station_wet.yaml"), 0.4);
}
