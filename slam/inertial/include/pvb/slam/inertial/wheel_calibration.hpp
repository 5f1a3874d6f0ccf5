#pragma once
// The wheels calibrated online: each wheel's rolling radius and the track
// fitted, by linear least squares, to the base's motion between keyframes
// as the map holds it (vision and the IMU), so that the encoders' increments
// can be believed where the map cannot check them.
#include "pvb/slam/inertial/wheel_preintegration.hpp"

namespace pvb::slam {

struct WheelCalibrationOptions {
  bool enabled = true;
  double min_rolled_m = 20.0;       ///< the radii are estimated past this much rolling
  double min_turned_rad = 6.2832;   ///< the track past this much turning (one full turn in all)
  double gate_arc_m = 0.05;         ///< an interval whose arc misfits by more (plus gate_fraction) is refused
  double gate_yaw_rad = 0.02;       ///< ... or whose turn misfits by more (plus gate_fraction)
  double gate_fraction = 0.1;       ///< of the interval's own arc or turn
  double prior_m2 = 0.01;           ///< weight of "as described" (m^2 of rolling), so that a fit always exists
};

/// The calibrator's normal equations (WheelCalibrator's model below), all
/// a fit needs to go on where it stopped: a map saves them.
struct WheelFitSums {
  Eigen::Matrix2d turn_normal = Eigen::Matrix2d::Zero();  ///< sum of f f^T, f = (R - L, R + L)
  Eigen::Vector2d turn_rhs = Eigen::Vector2d::Zero();     ///< sum of f yaw b
  // Sums of the arc rows: m = (L + R) / 2, n = (R - L) / 2, a the arc.
  double mm = 0, mn = 0, nn = 0, am = 0, an = 0;
  bool operator==(const WheelFitSums& o) const {
    return turn_normal == o.turn_normal && turn_rhs == o.turn_rhs && mm == o.mm && mn == o.mn && nn == o.nn &&
           am == o.am && an == o.an;
  }
};

/// A calibrator's state as others read it (the map holds the newest).
struct WheelFit {
  WheelCalibration calibration;  ///< as described until the drive has shown otherwise
  bool radii_known = false, track_known = false;
  int intervals = 0, refused = 0;  ///< intervals fitted and refused
  double rolled_m = 0, turned_rad = 0;
  WheelFitSums sums;
  double described_track_m = 0;   ///< the track the sums were taken with
  double described_radius_m = 0;  ///< the wheels' radius they were taken with (0: not said)
};

/// Fits, with L and R each wheel's described arc over an interval and b the
/// described track, the base's arc s_w (L + R) / 2 (1 + rho (R - L) / (R + L))
/// and its turn (s_w / k) ((R - L) + rho (R + L)) / b, where the wheels' radii
/// are s_w (1 -+ rho) times the described one and the track k times.  In
/// u = s_w / k and v = u rho both are linear; the turn fixes u and v, the
/// arc then s_w.  A straight observes rho and s_w, a turn k.
class WheelCalibrator {
 public:
  WheelCalibrator(double described_track_m, const WheelCalibrationOptions& options = {});

  /// One interval: the wheels' described arcs (m, signed) and the base's
  /// motion as the map holds it, its arc along the chord (m) and its turn
  /// (rad).  Returns false when the interval is refused (it misfits the
  /// fit so far by more than the gates: slip, a bad pose).
  bool add(double left_m, double right_m, double arc_m, double yaw_rad);

  /// Goes on from `fit` (a saved map's): its sums and counts replace this
  /// calibrator's.  False, and nothing changed, when it was taken with
  /// another described track or holds a value that is not finite.
  bool resume(const WheelFit& fit);

  /// The fit so far: 1 for a factor not yet observed.
  WheelCalibration estimate() const;
  /// The estimate with what it rests on.
  WheelFit fit() const;
  bool radii_known() const { return rolled_m_ >= options_.min_rolled_m; }
  bool track_known() const { return turned_rad_ >= options_.min_turned_rad; }

  double rolled_m() const { return rolled_m_; }     ///< arc rolled over the intervals taken
  double turned_rad() const { return turned_rad_; } ///< turn over the intervals taken
  int intervals() const { return intervals_; }
  int refused() const { return refused_; }

 private:
  /// [u, v] from the turn rows and the prior.
  Eigen::Vector2d turn_fit() const;
  /// s_w from the arc rows at a ratio rho.
  double scale_fit(double rho) const;
  /// The model's arc and turn for an interval at the fit so far.
  Eigen::Vector2d predict(double left_m, double right_m) const;

  double track_m_;
  WheelCalibrationOptions options_;
  WheelFitSums sums_;
  double rolled_m_ = 0, turned_rad_ = 0;
  int intervals_ = 0, refused_ = 0;
};

}  // namespace pvb::slam
