// The IMU and the wheel encoders: readings from the physics state that
// integrate back to the ground truth, Kalibr's noise model as specified
// (Allan deviation), the kinematic terms of an offset, turning sensor,
// and the kidnap's carry.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <vector>

#include "pvb/geometry/time.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/motion_sensors.hpp"
#include "pvb/sim/simulator.hpp"

using namespace pvb;

namespace {

/// A scenario whose IMU reads without noise, bias, saturation or steps.
void perfect_imu(scenes::Scenario* s) {
  for (scenes::InertialNoise* n : {&s->imu.gyro, &s->imu.accel}) *n = scenes::InertialNoise{};
}

scenes::Scenario drive_scenario(double speed_mps, double duration_s) {
  scenes::Scenario s = scenes::parse_scenario(R"(
name: motion_test
seed: 11
ground: {size_m: [40, 40]}
route: {waypoints_m: [[0, 0], [4, 0.5], [7, -0.5], [12, 1.0]], speed_mps: 0.5}
physics: {rate_hz: 600}
robot: {max_wheel_accel_radps2: 3}
camera: {width: 160, height: 120, fx: 131.25, fy: 131.25}
)",
                                              "motion_test.yaml");
  s.route.speed_mps = speed_mps;
  s.duration_s = duration_s;
  return s;
}

/// Every batch of readings over `frames` camera frames.
sim::MotionBatch drive(sim::Simulator& sim, int frames) {
  sim::MotionBatch all;
  for (int i = 0; i < frames; ++i) {
    sim.advance();
    sim::MotionBatch b = sim.take_motion();
    all.imu.insert(all.imu.end(), b.imu.begin(), b.imu.end());
    all.ticks.insert(all.ticks.end(), b.ticks.begin(), b.ticks.end());
    all.imu_truth.insert(all.imu_truth.end(), b.imu_truth.begin(), b.imu_truth.end());
    all.wheel_truth.insert(all.wheel_truth.end(), b.wheel_truth.begin(), b.wheel_truth.end());
  }
  return all;
}

/// Strapdown integration of readings that are means over their periods,
/// from the true state at the first reading.
struct Strapdown {
  Eigen::Matrix3d R;
  Eigen::Vector3d p, v;
  void step(const sensor::ImuSample& s, double dt, const Eigen::Vector3d& g) {
    const Eigen::Matrix3d R_mid = R * geom::so3_exp(0.5 * dt * s.gyro_radps);
    const Eigen::Vector3d a = R_mid * s.accel_mps2 + g;
    p += v * dt + 0.5 * a * dt * dt;
    v += a * dt;
    R = R * geom::so3_exp(dt * s.gyro_radps);
  }
};


/// Integrates the noise-free IMU of `s` over 10 s of driving from the true
/// initial state; the position and rotation errors at the end.
std::pair<double, double> imu_integration_error(scenes::Scenario s) {
  perfect_imu(&s);
  sim::Simulator sim(s, sim::SceneDetail::kGeometry);
  const sim::MotionBatch b = drive(sim, 301);
  EXPECT_GE(b.imu.size(), 2001u);
  EXPECT_EQ(b.imu[0].t_ns, 5'000'000);  // 200 Hz from frame 0
  Strapdown sd{b.imu_truth[0].T_w_i.linear(), b.imu_truth[0].T_w_i.translation(), b.imu_truth[0].v_w_i};
  const Eigen::Vector3d g(0, 0, -9.81);
  for (std::size_t k = 1; k <= 2000; ++k) sd.step(b.imu[k], 0.005, g);
  const sim::ImuTruth& end = b.imu_truth[2000];
  EXPECT_NEAR(geom::ns_to_seconds(end.t_ns - b.imu_truth[0].t_ns), 10.0, 1e-9);
  EXPECT_GT((end.T_w_i.translation() - b.imu_truth[0].T_w_i.translation()).norm(), 3.5) << "it drove";
  const double dp = (sd.p - end.T_w_i.translation()).norm();
  const double dr = Eigen::AngleAxisd(sd.R.transpose() * end.T_w_i.linear()).angle() * 180 / M_PI;
  std::printf("%s: IMU integrated over 10 s: %.2f mm, %.4f deg from the truth\n", s.name.c_str(), dp * 1000, dr);
  return {dp, dr};
}

}  // namespace

