// The motion sensors on the tracking side: intervals, predictions and the
// accelerometer's tilt, on readings of known motion.
#include <gtest/gtest.h>

#include <cmath>

#include "pvb/slam/core/motion_integrator.hpp"

namespace pvb::slam {
namespace {

constexpr double kG = 9.81;
constexpr std::int64_t kImuPeriodNs = 5'000'000;  // 200 Hz
constexpr std::int64_t kFramePeriodNs = 33'333'333;

/// A camera looking along the IMU's x (forward), 10 cm above it.
Settings robot_settings(sensor::SensorSetup setup) {
  Settings s;
  s.motion.setup = setup;
  s.motion.imu.present = true;
  s.motion.imu.rate_hz = 200;
  s.motion.imu.T_b_c = geom::make_se3(geom::R_body_optical(), Eigen::Vector3d(0.05, 0, 0.1));
  s.motion.robot.present = true;
  s.motion.robot.T_base_imu = geom::make_se3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 0.3));
  s.motion.robot.T_base_c = s.motion.robot.T_base_imu * s.motion.imu.T_b_c;
  return s;
}

/// Readings of an IMU on a level robot driving straight at constant speed
/// and turning at w_radps, from t0 (exclusive) to t1 (inclusive).
std::vector<sensor::ImuSample> level_readings(std::int64_t t0_ns, std::int64_t t1_ns, double w_radps,
                                              const Eigen::Vector3d& accel_extra = Eigen::Vector3d::Zero()) {
  std::vector<sensor::ImuSample> out;
  // On the IMU's own clock: every multiple of its period in (t0, t1].
  const std::int64_t first = (t0_ns >= 0 ? t0_ns / kImuPeriodNs + 1 : -((-t0_ns) / kImuPeriodNs)) * kImuPeriodNs;
  for (std::int64_t t = first; t <= t1_ns; t += kImuPeriodNs) {
    sensor::ImuSample s;
    s.t_ns = t;
    s.gyro_radps = Eigen::Vector3d(0, 0, w_radps);
    s.accel_mps2 = Eigen::Vector3d(0, 0, kG) + accel_extra;
    out.push_back(s);
  }
  return out;
}

TEST(MotionIntegrator, PredictsAStraightDriveAtConstantSpeed) {
  const Settings s = robot_settings(sensor::SensorSetup::kCameraImu);
  MotionIntegrator m(s.motion);
  m.add_frame(0, level_readings(-kFramePeriodNs, 0, 0), {});
  m.add_frame(kFramePeriodNs, level_readings(0, kFramePeriodNs, 0), {});
  // The readings at 5 ... 30 ms, the one at 30 ms held to the frame's time.
  EXPECT_NEAR(m.imu_since_frame().dt_s(), kFramePeriodNs * 1e-9, 1e-12);
  // The camera pose whose IMU stands at the origin, level, heading along x.
  const geom::SE3d T_c_w0 = m.camera_pose(NavState{});
  const Eigen::Vector3d v_w(0.5, 0, 0);
  Eigen::Vector3d v_out;
  const geom::SE3d T_c_w1 = m.predict(T_c_w0, v_w, Eigen::Vector3d(0, 0, -kG), &v_out);
  const NavState at1 = m.nav_state(T_c_w1, v_out);
  const double dt_s = m.imu_since_frame().dt_s();
  EXPECT_NEAR((at1.p_w_m - Eigen::Vector3d(0.5 * dt_s, 0, 0)).norm(), 0, 1e-9);
  EXPECT_NEAR((v_out - v_w).norm(), 0, 1e-9);
  EXPECT_NEAR((at1.R_w_b - Eigen::Matrix3d::Identity()).norm(), 0, 1e-9);
}

