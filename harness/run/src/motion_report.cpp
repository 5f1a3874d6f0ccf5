#include "motion_report.hpp"

#include <cmath>

#include "pvb/geometry/time.hpp"

namespace pvb::run {

MotionReportBuilder::MotionReportBuilder(const geom::SE3d& T_b_i, const sensor::DriveDescription& drive)
    : R_b_i_(T_b_i.linear()), odometry_(drive) {}

void MotionReportBuilder::add(const FrameItem& item) {
  for (std::size_t k = 0; k < item.frame.imu.size() && k < item.imu_truth.size(); ++k) {
    r_.imu_t_s.push_back(geom::ns_to_seconds(item.frame.imu[k].t_ns));
    r_.yaw_rate_measured.push_back((R_b_i_ * item.frame.imu[k].gyro_radps).z());
    r_.yaw_rate_true.push_back((R_b_i_ * item.imu_truth[k].gyro_radps).z());
  }
  for (std::size_t k = 0; k < item.frame.wheel_ticks.size() && k < item.wheel_truth.size(); ++k) {
    const sim::WheelTruth& truth = item.wheel_truth[k];
    if (!T_w_b0_) T_w_b0_ = truth.T_w_b;
    odometry_.add(item.frame.wheel_ticks[k]);
    const Eigen::Vector2d p_true = sensor::odometry_frame_position(*T_w_b0_, truth.T_w_b);
    const sensor::OdometryState& o = odometry_.state();
    const double step = r_.distance_m.empty() ? 0.0 : (p_true - last_true_).norm();
    last_true_ = p_true;
    r_.odo_t_s.push_back(geom::ns_to_seconds(o.t_ns));
    r_.odo_x_m.push_back(o.x_m);
    r_.odo_y_m.push_back(o.y_m);
    r_.true_x_m.push_back(p_true.x());
    r_.true_y_m.push_back(p_true.y());
    r_.distance_m.push_back((r_.distance_m.empty() ? 0.0 : r_.distance_m.back()) + step);
    r_.drift_m.push_back((Eigen::Vector2d(o.x_m, o.y_m) - p_true).norm());
    if (!truth.carried) {
      slip_sum_ += std::abs(truth.slip.x()) + std::abs(truth.slip.y());
      slip_count_ += 2;
    }
  }
  r_.mean_abs_slip = slip_count_ > 0 ? slip_sum_ / slip_count_ : 0.0;
}

}  // namespace pvb::run