// With noise and biases off, integrating the IMU from the true initial state
// gives back the true pose after 10 s of driving: within 1 cm and 0.1 deg,
// on flat ground and on rough_station's bumps and slope.
TEST(MotionSensors, ImuIntegratesBackToTheTruePose) {
  for (const scenes::Scenario& s :
       {drive_scenario(0.5, 12), scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/rough_station.yaml")}) {
    const auto [dp, dr] = imu_integration_error(s);
    EXPECT_LT(dp, 0.01) << s.name;
    EXPECT_LT(dr, 0.1) << s.name;
  }
}

// On flat ground at low speed, odometry from the encoders with the true
// radius and track follows the true path within 1 % of the distance driven.
TEST(MotionSensors, EncodersIntegrateBackToThePathAtLowSpeed) {
  scenes::Scenario s = drive_scenario(0.2, 31);
  s.robot.radius_error = 0;
  s.robot.track_error = 0;
  sim::Simulator sim(s, sim::SceneDetail::kGeometry);
  const sim::MotionBatch b = drive(sim, 900);
  ASSERT_GE(b.ticks.size(), 1400u);
  EXPECT_EQ(b.ticks[0].t_ns, 20'000'000);  // 50 Hz from frame 0
  sensor::WheelOdometry odo(sim::nominal_description(s));
  double driven_m = 0;
  for (std::size_t k = 0; k < b.ticks.size(); ++k) {
    odo.add(b.ticks[k]);
    if (k > 0)
      driven_m += (b.wheel_truth[k].T_w_b.translation() - b.wheel_truth[k - 1].T_w_b.translation()).head<2>().norm();
  }
  // the odometry frame is the base's first pose
  const geom::SE3d T_o_b = b.wheel_truth.front().T_w_b.inverse() * b.wheel_truth.back().T_w_b;
  const double err_m = std::hypot(odo.state().x_m - T_o_b.translation().x(), odo.state().y_m - T_o_b.translation().y());
  std::printf("encoders: %.3f m driven, end error %.4f m (%.2f %%)\n", driven_m, err_m, 100 * err_m / driven_m);
  EXPECT_GT(driven_m, 5.0);
  EXPECT_LT(err_m, 0.01 * driven_m);
}

// Wheels of unequal radius, described as equal: on a straight the encoders
// read with the description turn the robot the wrong way by the difference
// over the track per metre (right wheel 1 % large: the robot curves left
// and the follower steers it straight, while the counts say it turned
// right), and the wheels' truth sees no slip from it.
TEST(MotionSensors, UnequalWheelsTurnTheEncodersOdometryOnAStraight) {
  scenes::Scenario s = drive_scenario(0.2, 31);
  s.robot.radius_error = 0;
  s.robot.track_error = 0;
  s.robot.radius_difference = 0.01;
  sim::Simulator sim(s, sim::SceneDetail::kGeometry);
  const sim::MotionBatch b = drive(sim, 900);
  sensor::WheelOdometry odo(sim::nominal_description(s));
  double driven_m = 0;
  Eigen::Vector2d slip_sum = Eigen::Vector2d::Zero();
  int rolling = 0;
  for (std::size_t k = 0; k < b.ticks.size(); ++k) {
    odo.add(b.ticks[k]);
    if (k > 0)
      driven_m += (b.wheel_truth[k].T_w_b.translation() - b.wheel_truth[k - 1].T_w_b.translation()).head<2>().norm();
    if (b.wheel_truth[k].ground_mps.cwiseAbs().minCoeff() > 0.1) {
      slip_sum += b.wheel_truth[k].slip;
      ++rolling;
    }
  }
  const Eigen::Vector2d mean_slip = slip_sum / std::max(rolling, 1);
  const geom::SE3d T_o_b = b.wheel_truth.front().T_w_b.inverse() * b.wheel_truth.back().T_w_b;
  const double true_yaw = std::atan2(T_o_b.linear()(1, 0), T_o_b.linear()(0, 0));
  const double expected = -s.robot.radius_difference * driven_m / s.robot.track_m;
  std::printf("unequal wheels: %.3f m driven, odometry yaw - true %.4f rad (expected %.4f), mean slip %.4f %.4f\n",
              driven_m, odo.state().yaw_rad - true_yaw, expected, mean_slip.x(), mean_slip.y());
  EXPECT_GT(driven_m, 5.0);
  EXPECT_NEAR(odo.state().yaw_rad - true_yaw, expected, 0.2 * std::abs(expected));
  // Each wheel's slip is reckoned with its own radius: reckoned with the
  // mean one, the wheels would show -+0.5 % of slip on every metre.
  EXPECT_LT(mean_slip.cwiseAbs().maxCoeff(), 0.002);
}

// The calibration error of the description is the station's, within its range.
TEST(MotionSensors, NominalDescriptionIsOffByASeededErrorInItsRange) {
  scenes::Scenario s = drive_scenario(0.5, 1);
  double max_r = 0, max_t = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    s.station_seed = seed;
    const sensor::DriveDescription d = sim::nominal_description(s);
    max_r = std::max(max_r, std::abs(d.wheel_radius_m / s.robot.wheel_radius_m - 1));
    max_t = std::max(max_t, std::abs(d.track_m / s.robot.track_m - 1));
  }
  EXPECT_LE(max_r, s.robot.radius_error);
  EXPECT_GT(max_r, 0.8 * s.robot.radius_error);
  EXPECT_LE(max_t, s.robot.track_error);
  EXPECT_GT(max_t, 0.8 * s.robot.track_error);
  s.station_seed = 5;
  const sensor::DriveDescription a = sim::nominal_description(s);
  s.seed = 99;  // another day of the station
  EXPECT_EQ(sim::nominal_description(s).wheel_radius_m, a.wheel_radius_m);
}

