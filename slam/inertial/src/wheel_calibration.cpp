// Online wheel calibration by linear least squares (the odometry
// calibration of Antonelli, Caccavale, Grossi and Marino, "Simultaneous
// calibration of odometry and camera for a differential drive mobile robot",
// ICRA 2010, with the map's keyframe motion in place of the camera's).
#include "pvb/slam/inertial/wheel_calibration.hpp"

#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

namespace pvb::slam {

WheelCalibrator::WheelCalibrator(double described_track_m, const WheelCalibrationOptions& options)
    : track_m_(described_track_m), options_(options) {
  if (!(described_track_m > 0) || !(options.prior_m2 > 0) || !(options.gate_arc_m > 0) ||
      !(options.gate_yaw_rad > 0) || !(options.gate_fraction >= 0))
    throw std::invalid_argument("WheelCalibrator: the track, the prior and the gates must be positive");
}

Eigen::Vector2d WheelCalibrator::turn_fit() const {
  const double w = options_.prior_m2;
  const Eigen::Matrix2d A = sums_.turn_normal + w * Eigen::Matrix2d::Identity();
  const Eigen::Vector2d b = sums_.turn_rhs + Eigen::Vector2d(w, 0);
  return A.lu().solve(b);
}

double WheelCalibrator::scale_fit(double rho) const {
  const double w = options_.prior_m2;
  return (sums_.am + rho * sums_.an + w) / (sums_.mm + 2 * rho * sums_.mn + rho * rho * sums_.nn + w);
}

Eigen::Vector2d WheelCalibrator::predict(double left_m, double right_m) const {
  const Eigen::Vector2d uv = turn_fit();
  const double rho = uv.x() != 0 ? uv.y() / uv.x() : 0.0;
  const double s = scale_fit(rho);
  const double m = 0.5 * (left_m + right_m), n = 0.5 * (right_m - left_m);
  return {s * (m + rho * n), (uv.x() * (right_m - left_m) + uv.y() * (right_m + left_m)) / track_m_};
}

bool WheelCalibrator::add(double left_m, double right_m, double arc_m, double yaw_rad) {
  if (!std::isfinite(left_m) || !std::isfinite(right_m) || !std::isfinite(arc_m) || !std::isfinite(yaw_rad)) {
    ++refused_;
    return false;
  }
  const Eigen::Vector2d expected = predict(left_m, right_m);
  const bool check_arc = radii_known(), check_yaw = radii_known() || track_known();
  if ((check_arc && std::abs(arc_m - expected.x()) > options_.gate_arc_m + options_.gate_fraction * std::abs(arc_m)) ||
      (check_yaw &&
       std::abs(yaw_rad - expected.y()) > options_.gate_yaw_rad + options_.gate_fraction * std::abs(yaw_rad))) {
    ++refused_;
    return false;
  }
  const Eigen::Vector2d f(right_m - left_m, right_m + left_m);
  sums_.turn_normal += f * f.transpose();
  sums_.turn_rhs += f * (yaw_rad * track_m_);
  const double m = 0.5 * (left_m + right_m), n = 0.5 * (right_m - left_m);
  sums_.mm += m * m;
  sums_.mn += m * n;
  sums_.nn += n * n;
  sums_.am += arc_m * m;
  sums_.an += arc_m * n;
  rolled_m_ += std::abs(m);
  turned_rad_ += std::abs(right_m - left_m) / track_m_;
  ++intervals_;
  return true;
}

WheelCalibration WheelCalibrator::estimate() const {
  WheelCalibration c;
  const Eigen::Vector2d uv = turn_fit();
  if (!(uv.x() > 0)) return c;
  const double rho = radii_known() ? uv.y() / uv.x() : 0.0;
  const double s = radii_known() ? scale_fit(rho) : 1.0;
  if (radii_known()) {
    c.left_scale = s * (1 - rho);
    c.right_scale = s * (1 + rho);
  }
  if (track_known()) c.track_scale = scale_fit(rho) / uv.x();
  return c;
}

WheelFit WheelCalibrator::fit() const {
  return {estimate(), radii_known(), track_known(), intervals_, refused_, rolled_m_, turned_rad_, sums_, track_m_};
}

bool WheelCalibrator::resume(const WheelFit& fit) {
  const WheelFitSums& f = fit.sums;
  const bool finite = f.turn_normal.allFinite() && f.turn_rhs.allFinite() && std::isfinite(f.mm) &&
                      std::isfinite(f.mn) && std::isfinite(f.nn) && std::isfinite(f.am) && std::isfinite(f.an) &&
                      std::isfinite(fit.rolled_m) && std::isfinite(fit.turned_rad);
  if (!finite || fit.described_track_m != track_m_ || fit.intervals < 0 || fit.refused < 0 || fit.rolled_m < 0 ||
      fit.turned_rad < 0)
    return false;
  sums_ = f;
  rolled_m_ = fit.rolled_m;
  turned_rad_ = fit.turned_rad;
  intervals_ = fit.intervals;
  refused_ = fit.refused;
  return true;
}

}  // namespace pvb::slam