TEST(MotionIntegrator, WheelsCarryTheTranslationAndTheGyroTheTurn) {
  const Settings s = robot_settings(sensor::SensorSetup::kCameraImuWheels);
  MotionIntegrator m(s.motion);
  // An accelerometer bias of 0.5 m/s^2 forward that the IMU alone would
  // integrate; the wheels say 0.2 m/s straight on.
  const Eigen::Vector3d bias_like(0.5, 0, 0);
  const double metres_per_tick = 2 * M_PI * s.motion.robot.drive.wheel_radius_m / s.motion.robot.drive.ticks_per_rev;
  std::vector<sensor::WheelTicks> ticks;
  for (int k = 0; k <= 10; ++k) {
    const auto count = static_cast<std::int64_t>(std::lround(0.2 * 0.1 * k / metres_per_tick));
    ticks.push_back({k * 100'000'000LL, count, count});
  }
  m.add_frame(0, level_readings(-kImuPeriodNs, 0, 0), {ticks.front()});
  m.add_frame(1'000'000'000, level_readings(0, 1'000'000'000, 0.1, bias_like),
              std::vector<sensor::WheelTicks>(ticks.begin() + 1, ticks.end()));
  const geom::SE3d T_c_w0 = m.camera_pose(NavState{});
  const geom::SE3d T_c_w1 = m.predict(T_c_w0, Eigen::Vector3d(0.2, 0, 0), Eigen::Vector3d(0, 0, -kG), nullptr);
  const geom::SE3d T_w_base0 = T_c_w0.inverse() * s.motion.robot.T_base_c.inverse();
  const geom::SE3d T_w_base1 = T_c_w1.inverse() * s.motion.robot.T_base_c.inverse();
  const geom::SE3d T_b0_b1 = T_w_base0.inverse() * T_w_base1;
  // 0.2 m ahead within one count, turned 0.1 rad by the gyro, no height.
  EXPECT_NEAR(T_b0_b1.translation().x(), 0.2, metres_per_tick);
  EXPECT_NEAR(T_b0_b1.translation().y(), 0, 1e-9);
  EXPECT_NEAR(T_b0_b1.translation().z(), 0, 1e-9);
  EXPECT_NEAR(geom::so3_log(T_b0_b1.linear()).z(), 0.1, 1e-6);
}

/// Encoder readings at 50 Hz of a robot driving straight at speed_mps,
/// from t0 (exclusive) to t1 (inclusive), counts rounded down as an encoder
/// counts them.
std::vector<sensor::WheelTicks> straight_ticks(std::int64_t t0_ns, std::int64_t t1_ns, double speed_mps,
                                               double metres_per_tick) {
  constexpr std::int64_t kEncoderPeriodNs = 20'000'000;
  std::vector<sensor::WheelTicks> out;
  for (std::int64_t t = (t0_ns / kEncoderPeriodNs + 1) * kEncoderPeriodNs; t <= t1_ns;
       t += kEncoderPeriodNs) {
    const auto count =
        static_cast<std::int64_t>(std::floor(speed_mps * static_cast<double>(t) * 1e-9 / metres_per_tick));
    out.push_back({t, count, count});
  }
  return out;
}

TEST(MotionIntegrator, WheelIntervalsEndAtTheFramesBetweenEncoderReadings) {
  Settings s = robot_settings(sensor::SensorSetup::kCameraImuWheels);
  s.motion.robot.encoder_rate_hz = 50;
  MotionIntegrator m(s.motion);
  const double speed = 0.45,
               metres_per_tick = 2 * M_PI * s.motion.robot.drive.wheel_radius_m / s.motion.robot.drive.ticks_per_rev;
  // Keyframes 1, 2, 3 and 4 frames apart: their ends fall 0, 6.7 and 13.3 ms
  // after the last encoder reading, in turn.
  const int keyframe_at[] = {0, 3, 5, 6, 10, 14, 15, 18};
  int next = 0;
  for (int f = 0; f <= 18; ++f) {
    const std::int64_t t0 = (f - 1) * kFramePeriodNs, t1 = f * kFramePeriodNs;
    const std::vector<sensor::WheelTicks> ticks =
        f == 0 ? std::vector<sensor::WheelTicks>{{0, 0, 0}} : straight_ticks(t0, t1, speed, metres_per_tick);
    m.add_frame(t1, level_readings(t0, t1, 0), ticks);
    if (f != keyframe_at[next]) continue;
    const KeyframeInterval in = m.take_keyframe_interval();
    if (next++ == 0) continue;
    ASSERT_TRUE(in.wheels);
    const double span_s = (keyframe_at[next - 1] - keyframe_at[next - 2]) * kFramePeriodNs * 1e-9;
    // Within the counts' rounding at both ends; unaligned, the error would
    // reach 13.3 ms of driving (6 mm).
    EXPECT_NEAR(in.wheels->delta().x(), speed * span_s, 2.5 * metres_per_tick) << "keyframe at frame " << f;
  }
}