namespace {

/// Overlapping Allan variance of a rate signal sampled every dt at cluster
/// time m dt.
double allan_variance(const std::vector<double>& rate, double dt, std::size_t m) {
  std::vector<double> theta(rate.size() + 1, 0.0);
  for (std::size_t i = 0; i < rate.size(); ++i) theta[i + 1] = theta[i] + rate[i] * dt;
  const double tau = m * dt;
  double sum = 0;
  const std::size_t n = theta.size() - 2 * m;
  for (std::size_t k = 0; k < n; ++k) {
    const double d = theta[k + 2 * m] - 2 * theta[k + m] + theta[k];
    sum += d * d;
  }
  return sum / (2.0 * tau * tau * n);
}

/// Fits AVAR(tau) = N^2 / tau + K^2 tau / 3 by least squares in relative
/// terms over the given (tau, avar) points; returns (N, K).
Eigen::Vector2d fit_white_and_walk(const std::vector<std::pair<double, double>>& points) {
  Eigen::MatrixXd A(points.size(), 2);
  Eigen::VectorXd y(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto [tau, avar] = points[i];
    A(i, 0) = 1.0 / tau / avar;
    A(i, 1) = tau / 3.0 / avar;
    y(i) = 1.0;
  }
  const Eigen::Vector2d x = A.colPivHouseholderQr().solve(y);
  return {std::sqrt(std::max(0.0, x[0])), std::sqrt(std::max(0.0, x[1]))};
}

/// The noise-free readings of a robot standing still for 60 s, at 200 Hz.
const std::vector<sim::ImuTruth>& standstill_truth() {
  static const std::vector<sim::ImuTruth> truth = [] {
    scenes::Scenario s = drive_scenario(0.5, 61);
    sim::Simulator sim(s, sim::SceneDetail::kGeometry);
    sim.set_wheel_override(Eigen::Vector2d::Zero());
    return drive(sim, 1800).imu_truth;
  }();
  return truth;
}

std::vector<double> axis_of(const std::vector<sensor::ImuSample>& s, bool gyro, int axis) {
  std::vector<double> out;
  for (const auto& x : s) out.push_back(gyro ? x.gyro_radps[axis] : x.accel_mps2[axis]);
  return out;
}

/// The readings a day's IMU (seed) gives of the standstill.
std::vector<sensor::ImuSample> standstill_readings(const scenes::Imu& imu, std::uint64_t seed) {
  sim::InertialNoiseModel gyro(imu.gyro, 0.005, seed, 1), accel(imu.accel, 0.005, seed, 2);
  std::vector<sensor::ImuSample> out;
  for (const sim::ImuTruth& t : standstill_truth())
    out.push_back({t.t_ns, gyro.apply(t.gyro_radps, nullptr), accel.apply(t.accel_mps2, nullptr)});
  return out;
}

const std::vector<std::size_t> kClusters = {1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4000};

}  // namespace

