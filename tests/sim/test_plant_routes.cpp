// The shipped plants' day routes, whole (label slow, minutes each): the
// robot's physics over an hour's drive, and culled frames against frames
// drawn whole at 100 places along each kilometre.
#include <gtest/gtest.h>

#include <string>

#include "pvb/scenes/route.hpp"
#include "pvb/sim/renderer.hpp"
#include "sim_scenarios.hpp"

namespace pvb::test {
namespace plant_routes_test {

constexpr const char* kPlants[] = {"plants/plant_10mw_fixed", "plants/plant_10mw_tracker"};

scenes::Scenario shipped(const std::string& name) {
  return scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + name + ".yaml");
}

TEST(PlantRoutes, AnHoursDriveThroughEachShippedPlantStaysOnItsRoute) {
  for (const char* name : kPlants) expect_route_driven_to_its_end(name);
}

TEST(PlantRoutes, CulledFramesMatchFramesDrawnWholeAlongTheKilometre) {
  for (const char* name : kPlants) {
    scenes::Scenario s = shipped(name);
    const double length_m = scenes::polyline_length(scenes::route_polyline(s));
    for (int place = 0; place < 10; ++place) {
      s.route.start_m = length_m * place / 10.0;
      sim::Simulator sim(s);
      sim::Renderer culled(sim.model(), sim::GlBackend::kAuto, 640, 480);
      sim::Renderer whole(sim.model(), sim::GlBackend::kAuto, 640, 480);
      whole.set_culling(false);
      for (int frame = 0; frame < 10; ++frame) {
        cv::Mat rgb_c, depth_c, rgb_w, depth_w;
        culled.render(sim.model(), sim.data(), sim.camera_id(), &rgb_c, &depth_c);
        whole.render(sim.model(), sim.data(), sim.camera_id(), &rgb_w, &depth_w);
        EXPECT_EQ(cv::norm(rgb_c, rgb_w, cv::NORM_INF), 0.0) << name << " at " << s.route.start_m << " m";
        EXPECT_EQ(cv::norm(depth_c, depth_w, cv::NORM_INF), 0.0) << name << " at " << s.route.start_m << " m";
        EXPECT_GT(culled.culled_geoms(), sim.model()->ngeom / 2) << name << " at " << s.route.start_m << " m";
        for (int k = 0; k < 3; ++k) sim.advance();
      }
    }
  }
}

}  // namespace plant_routes_test
}  // namespace pvb::test
