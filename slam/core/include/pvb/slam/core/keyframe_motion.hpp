#pragma once
// What a keyframe keeps of the motion sensors: the readings from the
// keyframe before it in time, preintegrated, and its inertial state.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>

#include "pvb/slam/inertial/imu_preintegration.hpp"
#include "pvb/slam/inertial/wheel_preintegration.hpp"

namespace pvb::slam {

class KeyFrame;

/// The readings of the interval that ends at a keyframe.
struct KeyframeInterval {
  std::shared_ptr<const ImuPreintegration> imu;       ///< null without gyro readings
  std::shared_ptr<const WheelPreintegration> wheels;  ///< null without encoders
  /// The accelerometer's mean specific force over a short window before
  /// the keyframe, in the camera frame, and the spread of the readings
  /// about it (RMS, m/s^2); unset without readings.
  std::optional<Eigen::Vector3d> f_c_mps2;
  double f_spread_mps2 = 0;
};

/// A keyframe's place in time and its inertial state.  Read and written
/// under the map's mutex.
struct KeyFrameMotion {
  std::weak_ptr<KeyFrame> prev, next;  ///< neighbours in time (null at the ends)
  KeyframeInterval from_prev;          ///< the readings since prev
  bool has_state = false;              ///< v_w and bias estimated (inertial initialisation done)
  Eigen::Vector3d v_w_mps = Eigen::Vector3d::Zero();  ///< the IMU's velocity in the world
  ImuBias bias;
};

/// The map's inertial frame: gravity once it is known.
struct MapGravity {
  bool ready = false;  ///< inertial initialisation done: gravity, velocities and biases trusted
  Eigen::Vector3d g_w = Eigen::Vector3d(0, 0, -9.81);  ///< gravity in the map's frame
  ImuBias bias;        ///< the newest keyframe's bias after the last local BA
  /// When the inertial state became trusted: at which keyframe, its time,
  /// and the RMS of the initialisation's whitened residuals.
  std::uint64_t ready_keyframe_id = 0;
  std::int64_t ready_t_ns = 0;
  double init_rms = 0;
};

}  // namespace pvb::slam