// One minute standing still: each axis's Allan deviation gives back the
// white noise density within 10 %.  The bias random walk shows at long
// cluster times only, where one minute holds a few clusters; over 200 days
// (seeds) of the same minute the mean Allan variance gives it back within 10 %.
TEST(MotionSensors, AllanDeviationRecoversTheNoiseModel) {
  const scenes::Imu imu;  // BMI088
  ASSERT_GE(standstill_truth().size(), 12000u);
  const std::vector<sensor::ImuSample> one = standstill_readings(imu, 7);
  for (int sensor_kind = 0; sensor_kind < 2; ++sensor_kind) {
    const scenes::InertialNoise& spec = sensor_kind == 0 ? imu.gyro : imu.accel;
    for (int axis = 0; axis < 3; ++axis) {
      const std::vector<double> x = axis_of(one, sensor_kind == 0, axis);
      std::vector<std::pair<double, double>> pts;
      for (std::size_t m : {1, 2, 4, 8, 16, 32}) pts.push_back({m * 0.005, allan_variance(x, 0.005, m)});
      const double N = fit_white_and_walk(pts).x();
      EXPECT_NEAR(N / spec.noise_density, 1.0, 0.10) << (sensor_kind ? "accel " : "gyro ") << axis;
    }
  }
  std::vector<double> mean_avar[2][3];
  for (auto& s : mean_avar)
    for (auto& a : s) a.assign(kClusters.size(), 0.0);
  const int days = 200;
  for (int day = 0; day < days; ++day) {
    const std::vector<sensor::ImuSample> r = standstill_readings(imu, 1000 + day);
    for (int kind = 0; kind < 2; ++kind)
      for (int axis = 0; axis < 3; ++axis) {
        const std::vector<double> x = axis_of(r, kind == 0, axis);
        for (std::size_t c = 0; c < kClusters.size(); ++c)
          mean_avar[kind][axis][c] += allan_variance(x, 0.005, kClusters[c]) / days;
      }
  }
  for (int kind = 0; kind < 2; ++kind)
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<std::pair<double, double>> pts;
      for (std::size_t c = 0; c < kClusters.size(); ++c) pts.push_back({kClusters[c] * 0.005, mean_avar[kind][axis][c]});
      const Eigen::Vector2d nk = fit_white_and_walk(pts);
      const scenes::InertialNoise& spec = kind == 0 ? imu.gyro : imu.accel;
      std::printf("%s %d: N %.4g (%.4g), K %.4g (%.4g)\n", kind ? "accel" : "gyro", axis, nk.x(), spec.noise_density,
                  nk.y(), spec.random_walk);
      EXPECT_NEAR(nk.x() / spec.noise_density, 1.0, 0.10) << kind << " " << axis;
      EXPECT_NEAR(nk.y() / spec.random_walk, 1.0, 0.10) << kind << " " << axis;
    }
}

