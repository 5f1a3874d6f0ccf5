// The shipped plants' routes, whole (label slow, minutes each): the
// robot's physics over an hour's drive, and culled frames against frames
// drawn whole at 100 places along each kilometre.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include <opencv2/core.hpp>

#include "pvb/scenes/route.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/textures.hpp"
#include "sim_scenarios.hpp"

namespace pvb::test {
namespace plant_routes_test {

/// The plants with a day's kilometre: the cull leaves out more than half
/// of their geoms wherever the robot is (not so on the patrol's roads,
/// along which both lines of blocks lie in view).
constexpr const char* kKilometrePlants[] = {"plants/plant_10mw_fixed", "plants/plant_10mw_tracker",
                                            "plants/plant_10mw_tracker_rough"};
/// Every shipped plant (the kilometre plants and the patrol of four
/// blocks), and the rough plant's day on wet, soft earth.
constexpr const char* kPlants[] = {"plants/plant_10mw_fixed", "plants/plant_10mw_tracker",
                                   "plants/plant_10mw_tracker_rough", "plants/plant_tracker_blocks_roads",
                                   "days/plant_10mw_tracker_rough_wet"};
/// The colour tolerance of a culled frame (far ground tiles left out):
/// mean absolute difference, and the share of pixels off by more than 30 levels.
constexpr double kMeanAbsLevels = 1.0, kShareOver30 = 0.01;

scenes::Scenario shipped(const std::string& name) {
  return scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + name + ".yaml");
}

TEST(PlantRoutes, AnHoursDriveThroughEachShippedPlantStaysOnItsRoute) {
  for (const char* name : kPlants) expect_route_driven_to_its_end(name);
}

/// Culled frames against frames drawn whole: depth exact within the
/// camera's range; colour exact but where a far ground tile was left out
/// (docs/plants.md states the tolerance).
struct FrameDiff {
  double mean_abs = 0;      ///< mean absolute colour difference, levels
  double share_over_30 = 0; ///< share of pixels with a channel off by more than 30 levels
  int depth_in_range_differs = 0;
};

FrameDiff compare(const cv::Mat& rgb_a, const cv::Mat& depth_a, const cv::Mat& rgb_b, const cv::Mat& depth_b,
                  float range_m) {
  FrameDiff d;
  cv::Mat diff;
  cv::absdiff(rgb_a, rgb_b, diff);
  d.mean_abs = cv::mean(diff.reshape(1))[0];
  std::vector<cv::Mat> ch;
  cv::split(diff, ch);
  const cv::Mat over = (ch[0] > 30) | (ch[1] > 30) | (ch[2] > 30);
  d.share_over_30 = static_cast<double>(cv::countNonZero(over)) / over.total();
  const cv::Mat in_range = (depth_a <= range_m) | (depth_b <= range_m);
  d.depth_in_range_differs = cv::countNonZero((depth_a != depth_b) & in_range);
  return d;
}

TEST(PlantRoutes, CulledFramesMatchFramesDrawnWholeAlongTheKilometre) {
  for (const char* name : kKilometrePlants) {
    scenes::Scenario s = shipped(name);
    const double length_m = scenes::polyline_length(scenes::route_polyline(s));
    double worst_mean = 0, worst_share = 0;
    for (int place = 0; place < 10; ++place) {
      s.route.start_m = length_m * place / 10.0;
      sim::Simulator sim(s);
      sim::Renderer culled(sim.model(), sim::GlBackend::kAuto, 640, 480);
      sim::Renderer whole(sim.model(), sim::GlBackend::kAuto, 640, 480);
      culled.set_far_tile_cull_m(s.ground.soil_images > 0 ? s.camera.fx * sim::kSoilFeatureM / 0.5 : 0.0);
      whole.set_culling(false);
      culled.set_ground_stream(sim.ground_stream());  // the near tiles' own images, in both
      whole.set_ground_stream(sim.ground_stream());
      for (int frame = 0; frame < 10; ++frame) {
        cv::Mat rgb_c, depth_c, rgb_w, depth_w;
        culled.set_shadow_floor_z_m(sim.shadow_floor_z_m());
        culled.render(sim.model(), sim.data(), sim.camera_id(), &rgb_c, &depth_c);
        whole.render(sim.model(), sim.data(), sim.camera_id(), &rgb_w, &depth_w);
        const FrameDiff d = compare(rgb_c, depth_c, rgb_w, depth_w, static_cast<float>(s.camera.depth_range_m.y()));
        worst_mean = std::max(worst_mean, d.mean_abs);
        worst_share = std::max(worst_share, d.share_over_30);
        EXPECT_EQ(d.depth_in_range_differs, 0) << name << " at " << s.route.start_m << " m";
        EXPECT_LE(d.mean_abs, kMeanAbsLevels) << name << " at " << s.route.start_m << " m";
        EXPECT_LE(d.share_over_30, kShareOver30) << name << " at " << s.route.start_m << " m";
        EXPECT_GT(culled.culled_geoms(), sim.model()->ngeom / 2) << name << " at " << s.route.start_m << " m";
        for (int k = 0; k < 3; ++k) sim.advance();
      }
    }
    std::printf("%s: worst mean colour difference %.3f levels, worst share of pixels off by > 30: %.4f\n", name,
                worst_mean, worst_share);
  }
}

}  // namespace plant_routes_test
}  // namespace pvb::test
