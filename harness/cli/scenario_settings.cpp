#include "scenario_settings.hpp"

namespace pvb::cli {

dataset::OrbSlamSettings settings_for_scenario(const scenes::Scenario& s) {
  dataset::OrbSlamSettings o;
  o.K = {s.camera.fx, s.camera.fy, s.camera.cx(), s.camera.cy(), s.camera.width, s.camera.height};
  o.fps = s.camera.fps;
  o.bf = s.camera.depth_noise.baseline_m * s.camera.fx;
  // ThDepth is in baselines: points beyond depth_range max are "far".
  o.th_depth = s.camera.depth_range_m.y() / s.camera.depth_noise.baseline_m;
  o.rgb_order = 1;
  return o;
}

}  // namespace pvb::cli