// Turning on a circle at constant wheel speeds: the accelerometer shows the
// centripetal term (omega x v, towards the centre) and, for the IMU's
// offset from the base, omega x (omega x r); both together match the true
// acceleration of the IMU (from its true velocities) less gravity.
TEST(MotionSensors, TurningShowsTheKinematicTerms) {
  scenes::Scenario s = drive_scenario(0.5, 10);
  perfect_imu(&s);
  s.imu.p_c_i_m = Eigen::Vector3d(0.10, 0.05, -0.08);  // far from the base's axis of turn
  sim::Simulator sim(s, sim::SceneDetail::kGeometry);
  sim.set_wheel_override(Eigen::Vector2d(3.0, 6.0));  // left slower: a left turn
  const sim::MotionBatch b = drive(sim, 240);
  const Eigen::Vector3d g(0, 0, -9.81);
  double lateral_sum = 0, expected_sum = 0, worst = 0;
  int n = 0;
  for (std::size_t k = 600; k + 1 < b.imu.size(); ++k) {  // after 3 s: a steady circle
    const sim::ImuTruth &a = b.imu_truth[k - 1], &c = b.imu_truth[k];
    const Eigen::Vector3d acc_w = (c.v_w_i - a.v_w_i) / 0.005;  // the mean over the period ending at c
    const Eigen::Matrix3d R_mid = a.T_w_i.linear() * geom::so3_exp(0.0025 * b.imu[k].gyro_radps);
    const Eigen::Vector3d expected = R_mid.transpose() * (acc_w - g);
    worst = std::max(worst, (b.imu[k].accel_mps2 - expected).norm());
    // in the base's axes: lateral (left) component
    const Eigen::Matrix3d R_b_i = sim.motion_sensors().T_b_i().linear();
    lateral_sum += (R_b_i * b.imu[k].accel_mps2).y();
    expected_sum += (R_b_i * expected).y();
    ++n;
  }
  const sim::WheelTruth& w = b.wheel_truth.back();
  const double v = 0.5 * (w.ground_mps[0] + w.ground_mps[1]);
  const double omega = (sim.motion_sensors().T_b_i().linear() * b.imu.back().gyro_radps).z();
  std::printf("turning: lateral %.4f m/s^2 (from truth %.4f; v w %.4f), worst difference %.2e m/s^2\n",
              lateral_sum / n, expected_sum / n, v * omega, worst);
  EXPECT_GT(omega, 0.3);
  EXPECT_GT(lateral_sum / n, 0.5 * v * omega) << "the centripetal acceleration points left, into the turn";
  EXPECT_NEAR(lateral_sum / n, expected_sum / n, 0.01 * std::abs(expected_sum / n));
  EXPECT_LT(worst, 0.05);
}

// A kidnap carries the robot: the encoders stand still while it is in the
// air, the IMU integrates over the carry to where it is put down, and no
// reading jumps at either end of the carry.
TEST(MotionSensors, KidnapShowsInTheImuAndNotInTheWheels) {
  scenes::Scenario s = drive_scenario(0.5, 5);
  s.kidnap = scenes::Kidnap{1.5, 2.0, 0.5};
  perfect_imu(&s);
  sim::Simulator sim(s, sim::SceneDetail::kGeometry);
  const scenes::KidnapFrames k = *sim.kidnap_frames();
  const sim::MotionBatch b = drive(sim, 150);
  const std::int64_t carry_from = geom::frame_time_ns(0, k.cover_begin, 30), carry_to = geom::frame_time_ns(0, k.teleport, 30);
  // wheels: still in the air
  int carried = 0;
  for (std::size_t i = 1; i < b.ticks.size(); ++i) {
    if (b.ticks[i].t_ns <= carry_from || b.ticks[i].t_ns > carry_to) continue;
    EXPECT_EQ(b.ticks[i].left, b.ticks[i - 1].left) << i;
    EXPECT_EQ(b.ticks[i].right, b.ticks[i - 1].right) << i;
    EXPECT_TRUE(b.wheel_truth[i].carried);
    ++carried;
  }
  EXPECT_GE(carried, 45);
  // IMU: the carry from the state at its start integrates to the state at its end
  std::size_t first = 0;
  while (b.imu_truth[first].t_ns < carry_from) ++first;
  Strapdown sd{b.imu_truth[first].T_w_i.linear(), b.imu_truth[first].T_w_i.translation(), b.imu_truth[first].v_w_i};
  double jump_ends = 0, jump_drive = 0, lift = 0;
  std::size_t last = first;
  for (std::size_t i = first + 1; b.imu_truth[i].t_ns <= carry_to; ++i) {
    sd.step(b.imu[i], 0.005, Eigen::Vector3d(0, 0, -9.81));
    lift = std::max(lift, b.imu_truth[i].T_w_i.translation().z() - b.imu_truth[first].T_w_i.translation().z());
    last = i;
  }
  EXPECT_GT(lift, 0.25);
  EXPECT_LT((sd.p - b.imu_truth[last].T_w_i.translation()).norm(), 0.01);
  for (std::size_t i = 1; i < b.imu.size(); ++i) {
    const double jump = (b.imu[i].accel_mps2 - b.imu[i - 1].accel_mps2).norm();
    const bool at_end = std::llabs(b.imu[i].t_ns - carry_from) <= 10'000'000 || std::llabs(b.imu[i].t_ns - carry_to) <= 10'000'000;
    (at_end ? jump_ends : jump_drive) = std::max(at_end ? jump_ends : jump_drive, jump);
  }
  std::printf("kidnap: lift %.3f m, largest step of the accelerometer at the carry's ends %.2f m/s^2, "
              "elsewhere %.2f m/s^2\n", lift, jump_ends, jump_drive);
  EXPECT_LT(jump_ends, std::max(1.0, jump_drive));
}