TEST(MotionIntegrator, WheelIntervalsAreWeighedWithTheSettingsWheelNoise) {
  const auto yaw_sigma_after_a_metre = [](double yaw_per_sqrt_m) {
    Settings s = robot_settings(sensor::SensorSetup::kCameraImuWheels);
    s.motion.robot.encoder_rate_hz = 30;
    s.motion.robot.wheel_noise.yaw_per_sqrt_m = yaw_per_sqrt_m;
    MotionIntegrator m(s.motion);
    const double metres_per_tick = 2 * M_PI * s.motion.robot.drive.wheel_radius_m / s.motion.robot.drive.ticks_per_rev;
    for (int f = 0; f <= 60; ++f) {  // 2 s at 0.5 m/s, straight
      const std::int64_t t0 = (f - 1) * kFramePeriodNs, t1 = f * kFramePeriodNs;
      m.add_frame(t1, level_readings(t0, t1, 0),
                  f == 0 ? std::vector<sensor::WheelTicks>{{0, 0, 0}} : straight_ticks(t0, t1, 0.5, metres_per_tick));
      if (f == 0) m.take_keyframe_interval();
    }
    const KeyframeInterval in = m.take_keyframe_interval();
    EXPECT_TRUE(in.wheels);
    return in.wheels ? std::sqrt(in.wheels->covariance()(2, 2) / in.wheels->distance_m()) : 0.0;
  };
  // Straight, the yaw variance is the per-metre term alone.
  EXPECT_NEAR(yaw_sigma_after_a_metre(0.01), 0.01, 1e-6);
  EXPECT_NEAR(yaw_sigma_after_a_metre(0.001), 0.001, 1e-7);
}

// A calibration set between keyframes reads the next interval with it: a
// right wheel 1 % large turns a straight by 0.01 / track radians a metre.
TEST(MotionIntegrator, NewIntervalsAreReadWithTheWheelCalibration) {
  Settings s = robot_settings(sensor::SensorSetup::kCameraImuWheels);
  s.motion.robot.encoder_rate_hz = 30;
  MotionIntegrator m(s.motion);
  const double metres_per_tick = 2 * M_PI * s.motion.robot.drive.wheel_radius_m / s.motion.robot.drive.ticks_per_rev;
  const auto drive = [&](int first, int last) {
    for (int f = first; f <= last; ++f) {
      const std::int64_t t0 = (f - 1) * kFramePeriodNs, t1 = f * kFramePeriodNs;
      m.add_frame(t1, level_readings(t0, t1, 0),
                  f == 0 ? std::vector<sensor::WheelTicks>{{0, 0, 0}} : straight_ticks(t0, t1, 0.5, metres_per_tick));
      if (f == 0) m.take_keyframe_interval();
    }
    return m.take_keyframe_interval();
  };
  const KeyframeInterval described = drive(0, 60);
  m.set_wheel_calibration({0.995, 1.005, 1.0});
  const KeyframeInterval calibrated = drive(61, 120);
  ASSERT_TRUE(described.wheels && calibrated.wheels);
  EXPECT_NEAR(described.wheels->delta().z(), 0.0, 1e-9);
  const double d = calibrated.wheels->described_left_m();
  EXPECT_NEAR(calibrated.wheels->delta().z(), 0.01 * d / s.motion.robot.drive.track_m, 1e-3 * 0.01 * d);
  EXPECT_EQ(calibrated.wheels->calibration(), m.wheel_calibration());
}

