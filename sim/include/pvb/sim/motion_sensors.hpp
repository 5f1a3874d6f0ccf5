#pragma once
// The robot's IMU and wheel encoders, read from MuJoCo's physics state
// step by step (docs/sensors.md), and Kalibr's IMU noise model.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sensor/motion.hpp"
#include "pvb/sensor/wheel_odometry.hpp"

typedef struct mjModel_ mjModel;
typedef struct mjData_ mjData;

namespace pvb::sim {

/// The truth behind one IMU reading.
struct ImuTruth {
  std::int64_t t_ns = 0;
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();  ///< noise-free reading
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();  ///< noise-free reading
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   ///< bias in the reading, rad/s
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  ///< bias in the reading, m/s^2
  geom::SE3d T_w_i = geom::SE3d::Identity();             ///< the IMU's pose at t_ns
  Eigen::Vector3d v_w_i = Eigen::Vector3d::Zero();       ///< its velocity in the world, m/s
};

/// The truth behind one encoder reading: per wheel (left, right) the
/// commanded and the actual wheel speed, the forward speed of the wheel's
/// centre over the ground, and the slip (wheel speed x radius - ground
/// speed) / the larger of the two (0 rolling, > 0 spinning, < 0 skidding).
struct WheelTruth {
  std::int64_t t_ns = 0;
  Eigen::Vector2d commanded_radps = Eigen::Vector2d::Zero();
  Eigen::Vector2d wheel_radps = Eigen::Vector2d::Zero();
  Eigen::Vector2d ground_mps = Eigen::Vector2d::Zero();
  Eigen::Vector2d slip = Eigen::Vector2d::Zero();
  bool carried = false;  ///< the robot was in the air (a kidnap)
  geom::SE3d T_w_b = geom::SE3d::Identity();  ///< the robot's base (axle centre) at t_ns
};

/// What the motion sensors gave since the last take().
struct MotionBatch {
  std::vector<sensor::ImuSample> imu;
  std::vector<sensor::WheelTicks> ticks;
  std::vector<ImuTruth> imu_truth;
  std::vector<WheelTruth> wheel_truth;
};

/// Kalibr's IMU noise model for one three-axis sensor, in discrete time
/// at sample period dt: reading = clip(quantise(truth + bias + sigma_d n)),
/// sigma_d = noise_density / sqrt(dt), and after each sample
/// bias += random_walk sqrt(dt) n; the bias starts at turn_on_bias n.
/// n are independent standard normal draws from `stream` of `seed`.
class InertialNoiseModel {
 public:
  InertialNoiseModel(const scenes::InertialNoise& spec, double dt_s, std::uint64_t seed, std::uint64_t stream);
  /// The reading for a noise-free value; *bias receives the bias in it.
  Eigen::Vector3d apply(const Eigen::Vector3d& truth, Eigen::Vector3d* bias);

 private:
  double normal();
  scenes::InertialNoise spec_;
  double dt_s_;
  std::uint64_t rng_state_;  ///< splitmix64
  bool has_spare_ = false;   ///< Box-Muller gives normals in pairs
  double spare_ = 0;
  Eigen::Vector3d bias_;
};

/// The robot's description for odometry and SLAM (robot.yaml): the built
/// robot's wheel radius and track, each off by a calibration error drawn
/// from the station seed, uniform within +-robot.radius_error and
/// +-robot.track_error (relative), and the encoders' counts a revolution.
sensor::DriveDescription nominal_description(const scenes::Scenario& s);

/// Samples the IMU and the encoders after every physics step.  Call
/// before_step() and after_step() around each step (mj_step or a step of a
/// carried robot); readings fall due on whole multiples of their periods
/// counted from the first step.
class MotionSensors {
 public:
  /// T_b_c: the camera in the base as the model has it; the IMU is at the
  /// scenario's offset from it (scenes::T_camera_imu).
  MotionSensors(const mjModel* m, const scenes::Scenario& s, int robot_body, const geom::SE3d& T_b_c);
  void before_step(const mjData* d);
  void after_step(const mjModel* m, const mjData* d, bool carried);
  /// The wheels' joint angles were set anew (a kidnap's restore): the
  /// encoders count on from where they were.
  void rebase_wheels(const mjData* before, const mjData* after);
  MotionBatch take();
  const geom::SE3d& T_b_i() const { return T_b_i_; }
  double imu_rate_hz() const { return imu_rate_hz_; }
  double wheel_rate_hz() const { return wheel_rate_hz_; }

 private:
  struct Pre {  ///< the free body before a step
    Eigen::Matrix3d R_w_b;
    Eigen::Vector3d v_w, w_b;
  };
  void accumulate_imu(const mjModel* m, const mjData* d);
  void emit_imu(const mjData* d);
  void emit_wheels(const mjData* d);
  double wheel_angle(const mjData* d, int side) const;

  geom::SE3d T_b_i_;
  double dt_s_, imu_rate_hz_, wheel_rate_hz_;
  int imu_steps_, wheel_steps_;
  int free_qpos_, free_dof_;
  int wheel_qpos_[2], wheel_dof_[2], wheel_act_[2];
  double wheel_radius_m_[2], track_m_;  ///< as built: left, right
  int ticks_per_rev_;
  double wheel_offset_rad_[2] = {0, 0};
  long long steps_ = 0;
  Pre pre_{};
  Eigen::Vector3d sum_gyro_ = Eigen::Vector3d::Zero(), sum_accel_ = Eigen::Vector3d::Zero();
  InertialNoiseModel gyro_noise_, accel_noise_;
  MotionBatch out_;
};

}  // namespace pvb::sim