// A cover only blinds the camera: the IMU and the encoders read what they
// read without it, bit for bit, and the wheels turn on through it.
TEST(MotionSensors, CoverLeavesTheImuAndTheWheelsAsTheyAre) {
  scenes::Scenario plain = drive_scenario(0.5, 5);
  scenes::Scenario covered = plain;
  covered.cover = scenes::Cover{1.5, 2.0};
  sim::Simulator a(plain, sim::SceneDetail::kGeometry), b(covered, sim::SceneDetail::kGeometry);
  const sim::MotionBatch ra = drive(a, 150), rb = drive(b, 150);
  ASSERT_EQ(ra.imu.size(), rb.imu.size());
  ASSERT_EQ(ra.ticks.size(), rb.ticks.size());
  for (std::size_t i = 0; i < ra.imu.size(); ++i) {
    ASSERT_EQ(ra.imu[i].t_ns, rb.imu[i].t_ns) << i;
    ASSERT_TRUE(ra.imu[i].gyro_radps == rb.imu[i].gyro_radps) << i;
    ASSERT_TRUE(ra.imu[i].accel_mps2 == rb.imu[i].accel_mps2) << i;
  }
  const scenes::CoverFrames c = *scenes::camera_cover_frames(covered);
  const std::int64_t from_ns = geom::frame_time_ns(0, c.begin, 30), to_ns = geom::frame_time_ns(0, c.end, 30);
  std::optional<sensor::WheelTicks> first, last;
  for (std::size_t i = 0; i < rb.ticks.size(); ++i) {
    ASSERT_EQ(ra.ticks[i].left, rb.ticks[i].left) << i;
    ASSERT_EQ(ra.ticks[i].right, rb.ticks[i].right) << i;
    if (rb.ticks[i].t_ns < from_ns || rb.ticks[i].t_ns > to_ns) continue;
    EXPECT_FALSE(rb.wheel_truth[i].carried) << i;
    if (!first) first = rb.ticks[i];
    last = rb.ticks[i];
  }
  ASSERT_TRUE(first && last);
  EXPECT_GE(last->t_ns - first->t_ns, 1'900'000'000);  // 50 Hz over the 2 s
  // 0.5 m/s over about 2 s: a metre, far more than a few ticks on each wheel
  EXPECT_GT(last->left - first->left, 100);
  EXPECT_GT(last->right - first->right, 100);
}

// Two simulators of one scenario give the same readings, bit for bit.
TEST(MotionSensors, ReadingsAreDeterministic) {
  const scenes::Scenario s = drive_scenario(0.5, 2);
  sim::Simulator a(s, sim::SceneDetail::kGeometry), b(s, sim::SceneDetail::kGeometry);
  const sim::MotionBatch ra = drive(a, 40), rb = drive(b, 40);
  ASSERT_EQ(ra.imu.size(), rb.imu.size());
  for (std::size_t i = 0; i < ra.imu.size(); ++i) {
    EXPECT_EQ(ra.imu[i].gyro_radps, rb.imu[i].gyro_radps);
    EXPECT_EQ(ra.imu[i].accel_mps2, rb.imu[i].accel_mps2);
  }
  ASSERT_EQ(ra.ticks.size(), rb.ticks.size());
  for (std::size_t i = 0; i < ra.ticks.size(); ++i) EXPECT_EQ(ra.ticks[i].left, rb.ticks[i].left);
  EXPECT_NE(ra.imu[5].gyro_radps, ra.imu_truth[5].gyro_radps) << "the default IMU is noisy";
}

// The camera's and the IMU's poses on the base, as the scenario computes
// them for the settings files, are those of the compiled model.
TEST(MotionSensors, MountPosesAgreeWithTheModel) {
  scenes::Scenario s = drive_scenario(0.5, 1);
  s.camera.yaw_deg = 7;
  s.camera.pitch_deg = -20;
  sim::Simulator sim(s, sim::SceneDetail::kGeometry);
  // the MJCF carries the camera's axes to 7 significant digits
  const geom::SE3d a = sim.T_b_c(), b = scenes::T_base_camera(s);
  EXPECT_LT((a.translation() - b.translation()).norm(), 1e-6);
  EXPECT_LT((a.linear() - b.linear()).norm(), 1e-6);
  const geom::SE3d i = sim.motion_sensors().T_b_i(), j = scenes::T_base_imu(s);
  EXPECT_LT((i.translation() - j.translation()).norm(), 1e-6);
  EXPECT_LT((i.translation() - a.translation()).norm(), 0.05) << "near the camera";
}

namespace {

struct OdometryOutcome {
  double drift_m = 0, distance_m = 0, mean_abs_slip = 0, max_abs_slip = 0;
};

/// Drives a day's scenario and integrates its encoders with the robot's
/// description: the odometry's position error at the end, and the slip.
OdometryOutcome drive_day(const std::string& file) {
  const scenes::Scenario s = scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + file);
  sim::Simulator sim(s, sim::SceneDetail::kGeometry);
  const sim::MotionBatch b = drive(sim, sim.frame_count() - 1);
  sensor::WheelOdometry odo(sim::nominal_description(s));
  OdometryOutcome out;
  const geom::SE3d T_w_b0 = b.wheel_truth.front().T_w_b;
  for (std::size_t k = 0; k < b.ticks.size(); ++k) {
    odo.add(b.ticks[k]);
    if (k > 0)
      out.distance_m +=
          (b.wheel_truth[k].T_w_b.translation() - b.wheel_truth[k - 1].T_w_b.translation()).head<2>().norm();
    out.mean_abs_slip += (std::abs(b.wheel_truth[k].slip.x()) + std::abs(b.wheel_truth[k].slip.y())) / 2;
    out.max_abs_slip = std::max(out.max_abs_slip, b.wheel_truth[k].slip.cwiseAbs().maxCoeff());
  }
  out.mean_abs_slip /= b.ticks.size();
  const Eigen::Vector2d p_true = sensor::odometry_frame_position(T_w_b0, b.wheel_truth.back().T_w_b);
  out.drift_m = (Eigen::Vector2d(odo.state().x_m, odo.state().y_m) - p_true).norm();
  std::printf("%s: odometry %.4f m off after %.2f m; mean |slip| %.4f, max %.3f\n", file.c_str(), out.drift_m,
              out.distance_m, out.mean_abs_slip, out.max_abs_slip);
  return out;
}

}  // namespace

// The same station on a wet and a dry day: the wheels slip more on wet
// earth (MuJoCo's contact, not a random draw), and the odometry alone
// drifts further.
TEST(MotionSensors, WetDaySlipsAndDriftsMoreThanDryDay) {
  const OdometryOutcome dry = drive_day("days/rough_station_dry.yaml");
  const OdometryOutcome wet = drive_day("days/rough_station_wet.yaml");
  EXPECT_GT(wet.mean_abs_slip, dry.mean_abs_slip);
  EXPECT_GT(wet.drift_m, dry.drift_m);
  EXPECT_GT(dry.distance_m, 8.0);
}
