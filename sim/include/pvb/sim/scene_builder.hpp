#pragma once
// Scenario -> MJCF.  The generated model holds the station (ground, PV
// arrays, brick walls, vegetation), the sun and the robot with its camera.
#include <mujoco/mujoco.h>

#include <memory>
#include <string>
#include <vector>

#include "pvb/scenes/scenario.hpp"

namespace pvb::sim {

/// A generated scene: scene.xml plus the texture files it names.
struct SceneAssets {
  std::string xml;
  std::vector<std::pair<std::string, std::vector<unsigned char>>> files;  ///< path relative to scene.xml, PNG bytes
  double timestep_s = 0.002;   ///< physics step; an exact divisor of the frame period
  int substeps = 17;           ///< physics steps per camera frame
  double max_scene_depth_m = 100;  ///< anything farther than this is sky
  std::vector<double> route_xy;    ///< route polyline, x0 y0 x1 y1 ...
};

/// Generates the scene.  Deterministic in the scenario (seed included).
SceneAssets build_scene(const scenes::Scenario& scenario);

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

/// Compiles the assets with MuJoCo (from memory, no disk).  Throws Error
/// carrying MuJoCo's message on failure.
ModelPtr compile_scene(const SceneAssets& assets);

/// Writes scene.xml and the texture files under `dir` (created if needed).
void write_scene(const SceneAssets& assets, const std::string& dir);

/// Names used in the generated model.
inline constexpr const char* kCameraName = "rgbd";
inline constexpr const char* kRobotBody = "robot";
inline constexpr const char* kLeftActuator = "wheel_left";
inline constexpr const char* kRightActuator = "wheel_right";

}  // namespace pvb::sim