TEST(MotionIntegrator, KeyframeIntervalsSplitTheReadingsAndGiveTheTilt) {
  const Settings s = robot_settings(sensor::SensorSetup::kCameraImu);
  MotionIntegrator m(s.motion);
  for (int f = 0; f < 10; ++f)
    m.add_frame(f * kFramePeriodNs, level_readings((f - 1) * kFramePeriodNs, f * kFramePeriodNs, 0), {});
  const KeyframeInterval a = m.take_keyframe_interval();
  ASSERT_TRUE(a.imu);
  ASSERT_TRUE(a.f_c_mps2);
  // Up (the specific force) in the optical frame is -y.
  EXPECT_NEAR((a.f_c_mps2->normalized() - Eigen::Vector3d(0, -1, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR(a.f_spread_mps2, 0, 1e-12);
  for (int f = 10; f < 15; ++f)
    m.add_frame(f * kFramePeriodNs, level_readings((f - 1) * kFramePeriodNs, f * kFramePeriodNs, 0), {});
  const KeyframeInterval b = m.take_keyframe_interval();
  ASSERT_TRUE(b.imu);
  // The intervals end at the frames: the first reading (at -30 ms) counts
  // one period, and the last frame is at 14 frame periods.
  EXPECT_NEAR(a.imu->dt_s(), (9 * kFramePeriodNs + 35'000'000) * 1e-9, 1e-12);
  EXPECT_NEAR(b.imu->dt_s(), 5 * kFramePeriodNs * 1e-9, 1e-12);
  EXPECT_EQ(m.imu_since_keyframe().size(), 0u);
}

TEST(MotionIntegrator, AccelerometerOnlyReadingsGiveTiltButNoIntervals) {
  const Settings s = robot_settings(sensor::SensorSetup::kCameraAccel);
  MotionIntegrator m(s.motion);
  auto readings = level_readings(-kFramePeriodNs, 0, 0);
  for (auto& r : readings) r.gyro_radps = Eigen::Vector3d::Constant(std::nan(""));
  m.add_frame(0, readings, {});
  const KeyframeInterval k = m.take_keyframe_interval();
  EXPECT_FALSE(k.imu);
  ASSERT_TRUE(k.f_c_mps2);
  EXPECT_NEAR(k.f_c_mps2->norm(), kG, 1e-9);
}

}  // namespace
}  // namespace pvb::slam

namespace pvb::slam {
namespace {

// A blind stretch feeds each prediction back as the next start: ninety
// frames with wheels stay a rotation and follow the encoders.
TEST(MotionIntegrator, ChainedPredictionsStayRigidAndFollowTheWheels) {
  Settings s = robot_settings(sensor::SensorSetup::kCameraImuWheels);
  // A mount with a tilt, as a real one (the camera pitched down 15 degrees).
  s.motion.robot.T_base_c = geom::make_se3(Eigen::Matrix3d(Eigen::AngleAxisd(0.26, Eigen::Vector3d::UnitY())) *
                                        geom::R_body_optical(),
                                    Eigen::Vector3d(0.15, 0, 1.0));
  s.motion.imu.T_b_c = s.motion.robot.T_base_imu.inverse() * s.motion.robot.T_base_c;
  MotionIntegrator m(s.motion);
  const double metres_per_tick = 2 * M_PI * s.motion.robot.drive.wheel_radius_m / s.motion.robot.drive.ticks_per_rev;
  geom::SE3d T_c_w = s.motion.robot.T_base_c.inverse();  // the base at the origin
  const Eigen::Vector3d g(0, 0, -kG);
  m.add_frame(0, level_readings(-kFramePeriodNs, 0, 0), {{0, 0, 0}});
  for (int f = 1; f <= 90; ++f) {
    const std::int64_t t = f * kFramePeriodNs;
    const auto count = static_cast<std::int64_t>(std::lround(0.5 * t * 1e-9 / metres_per_tick));
    m.add_frame(t, level_readings(t - kFramePeriodNs, t, 0), {{t, count, count}});
    T_c_w = m.predict(T_c_w, Eigen::Vector3d(0.5, 0, 0), g, nullptr);
    const Eigen::Matrix3d R = T_c_w.linear();
    ASSERT_NEAR((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 0, 1e-12) << "frame " << f;
  }
  // 3 s at 0.5 m/s straight ahead, within a count, the mount's height kept.
  const geom::SE3d T_w_base = T_c_w.inverse() * s.motion.robot.T_base_c.inverse();
  EXPECT_NEAR(T_w_base.translation().x(), 1.5, 2 * metres_per_tick);
  EXPECT_NEAR(T_w_base.translation().y(), 0, 1e-9);
  EXPECT_NEAR(T_w_base.translation().z(), 0, 1e-9);
}

}  // namespace
}  // namespace pvb::slam
