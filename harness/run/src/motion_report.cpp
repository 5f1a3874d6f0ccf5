#include "motion_report.hpp"

#include <cmath>
#include <iterator>

#include "pvb/geometry/time.hpp"

namespace pvb::run {

namespace {
/// Rows kept of each series: 82 s of IMU readings (200 Hz), 5.5 minutes
/// of wheel readings (50 Hz) at full rate, evenly thinned past that.
constexpr std::size_t kMaxRows = 16384;
}  // namespace

MotionReportBuilder::MotionReportBuilder(const geom::SE3d& T_b_i, const sensor::DriveDescription& drive)
    : R_b_i_(T_b_i.linear()), odometry_(drive), imu_(3, kMaxRows), odo_(7, kMaxRows) {}

void MotionReportBuilder::add(const FrameItem& item) {
  for (std::size_t k = 0; k < item.frame.imu.size() && k < item.imu_truth.size(); ++k)
    imu_.add({geom::ns_to_seconds(item.frame.imu[k].t_ns), (R_b_i_ * item.frame.imu[k].gyro_radps).z(),
              (R_b_i_ * item.imu_truth[k].gyro_radps).z()});
  for (std::size_t k = 0; k < item.frame.wheel_ticks.size() && k < item.wheel_truth.size(); ++k) {
    const sim::WheelTruth& truth = item.wheel_truth[k];
    if (!T_w_b0_) T_w_b0_ = truth.T_w_b;
    odometry_.add(item.frame.wheel_ticks[k]);
    const Eigen::Vector2d p_true = sensor::odometry_frame_position(*T_w_b0_, truth.T_w_b);
    const sensor::OdometryState& o = odometry_.state();
    if (odo_.rows_added() > 0) distance_m_ += (p_true - last_true_).norm();
    last_true_ = p_true;
    odo_.add({geom::ns_to_seconds(o.t_ns), o.x_m, o.y_m, p_true.x(), p_true.y(), distance_m_,
              (Eigen::Vector2d(o.x_m, o.y_m) - p_true).norm()});
    if (!truth.carried) {
      slip_sum_ += std::abs(truth.slip.x()) + std::abs(truth.slip.y());
      slip_count_ += 2;
    }
  }
}

MotionSensorsReport MotionReportBuilder::report() const {
  MotionSensorsReport r;
  r.imu_t_s = imu_.column(0);
  r.yaw_rate_measured = imu_.column(1);
  r.yaw_rate_true = imu_.column(2);
  std::vector<double>* odo[] = {&r.odo_t_s,  &r.odo_x_m,    &r.odo_y_m, &r.true_x_m,
                                &r.true_y_m, &r.distance_m, &r.drift_m};
  for (std::size_t c = 0; c < std::size(odo); ++c) *odo[c] = odo_.column(c);
  r.mean_abs_slip = slip_count_ > 0 ? slip_sum_ / static_cast<double>(slip_count_) : 0.0;
  return r;
}

}  // namespace pvb::run
