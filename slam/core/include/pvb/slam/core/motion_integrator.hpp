#pragma once
// The motion sensors on the tracking side: each frame's IMU and encoder
// readings preintegrated since the previous frame and since the last
// keyframe, the accelerometer's recent mean for the tilt of a keyframe
// (camera + accelerometer), and the prediction of a frame's pose from the
// last one.  The readings come with the frames (sensor::RgbdFrame).
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/sensor/motion.hpp"
#include "pvb/slam/core/keyframe_motion.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/inertial/imu_preintegration.hpp"
#include "pvb/slam/inertial/wheel_preintegration.hpp"

namespace pvb::slam {

class MotionIntegrator {
 public:
  /// Seconds of accelerometer readings averaged for a keyframe's tilt.
  static constexpr double kTiltWindowS = 0.2;

  explicit MotionIntegrator(const MotionSensorSettings& sensors);

  /// Adds the readings that came with the frame at t_ns (those since the
  /// previous frame); starts a new since-last-frame interval.
  void add_frame(std::int64_t t_ns, const std::vector<sensor::ImuSample>& imu,
                 const std::vector<sensor::WheelTicks>& ticks);

  /// Readings since the previous frame and since the last keyframe, at the
  /// current bias (empty before the first readings).
  const ImuPreintegration& imu_since_frame() const { return imu_frame_; }
  const ImuPreintegration& imu_since_keyframe() const { return imu_kf_; }
  const WheelPreintegration& wheels_since_frame() const { return wheel_frame_; }
  const WheelPreintegration& wheels_since_keyframe() const { return wheel_kf_; }

  /// Ends the keyframe interval at the current frame and begins the next.
  KeyframeInterval take_keyframe_interval();

  /// The bias the intervals are integrated at; a new one re-integrates
  /// the open intervals.
  const ImuBias& bias() const { return bias_; }
  void set_bias(const ImuBias& b);

  /// The wheels' calibration encoder intervals are read with.  A new one
  /// applies to the open intervals if the wheels have not moved in them
  /// yet, else from the next: counts are not kept to read them again.
  const WheelCalibration& wheel_calibration() const { return wheel_calibration_; }
  void set_wheel_calibration(const WheelCalibration& c);

  /// The accelerometer's mean over the last kTiltWindowS in the camera
  /// frame (specific force, pointing up), if any: the map's first frame is
  /// levelled with it.
  std::optional<Eigen::Vector3d> recent_specific_force_c() const;
  /// RMS distance of those readings from their mean (0 without readings).
  double recent_spread_mps2() const;

  /// The frame after `last` (IMU state of the last frame: attitude and
  /// position from its camera pose, velocity v_w) by the readings since it,
  /// with gravity g_w; with wheels the translation follows the encoders,
  /// rotated by the IMU's attitude.  Returns T_c_w.
  geom::SE3d predict(const geom::SE3d& T_c_w_last, const Eigen::Vector3d& v_w_last, const Eigen::Vector3d& g_w,
                     Eigen::Vector3d* v_w_out) const;

  /// The IMU frame's state from a camera pose and a velocity.
  NavState nav_state(const geom::SE3d& T_c_w, const Eigen::Vector3d& v_w) const;
  /// The camera pose of an IMU state.
  geom::SE3d camera_pose(const NavState& s) const;

  sensor::SensorSetup setup() const { return setup_; }
  const ImuSettings& imu_settings() const { return imu_; }
  const RobotSettings& robot_settings() const { return robot_; }
  /// Readings have come (a source without them leaves the intervals empty).
  bool has_imu() const { return imu_count_ > 0; }
  bool has_wheels() const { return last_ticks_.has_value(); }

 private:
  void add_imu(const sensor::ImuSample& s);
  void add_ticks(const sensor::WheelTicks& t);
  /// Credits the wheels up to the frame at the last interval's rate.
  void wheels_up_to(std::int64_t t_ns);

  sensor::SensorSetup setup_;
  ImuSettings imu_;
  sensor::ImuNoise imu_noise_;  ///< imu_.fused_noise(): what the preintegrations weigh
  RobotSettings robot_;
  std::int64_t period_ns_;          ///< the IMU's reading period
  std::int64_t encoder_period_ns_;  ///< the encoders' reading period
  ImuBias bias_;
  WheelCalibration wheel_calibration_;
  ImuPreintegration imu_frame_, imu_kf_;
  WheelPreintegration wheel_frame_, wheel_kf_;
  /// Holds the newest reading from its time up to the frame's t_ns.
  void integrate_up_to(std::int64_t t_ns);

  std::optional<std::int64_t> last_imu_t_ns_;  ///< the newest reading's time
  std::optional<std::int64_t> covered_t_ns_;   ///< integrated up to here
  std::optional<sensor::ImuSample> last_reading_;
  std::optional<sensor::WheelTicks> last_ticks_;
  /// Counts per nanosecond of the last encoder interval, and the counts
  /// already credited past last_ticks_ (up to a frame between readings).
  std::optional<Eigen::Vector2d> tick_rate_per_ns_;
  Eigen::Vector2d ticks_ahead_ = Eigen::Vector2d::Zero();
  std::size_t imu_count_ = 0;
  /// Accelerometer readings of the last kTiltWindowS (time, camera frame).
  std::deque<std::pair<std::int64_t, Eigen::Vector3d>> recent_f_c_;
};

}  // namespace pvb::slam
