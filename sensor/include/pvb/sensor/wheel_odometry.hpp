#pragma once
// Differential-drive odometry from wheel encoder counts.
#include <cstdint>
#include <optional>

#include "pvb/geometry/se3.hpp"
#include "pvb/sensor/motion.hpp"

namespace pvb::sensor {

/// The planar pose of the base in the odometry frame (where the first
/// reading found it: the origin, heading along x) and its body speeds.
struct OdometryState {
  std::int64_t t_ns = 0;
  double x_m = 0, y_m = 0, yaw_rad = 0;
  double v_mps = 0;     ///< forward speed over the last interval
  double w_radps = 0;   ///< turn rate over the last interval
};

/// Where the base at T_w_b is in the odometry frame that starts at T_w_b0
/// (origin there, x along its heading, z up): the planar position that
/// odometry from T_w_b0 should give.
Eigen::Vector2d odometry_frame_position(const geom::SE3d& T_w_b0, const geom::SE3d& T_w_b);

/// Integrates encoder counts: each wheel's arc from its count change, the
/// base moving along the arc's chord at the mean heading of the interval.
class WheelOdometry {
 public:
  explicit WheelOdometry(const DriveDescription& d) : d_(d) {}
  /// The first reading sets the counts and the time; every later one moves
  /// the state on.  Readings must come in time order.
  void add(const WheelTicks& t);
  const OdometryState& state() const { return state_; }
  /// Distance a wheel rolls a count, metres.
  double metres_per_tick() const;

 private:
  DriveDescription d_;
  std::optional<WheelTicks> last_;
  OdometryState state_;
};

}  // namespace pvb::sensor
