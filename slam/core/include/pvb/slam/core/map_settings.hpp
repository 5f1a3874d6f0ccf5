#pragma once
// What a saved map was made with (map_file.hpp): the camera, ORB and
// vocabulary settings a run must share to use it, and the motion sensors'
// extrinsics.
#include <array>
#include <cstdint>
#include <string>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/core/sensor_settings.hpp"

namespace pvb::slam {

/// What a map was made with.  A map is used only by a run whose settings
/// match, and never with another vocabulary.
struct MapSettings {
  // The camera and ORB settings: in HEAD.
  double fx = 0, fy = 0, cx = 0, cy = 0, bf = 0;
  std::uint32_t width = 0, height = 0;
  std::array<double, 5> distortion{};  ///< k1 k2 p1 p2 k3
  double th_depth_m = 0;
  double depth_factor = 0;  ///< raw depth units per metre (DepthMapFactor)
  double scale_factor = 0;  ///< ORB pyramid
  std::uint32_t num_levels = 0;
  std::uint32_t num_features = 0;
  std::uint64_t vocabulary = 0;  ///< place::Vocabulary::fingerprint()
  // The motion sensors: in INER, so only in a map with a trusted inertial
  // state; a map without one reads back as kCamera (its visual map is all
  // it holds).
  sensor::SensorSetup sensors = sensor::SensorSetup::kCamera;
  /// IMU.T_b_c1, the camera in the IMU (body) frame; used when
  /// uses_accel(sensors), the identity otherwise.
  geom::SE3d T_b_c = geom::SE3d::Identity();
  /// Robot.T_base_c1, the camera in the base frame; used when
  /// uses_wheels(sensors), the identity otherwise.
  geom::SE3d T_base_c = geom::SE3d::Identity();

  /// The first setting that differs from `run`'s, as "NAME: VALUE in the
  /// map, VALUE in this run"; empty when they agree.  The depth factor is
  /// not compared (a source's raw units; the map holds metres), nor the
  /// sensor setup: a camera-only map serves a run with an IMU (which finds
  /// gravity itself) and a map with inertial state serves a camera-only run
  /// (the visual map is the same).  When both the map and the run use an
  /// accelerometer, T_b_c must agree within kMaxExtrinsicShiftM and
  /// kMaxExtrinsicTurnDeg, and T_base_c too when both use the wheels.
  std::string difference(const MapSettings& run) const;
};

}  // namespace pvb::slam
