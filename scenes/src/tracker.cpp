#include "pvb/scenes/tracker.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "pvb/common/text.hpp"
#include "pvb/geometry/angles.hpp"

namespace pvb::scenes {
namespace {

using geom::cos_deg;
using geom::kDegToRad;
using geom::kRadToDeg;
using geom::sin_deg;


// True-tracking angle: the sun vector in the tracker frame, projected on its
// x-z plane (Anderson and Mikofski 2020, eqs. 4-5; pvlib
// shading.projected_solar_zenith_angle).  With the panel normal turned to
// this angle the sun lies in the plane of the normal and the axis.
double ideal_angle_deg(double zenith_deg, double azimuth_deg, const SingleAxisTracker& t) {
  const Eigen::Vector3d s = sun_direction_enu(zenith_deg, azimuth_deg);
  const double ca = cos_deg(t.axis_azimuth_deg), sa = sin_deg(t.axis_azimuth_deg);
  const double ct = cos_deg(t.axis_tilt_deg), st = sin_deg(t.axis_tilt_deg);
  const double sx_axis = s.x() * ca - s.y() * sa;
  const double sz_axis = (s.x() * sa + s.y() * ca) * st + s.z() * ct;
  return std::atan2(sx_axis, sz_axis) * kRadToDeg;
}

}  // namespace

std::optional<std::string> tracker_error(const SingleAxisTracker& t) {
  if (!(t.axis_tilt_deg >= -90.0 && t.axis_tilt_deg <= 90.0))
    return "axis tilt " + format_g(t.axis_tilt_deg) + " deg is outside [-90, 90]";
  if (!std::isfinite(t.axis_azimuth_deg))
    return "axis azimuth " + format_g(t.axis_azimuth_deg) + " deg is not finite";
  if (!(t.max_angle_deg > 0.0 && t.max_angle_deg <= 180.0))
    return "max angle " + format_g(t.max_angle_deg) + " deg is outside (0, 180]";
  if (!(t.gcr > 0.0 && t.gcr <= 1.0)) return "ground coverage ratio " + format_g(t.gcr) + " is outside (0, 1]";
  if (!(t.cross_axis_tilt_deg > -90.0 && t.cross_axis_tilt_deg < 90.0))
    return "cross-axis tilt " + format_g(t.cross_axis_tilt_deg) + " deg is outside (-90, 90)";
  return std::nullopt;
}

std::optional<TrackerRotation> tracker_rotation(double apparent_zenith_deg, double solar_azimuth_deg,
                                                const SingleAxisTracker& t) {
  if (tracker_error(t) || !std::isfinite(solar_azimuth_deg) || !(apparent_zenith_deg <= 90.0))
    return std::nullopt;
  TrackerRotation out;
  out.ideal_deg = ideal_angle_deg(apparent_zenith_deg, solar_azimuth_deg, t);
  out.sun_behind = std::abs(out.ideal_deg) > 90.0;
  double angle = out.ideal_deg;
  if (t.backtrack) {
    // Rows one pitch apart, in module widths across the slope; the shadow of
    // one row reaches the next when this distance times the cosine of the
    // sun's angle from the slope normal drops below 1, and the rotation that
    // makes the shadow end just at the next row is the ideal angle minus
    // acos of that product (Anderson and Mikofski 2020, eqs. 14-16).
    const double axes_distance = 1.0 / (t.gcr * cos_deg(t.cross_axis_tilt_deg));
    const double reach = std::abs(axes_distance * cos_deg(out.ideal_deg - t.cross_axis_tilt_deg));
    if (reach < 1.0) {
      const double sign = out.ideal_deg > 0.0 ? 1.0 : (out.ideal_deg < 0.0 ? -1.0 : 0.0);
      angle = out.ideal_deg - sign * std::acos(reach) * kRadToDeg;
      out.backtracking = sign != 0.0;
    }
  }
  // max_angle is measured from the axis' zero rotation, not from the slope.
  out.rotation_deg = std::clamp(angle, -t.max_angle_deg, t.max_angle_deg);
  out.clipped = out.rotation_deg != angle;
  return out;
}

Eigen::Vector3d sun_direction_enu(double zenith_deg, double solar_azimuth_deg) {
  const double sz = sin_deg(zenith_deg);
  return {sz * sin_deg(solar_azimuth_deg), sz * cos_deg(solar_azimuth_deg), cos_deg(zenith_deg)};
}

Eigen::Vector3d tracker_axis_enu(const SingleAxisTracker& t) {
  const double ct = cos_deg(t.axis_tilt_deg);
  return {sin_deg(t.axis_azimuth_deg) * ct, cos_deg(t.axis_azimuth_deg) * ct, -sin_deg(t.axis_tilt_deg)};
}

Eigen::Vector3d tracker_normal_enu(double rotation_deg, const SingleAxisTracker& t) {
  // Turn the up vector about the tracker's y, tilt that frame's y down by the
  // axis tilt (about x), then turn it from north to the axis azimuth
  // (clockwise seen from above, so negative about z).
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(-t.axis_azimuth_deg * kDegToRad, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-t.axis_tilt_deg * kDegToRad, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(rotation_deg * kDegToRad, Eigen::Vector3d::UnitY()))
                                .toRotationMatrix();
  return r * Eigen::Vector3d::UnitZ();
}

}  // namespace pvb::scenes
