#pragma once
// Gathers a run's motion sensor readings and their truth, frame by frame,
// into the report's MotionSensorsReport; an hour's readings are thinned to
// a figure's worth (ThinnedSeries).
#include "frame_producer.hpp"
#include "pvb/report/report.hpp"
#include "pvb/report/thinned_series.hpp"
#include "pvb/sensor/wheel_odometry.hpp"

namespace pvb::run {

class MotionReportBuilder {
 public:
  /// T_b_i: the IMU in the base; drive: the description odometry uses.
  MotionReportBuilder(const geom::SE3d& T_b_i, const sensor::DriveDescription& drive);
  void add(const FrameItem& item);
  /// The series so far, each ending with its latest reading.
  MotionSensorsReport report() const;

 private:
  Eigen::Matrix3d R_b_i_;
  sensor::WheelOdometry odometry_;
  std::optional<geom::SE3d> T_w_b0_;  ///< the base's first pose: the odometry frame's origin
  Eigen::Vector2d last_true_ = Eigen::Vector2d::Zero();
  double slip_sum_ = 0;
  long slip_count_ = 0;
  double distance_m_ = 0;
  ThinnedSeries imu_;   ///< t, measured and true yaw rate
  ThinnedSeries odo_;   ///< t, odometry x y, true x y, distance, drift
};

}  // namespace pvb::run
