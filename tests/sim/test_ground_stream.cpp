// A ground of shared soil images shows every tile near the camera with an
// image of its own, held in a bounded set of slots and drawn as the camera
// nears it; what is drawn depends on where the camera is, not on the drive
// that brought it there.
#include <gtest/gtest.h>

#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "pvb/scenes/route.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/ground_stream.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/sim/textures.hpp"

namespace pvb::test {
namespace ground_stream_test {

/// Six rows of a small plant on shared soil images, driven through three
/// aisles and round the headlands.
scenes::Scenario streamed(const std::string& extra = "") {
  return scenes::parse_scenario("name: streamed\nseed: 3\nduration_s: 120\n"
                                "ground: {size_m: [160, 120], tiling: varied, soil_images: 4" +
                                    extra +
                                    "}\n"
                                    "plant: {origin_m: [-30, -20], rows: 6, tables_per_row: 2, modules_per_table: 20}\n"
                                    "route: {pattern: lawnmower, aisles: 3}\n"
                                    "camera: {width: 160, height: 120, fx: 131.25, fy: 131.25}\n",
                                "streamed.yaml");
}

/// The pixels of texture `tex` of a model.
std::vector<unsigned char> texels(const mjModel* m, int tex) {
  const unsigned char* p = m->tex_rgb + m->tex_adr[tex];
  return {p, p + static_cast<std::size_t>(m->tex_width[tex]) * m->tex_height[tex] * 3};
}

Eigen::Vector3d eye(const Eigen::Vector2d& p) { return {p.x(), p.y(), 0.6}; }

TEST(GroundStream, NearTilesShowImagesOfTheirOwnWhateverTheDriveBefore) {
  const scenes::Scenario s = streamed(", unique_within_m: 9");
  const sim::SceneAssets a = sim::build_scene(s, sim::SceneDetail::kFull, sim::TextureEncoding::kPixels);
  sim::ModelPtr driven = sim::compile_scene(a), fresh = sim::compile_scene(a);
  sim::GroundStream along(driven.get(), s), here(fresh.get(), s);
  const std::vector<Eigen::Vector2d> route = scenes::route_polyline(s);
  ASSERT_GT(route.size(), 100u);
  const int slots = static_cast<int>(along.slot_textures().size());
  EXPECT_EQ(slots, sim::unique_ground_slots(s.ground.unique_within_m));  // 62: the scene has room for them
  // Drive the route: the slots hold every near tile wherever the camera is.
  std::size_t most_near = 0;
  for (std::size_t i = 0; i < route.size(); i += 20) {
    along.update(eye(route[i]));
    most_near = std::max(most_near, along.near_tiles().size());
  }
  EXPECT_LE(most_near, static_cast<std::size_t>(slots));
  EXPECT_GT(most_near, static_cast<std::size_t>(slots) / 2);  // the bound is not loose
  EXPECT_GT(along.images_drawn(), static_cast<std::uint64_t>(slots));  // slots were reused
  // Back to where the drive began, and a fresh stream there.
  along.update(eye(route.front()));
  here.update(eye(route.front()));
  ASSERT_EQ(along.near_tiles(), here.near_tiles());
  const double near_m = s.ground.unique_within_m + sim::kGroundTileM / std::sqrt(2.0);
  const std::vector<sim::GroundTile> tiles = sim::ground_tiles(s);
  const int first = mj_name2id(driven.get(), mjOBJ_GEOM, "ground") + 2;
  const std::vector<int> near_list = here.near_tiles();
  const std::set<int> near(near_list.begin(), near_list.end());
  for (int k = 0; k < here.tile_count(); ++k) {
    const bool close = (tiles[static_cast<std::size_t>(k)].centre_m - route.front()).norm() <= near_m;
    EXPECT_EQ(near.count(k) == 1, close) << "tile " << k;
    const int tex_a = along.texture_of_geom(first + k), tex_b = here.texture_of_geom(first + k);
    if (!close) {
      EXPECT_EQ(tex_a, -1);
      EXPECT_EQ(tex_b, -1);
      continue;
    }
    // The same picture, the tile's own, whichever slot holds it.
    const cv::Mat own = sim::make_ground_texture(
        tiles[static_cast<std::size_t>(k)].gravel ? scenes::GroundType::kGravel : s.ground.type, here.tile_seed(k));
    ASSERT_GE(tex_a, 0);
    ASSERT_GE(tex_b, 0);
    EXPECT_EQ(texels(driven.get(), tex_a), texels(fresh.get(), tex_b)) << "tile " << k;
    EXPECT_EQ(std::memcmp(fresh->tex_rgb + fresh->tex_adr[tex_b], own.data, own.total() * 3), 0) << "tile " << k;
  }
  // Every tile's own image is a different one.
  std::set<std::uint64_t> seeds;
  for (int k = 0; k < here.tile_count(); ++k) seeds.insert(here.tile_seed(k));
  EXPECT_EQ(seeds.size(), static_cast<std::size_t>(here.tile_count()));
}

TEST(GroundStream, RendersTheSameFrameAfterAnyDriveAndOnlyWithItsSlots) {
  const scenes::Scenario s = streamed(", unique_within_m: 9");
  sim::Simulator sim(s);
  ASSERT_NE(sim.ground_stream(), nullptr);
  sim::Renderer early(sim.model(), sim::GlBackend::kAuto, 160, 120);
  early.set_ground_stream(sim.ground_stream());
  cv::Mat rgb, depth;
  for (int i = 0; i < 90; ++i) {  // 3 s: new tiles come near, their slots are uploaded
    early.render(sim.model(), sim.data(), sim.camera_id(), &rgb, &depth);
    sim.advance();
  }
  const std::uint64_t drawn = sim.ground_stream()->images_drawn();
  EXPECT_GT(drawn, static_cast<std::uint64_t>(sim.ground_stream()->near_tiles().size()));
  sim::Renderer late(sim.model(), sim::GlBackend::kAuto, 160, 120), shared(sim.model(), sim::GlBackend::kAuto, 160, 120);
  late.set_ground_stream(sim.ground_stream());
  cv::Mat rgb_early, rgb_late, rgb_shared;
  early.render(sim.model(), sim.data(), sim.camera_id(), &rgb_early, &depth);
  late.render(sim.model(), sim.data(), sim.camera_id(), &rgb_late, &depth);
  shared.render(sim.model(), sim.data(), sim.camera_id(), &rgb_shared, &depth);
  EXPECT_EQ(cv::norm(rgb_early, rgb_late, cv::NORM_INF), 0.0);
  // Without the stream the near ground shows the shared images instead.
  cv::Mat diff;
  cv::absdiff(rgb_early, rgb_shared, diff);
  EXPECT_GT(cv::countNonZero(diff.reshape(1) > 20), 500);
}

TEST(GroundStream, OffWhereTheGroundHasNoSharedImagesOrTheUserTurnsItOff) {
  EXPECT_FALSE(sim::GroundStream::wanted(streamed(", unique_within_m: 0"), sim::SceneDetail::kFull));
  // The slots take what the renderer's 100 textures leave: with 12 m (93
  // wanted) the scene has room for fewer, and the stream takes those.
  const sim::SceneAssets wide = sim::build_scene(streamed(", unique_within_m: 12"), sim::SceneDetail::kFull,
                                                 sim::TextureEncoding::kPixels);
  int textures = 0;
  for (std::size_t at = wide.xml.find("<texture "); at != std::string::npos; at = wide.xml.find("<texture ", at + 1))
    ++textures;
  EXPECT_EQ(textures, sim::kMaxSceneTextures);
  EXPECT_LT(textures, 30 + sim::unique_ground_slots(12));
  // A scene that would need more textures than the renderer holds is refused.
  try {
    sim::build_scene(scenes::parse_scenario("ground: {size_m: [160, 120], tiling: varied, soil_images: 97}\n"
                                            "route: {waypoints_m: [[0, 0], [30, 0]]}\n",
                                            "many.yaml"));
    FAIL() << "a scene of more than 100 textures";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("ground.soil_images: expected a scene of at most 100 textures"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(sim::GroundStream::wanted(streamed(), sim::SceneDetail::kGeometry));
  EXPECT_TRUE(sim::GroundStream::wanted(streamed(), sim::SceneDetail::kFull));
  const sim::SceneAssets off = sim::build_scene(streamed(", unique_within_m: 0"), sim::SceneDetail::kFull,
                                                sim::TextureEncoding::kPixels);
  EXPECT_EQ(off.xml.find(sim::kGroundSlotPrefix), std::string::npos);
  try {
    scenes::parse_scenario("ground: {size_m: [60, 60], unique_within_m: 8}\n", "unique.yaml");
    FAIL() << "unique_within_m without soil_images";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("unique.yaml:1: ground.unique_within_m: expected unique_within_m with "
                                         "soil_images only"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace ground_stream_test
}  // namespace pvb::test
