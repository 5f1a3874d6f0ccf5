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

/// A calibrator's state as others read it (the map holds the newest).
struct WheelFit {
  WheelCalibration calibration;  ///< as described until the drive has shown otherwise
  bool radii_known = false, track_known = false;
  int intervals = 0, refused = 0;  ///< intervals fitted and refused
  double rolled_m = 0, turned_rad = 0;
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
  Eigen::Matrix2d turn_normal_ = Eigen::Matrix2d::Zero();
  Eigen::Vector2d turn_rhs_ = Eigen::Vector2d::Zero();
  // Sums of the arc rows: m = (L + R) / 2, n = (R - L) / 2, a the arc.
  double s_mm_ = 0, s_mn_ = 0, s_nn_ = 0, s_am_ = 0, s_an_ = 0;
  double rolled_m_ = 0, turned_rad_ = 0;
  int intervals_ = 0, refused_ = 0;
};

}  // namespace pvb::slam
