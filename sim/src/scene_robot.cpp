// The robot and the sun, as MJCF: the differential-drive body at the
// start of the driven route with its wheels, caster, mast and cameras, and
// the sun's directional light (with the robot or fixed in the world).
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "scene_mjcf.hpp"

namespace pvb::sim::mjcf {
namespace {

/// The unit vector towards the sun.
Eigen::Vector3d to_sun(const scenes::Light& light) {
  const double az = light.sun_azimuth_deg * kDeg, el = light.sun_elevation_deg * kDeg;
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

/// The sun: a directional light whose position only places its shadow map
/// (ShadowMap), in `mode` (track: in the robot's body, fixed offset and
/// orientation in the world frame; fixed: in the world body).
std::string sun_line(const scenes::Light& light, const std::string& mode, const Eigen::Vector3d& pos) {
  const double I = light.intensity;
  return "<light name=\"sun\" mode=\"" + mode + "\" directional=\"true\" castshadow=\"" +
         std::string(light.shadows ? "true" : "false") + "\" pos=\"" + v3(pos) + "\" dir=\"" + v3(-to_sun(light)) +
         "\" diffuse=\"" + v3(I, I, I * 0.96) + "\" specular=\"" + v3(0.5 * I, 0.5 * I, 0.5 * I) + "\"/>";
}

/// The chassis, caster, the two driven wheels and the mast.
void add_robot_parts(XmlWriter& x, const scenes::Scenario& s) {
  const scenes::Robot& rb = s.robot;
  const double r = rb.wheel_radius_m;
  x.line("<freejoint name=\"robot_free\"/>");
  x.line("<geom name=\"chassis\" type=\"box\" size=\"0.30 " + f(0.5 * rb.track_m - 0.05) + " 0.07\" pos=\"-0.12 0 0.05\" "
         "mass=\"18\" material=\"robot\"/>");
  // Frictionless: its priority above the ground's (1 when the soil's friction is given) makes its own govern.
  x.line("<geom name=\"caster\" type=\"sphere\" size=\"0.04\" pos=\"" + v3(-scenes::kRobotWheelBaseM, 0, 0.04 - r) +
         "\" mass=\"0.3\" condim=\"1\" priority=\"" + (s.ground.governs_contact() ? "2" : "1") +
         "\" friction=\"0 0 0\" rgba=\"0.2 0.2 0.2 1\"/>");
  for (int side = 0; side < 2; ++side) {
    const double y = (side == 0 ? 1 : -1) * 0.5 * rb.track_m;
    const std::string n = side == 0 ? kLeftActuator : kRightActuator;
    x.open("<body name=\"" + n + "\" pos=\"" + v3(0, y, 0) + "\">");
    x.line("<joint name=\"" + n + "\" type=\"hinge\" axis=\"0 1 0\" armature=\"0.01\" damping=\"0.02\"/>");
    const double r_side = side == 0 ? rb.left_radius_m() : rb.right_radius_m();
    x.line("<geom type=\"cylinder\" size=\"" + f(r_side) + " 0.025\" euler=\"90 0 0\" mass=\"1.5\" condim=\"3\" "
           "friction=\"1.2 0.01 0.001\" material=\"tyre\"/>");
    x.close("</body>");
  }
  const double mast_h = s.camera.mount_height_m - r;
  x.line("<geom name=\"mast\" type=\"cylinder\" size=\"0.02 " + f(mast_h / 2) + "\" pos=\"" +
         v3(s.camera.mount_forward_m - 0.05, 0, mast_h / 2) + "\" mass=\"0.5\" rgba=\"0.3 0.3 0.3 1\"/>");
}

/// The robot's body at its start: on flat ground 2 mm above it, heading
/// yaw0; on a relief tilted to the plane through the ground under its two
/// wheels and its caster, 10 mm above it (it settles before frame 0).
std::string robot_body_line(const scenes::Scenario& s, const scenes::GroundRelief& ground, const Eigen::Vector2d& start,
                            double yaw0) {
  const double r = s.robot.wheel_radius_m;
  const std::string open = "<body name=\"" + std::string(kRobotBody) + "\" pos=\"";
  if (ground.flat()) return open + v3(start.x(), start.y(), r + 0.002) + "\" euler=\"0 0 " + f(yaw0 / kDeg) + "\">";
  const Eigen::Vector2d ahead(std::cos(yaw0), std::sin(yaw0)), left(-ahead.y(), ahead.x());
  const double hl = ground.height_m(start + 0.5 * s.robot.track_m * left);
  const double hr = ground.height_m(start - 0.5 * s.robot.track_m * left);
  const double hc = ground.height_m(start - scenes::kRobotWheelBaseM * ahead), axle = 0.5 * (hl + hr);
  const double pitch = -std::atan2(axle - hc, scenes::kRobotWheelBaseM);  // about +y: positive turns the nose down
  const double roll = std::atan2(hl - hr, s.robot.track_m);               // about +x: positive lifts the left wheel
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw0, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return open + v3(start.x(), start.y(), axle + r + 0.010) + "\" quat=\"" + f(q.w()) + " " + v3(q.vec()) + "\">";
}

}  // namespace

void add_robot_and_sun(XmlWriter& x, const scenes::Scenario& s, const std::vector<Eigen::Vector2d>& driven,
                       const ShadowMap& shadow, const scenes::GroundRelief& ground) {
  const scenes::Camera& cam = s.camera;
  const double r = s.robot.wheel_radius_m;
  const Eigen::Vector2d start = driven.empty() ? Eigen::Vector2d::Zero() : driven.front();
  double yaw0 = 0;
  if (driven.size() >= 2) {
    const Eigen::Vector2d d = driven[std::min<std::size_t>(10, driven.size() - 1)] - driven.front();
    yaw0 = std::atan2(d.y(), d.x());
  }
  x.open(robot_body_line(s, ground, start, yaw0));
  add_robot_parts(x, s);
  const double mast_h = cam.mount_height_m - r;
  // Camera: MuJoCo cameras look along -z with y up.  Forward direction from
  // yaw (left positive) and pitch (up positive) in the robot frame.
  const double p = cam.pitch_deg * kDeg, yw = cam.yaw_deg * kDeg;
  const Eigen::Vector3d fwd(std::cos(p) * std::cos(yw), std::cos(p) * std::sin(yw), std::sin(p));
  const Eigen::Vector3d right(std::sin(yw), -std::cos(yw), 0);
  const Eigen::Vector3d up = right.cross(fwd);
  x.line("<camera name=\"" + std::string(kCameraName) + "\" pos=\"" + v3(cam.mount_forward_m, 0, mast_h) +
         "\" xyaxes=\"" + v3(right) + " " + v3(up) + "\" fovy=\"" + f(cam.fovy_deg()) + "\"/>");
  if (cam.model == scenes::CameraKind::kD435) {  // the two infrared imagers, beside the colour camera
    const Eigen::Vector3d left = Eigen::Vector3d(cam.mount_forward_m, 0, mast_h) - cam.stereo.colour_offset_m * right;
    const std::string axes = "\" xyaxes=\"" + v3(right) + " " + v3(up) + "\" fovy=\"" + f(cam.stereo.ir_fovy_deg()) + "\"/>";
    x.line("<camera name=\"" + std::string(kIrLeftCameraName) + "\" pos=\"" + v3(left) + axes);
    x.line("<camera name=\"" + std::string(kIrRightCameraName) + "\" pos=\"" +
           v3(left + cam.stereo.baseline_m * right) + axes);
  }
  if (shadow.follows_robot) x.line(sun_line(s.light, "track", to_sun(s.light) * 20.0));
  x.close("</body>");
  if (!shadow.follows_robot)
    x.line(sun_line(s.light, "fixed",
                    Eigen::Vector3d(shadow.centre_xy_m.x(), shadow.centre_xy_m.y(), 0) + to_sun(s.light) * 20.0));
}

}  // namespace pvb::sim::mjcf
