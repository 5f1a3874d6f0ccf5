#pragma once
// Single-axis trackers: the rotation of a torque tube that follows the sun,
// with backtracking, as pvlib's pvlib.tracking.singleaxis computes it
// (Anderson and Mikofski, "Slope-Aware Backtracking for Single-Axis
// Trackers", NREL/TP-5K00-76626, 2020; Lorenzo et al., "Tracking and
// back-tracking", Prog. Photovolt. 19(6), 2011).  Pure functions, no state;
// docs/sun_and_trackers.md gives the conventions and the reference values.
//
// Frames.  ENU: x east, y north, z up.  Tracker frame (pvlib's): y along the
// axis, pointing to axis_azimuth_deg and down by axis_tilt_deg; x horizontal,
// 90 degrees clockwise from y seen from above; z = x cross y, upwards.  The
// rotation is right-handed about y: for a horizontal north-south axis with
// axis_azimuth_deg = 180 (y south, x west) a positive rotation turns the
// panels to face west (afternoon), a negative one east (morning).
#include <Eigen/Core>
#include <optional>
#include <string>

namespace pvb::scenes {

/// A row of single-axis trackers.  Angles in degrees.
struct SingleAxisTracker {
  /// [-90, 90]; positive: the axis goes down towards axis_azimuth_deg.
  double axis_tilt_deg = 0.0;
  /// Direction of the axis, clockwise from north; 180 for a north-south axis.
  double axis_azimuth_deg = 180.0;
  /// (0, 180]: the rotation stays in [-max, max].  pvlib's default is 90;
  /// 55 is a common mechanical limit.
  double max_angle_deg = 55.0;
  /// Turn back from the sun so that rows do not shade each other.
  bool backtrack = true;
  /// Ground coverage ratio, (0, 1]: module width across the tube / row pitch.
  double gcr = 2.0 / 7.0;
  /// (-90, 90): slope across the rows, right-handed about the axis (pvlib).
  double cross_axis_tilt_deg = 0.0;
};

/// Why `t` is not a valid tracker, in one line, or nullopt when it is.
std::optional<std::string> tracker_error(const SingleAxisTracker& t);

struct TrackerRotation {
  /// After backtracking and clipping to +-max_angle_deg.
  double rotation_deg = 0.0;
  /// True tracking, [-180, 180]: the sun lies in the plane of the panel
  /// normal and the axis.
  double ideal_deg = 0.0;
  /// The backtracking correction changed the angle.
  bool backtracking = false;
  /// The rotation was clipped to +-max_angle_deg.
  bool clipped = false;
  /// The sun is above the horizon but below the plane through the axis and
  /// the tracker's x (only possible with a tilted axis): |ideal_deg| > 90.
  bool sun_behind = false;
};

/// The tracker's rotation for the sun at apparent zenith and azimuth
/// (degrees, azimuth clockwise from north).  nullopt when the sun is below
/// the horizon (apparent zenith > 90; pvlib returns NaN) or when
/// tracker_error(t) has a reason.
std::optional<TrackerRotation> tracker_rotation(double apparent_zenith_deg, double solar_azimuth_deg,
                                                const SingleAxisTracker& t);

/// Unit vector towards the sun in ENU from its zenith and azimuth (degrees).
Eigen::Vector3d sun_direction_enu(double zenith_deg, double solar_azimuth_deg);

/// Unit vector along the axis in ENU, pointing to axis_azimuth_deg and down
/// by axis_tilt_deg (the tracker's y).  The panels' rotation is a
/// right-handed turn by rotation_deg about this vector (an axis-angle
/// rotation, as MuJoCo's axisangle takes it).
Eigen::Vector3d tracker_axis_enu(const SingleAxisTracker& t);

/// Unit normal of the panels' front face in ENU at a rotation (degrees):
/// R_z(-axis_azimuth) R_x(-axis_tilt) R_y(rotation) (0, 0, 1), the
/// convention of pvlib's tracking._unit_normal.
Eigen::Vector3d tracker_normal_enu(double rotation_deg, const SingleAxisTracker& t);

}  // namespace pvb::scenes
