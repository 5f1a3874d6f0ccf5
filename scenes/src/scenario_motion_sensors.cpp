// The robot's motion sensors as a scenario describes them: physics rate,
// IMU and wheel encoders (scenes/SCHEMA.md, docs/sensors.md).
#include <algorithm>
#include <Eigen/Geometry>
#include <cmath>

#include "pvb/common/text.hpp"
#include "scenario_sections.hpp"

namespace pvb::scenes {
namespace {

constexpr double kPartDegToRad = M_PI / 180.0;
constexpr double kPartStandardGravity = 9.80665;  // m/s^2, for figures given in g
constexpr double kDefaultMaxStepS = 0.002;           // physics step of a file that sets no rate

}  // namespace

const char* to_string(ImuPart part) { return part == ImuPart::kBmi055 ? "bmi055" : "bmi088"; }

sensor::ImuNoise kalibr_noise(const Imu& imu) {
  sensor::ImuNoise n;
  n.gyro_noise_density = imu.gyro.noise_density;
  n.gyro_random_walk = imu.gyro.random_walk;
  n.accel_noise_density = imu.accel.noise_density;
  n.accel_random_walk = imu.accel.random_walk;
  return n;
}

// Datasheet figures (BST-BMI088-DS001, BST-BMI055-DS000): gyroscope rate
// noise density 0.014 deg/s/sqrt(Hz) and zero-rate offset +-1 deg/s for
// both; accelerometer noise density 160 (BMI088) and 150 (BMI055)
// ug/sqrt(Hz), zero-g offset +-20 mg and +-70 mg.  Ranges: the gyroscopes'
// 2000 deg/s, the BMI088's 6 g (its reset value) and 4 g for the BMI055
// (as the RealSense D435i sets it).  Neither datasheet gives a bias random
// walk: the defaults are assumed values of the size Allan analyses of
// consumer MEMS parts find (docs/sensors.md).
InertialNoise part_gyro(ImuPart /*part*/) {
  InertialNoise n;
  n.noise_density = 0.014 * kPartDegToRad;
  n.random_walk = 2.0e-5;
  n.turn_on_bias = 1.0 * kPartDegToRad;
  n.range = 2000.0 * kPartDegToRad;
  n.bits = 16;
  return n;
}

InertialNoise part_accel(ImuPart part) {
  InertialNoise n;
  const bool b055 = part == ImuPart::kBmi055;
  n.noise_density = (b055 ? 150e-6 : 160e-6) * kPartStandardGravity;
  n.random_walk = 4.0e-4;
  n.turn_on_bias = (b055 ? 0.070 : 0.020) * kPartStandardGravity;
  n.range = (b055 ? 4.0 : 6.0) * kPartStandardGravity;
  n.bits = b055 ? 12 : 16;
  return n;
}

geom::SE3d T_base_camera(const Scenario& s) {
  const Camera& cam = s.camera;
  const double p = cam.pitch_deg * kPartDegToRad, yw = cam.yaw_deg * kPartDegToRad;
  const Eigen::Vector3d forward(std::cos(p) * std::cos(yw), std::cos(p) * std::sin(yw), std::sin(p));
  const Eigen::Vector3d right(std::sin(yw), -std::cos(yw), 0);
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d R_b_c;
  R_b_c << right, down, forward;  // optical x right, y down, z forward
  return geom::make_se3(R_b_c, Eigen::Vector3d(cam.mount_forward_m, 0, cam.mount_height_m - s.robot.wheel_radius_m));
}

geom::SE3d T_camera_imu(const Imu& imu) {
  const Eigen::Vector3d rpy = imu.rpy_c_i_deg * kPartDegToRad;
  const Eigen::Matrix3d R_c_i = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
  return geom::make_se3(R_c_i, imu.p_c_i_m);
}

geom::SE3d T_base_imu(const Scenario& s) { return T_base_camera(s) * T_camera_imu(s.imu); }

bool divides(double rate_hz, double physics_hz) {
  if (rate_hz <= 0) return false;
  const double k = physics_hz / rate_hz;
  return k >= 1 - 1e-9 && std::abs(k - std::round(k)) < 1e-9 * k;
}

double nearest_divisor_rate(double physics_hz, double wanted_hz) {
  const double k = std::max(1.0, std::floor(physics_hz / wanted_hz));
  const double above = physics_hz / k, below = physics_hz / (k + 1);
  return above - wanted_hz < wanted_hz - below ? above : below;
}

int physics_substeps(const Scenario& s) {
  if (s.physics.rate_hz) return static_cast<int>(std::lround(*s.physics.rate_hz / s.camera.fps));
  return std::max(1, static_cast<int>(std::ceil(1.0 / s.camera.fps / kDefaultMaxStepS - 1e-9)));
}

double physics_rate_hz(const Scenario& s) { return s.camera.fps * physics_substeps(s); }

double imu_rate_hz(const Scenario& s) {
  const double physics = physics_rate_hz(s);
  if (s.imu.rate_hz) return *s.imu.rate_hz;
  return divides(200.0, physics) ? 200.0 : nearest_divisor_rate(physics, 200.0);
}

double wheel_rate_hz(const Scenario& s) {
  const double physics = physics_rate_hz(s);
  if (s.wheels.rate_hz) return *s.wheels.rate_hz;
  return divides(50.0, physics) ? 50.0 : nearest_divisor_rate(physics, 50.0);
}

namespace detail {
namespace {

/// A sample rate that divides the physics rate.
double read_rate(MapReader& r, const std::string& key, double physics_hz, double max_hz) {
  const double rate = r.number(key, 0.0, 1, max_hz);
  if (!divides(rate, physics_hz))
    r.fail(r.full(key), r.child(key),
           "a rate that divides the physics rate of " + format_exact(physics_hz) + " Hz (physics.rate_hz sets it)",
           format_exact(rate));
  return rate;
}

void read_inertial(MapReader& r, InertialNoise& n, double max_density, double max_walk, double max_bias,
                   double min_range, double max_range) {
  n.noise_density = r.number("noise_density", n.noise_density, 0, max_density);
  n.random_walk = r.number("random_walk", n.random_walk, 0, max_walk);
  n.turn_on_bias = r.number("turn_on_bias", n.turn_on_bias, 0, max_bias);
  n.range = r.number("range", n.range, min_range, max_range);
  n.bits = r.integer("bits", n.bits, 0, 32);
}

/// +-2 g, the smallest range MEMS accelerometers offer (BMI088: 3 g at least).
constexpr double kMinAccelRangeMps2 = 2 * 9.80665;

/// The IMU lies on the robot: within kImuReachM of the camera (its housing
/// and bracket on the mast).  Checked in the camera's frame, where it is given.
constexpr double kImuReachM = 0.15;

void read_imu(MapReader& r, Imu& imu, double physics_hz) {
  imu.part = r.choice<ImuPart>("part", imu.part, {{"bmi088", ImuPart::kBmi088}, {"bmi055", ImuPart::kBmi055}});
  imu.gyro = part_gyro(imu.part);
  imu.accel = part_accel(imu.part);
  if (r.has("rate_hz")) imu.rate_hz = read_rate(r, "rate_hz", physics_hz, 1000);
  if (r.has("p_c_i_m")) {
    const std::vector<double> p = r.numbers("p_c_i_m", 3, -10, 10);
    imu.p_c_i_m = Eigen::Vector3d(p[0], p[1], p[2]);
    if (imu.p_c_i_m.norm() > kImuReachM)
      r.fail(r.full("p_c_i_m"), YAML::Node(),
             "a place on the robot: within " + format_exact(kImuReachM) + " m of the camera",
             format_exact(imu.p_c_i_m.norm()) + " m from it");
  }
  if (r.has("rpy_c_i_deg")) {
    const std::vector<double> a = r.numbers("rpy_c_i_deg", 3, -180, 180);
    imu.rpy_c_i_deg = Eigen::Vector3d(a[0], a[1], a[2]);
  }
  with_map(r, "gyro", [&](MapReader& g) { read_inertial(g, imu.gyro, 0.1, 0.01, 0.5, 1e-3, 100); });
  // An accelerometer's smallest range is +-2 g: below g, gravity alone saturates it.
  with_map(r, "accel",
           [&](MapReader& a) { read_inertial(a, imu.accel, 1.0, 1.0, 5.0, kMinAccelRangeMps2, 2000); });
}

}  // namespace

void read_body(MapReader& top, Scenario& s) {
  with_map(top, "physics", [&](MapReader& r) {
    const double rate = r.number("rate_hz", 0.0, 100, 10000);
    if (!r.has("rate_hz")) return;  // absent or null: unset, as without the section
    if (!divides(s.camera.fps, rate))
      r.fail(r.full("rate_hz"), r.child("rate_hz"),
             "a whole multiple of the camera's " + format_exact(s.camera.fps) + " frames/s", format_exact(rate));
    s.physics.rate_hz = rate;
  });
  const double physics = physics_rate_hz(s);
  with_map(top, "imu", [&](MapReader& r) { read_imu(r, s.imu, physics); });
  with_map(top, "wheels", [&](MapReader& r) {
    s.wheels.ticks_per_rev = r.integer("ticks_per_rev", s.wheels.ticks_per_rev, 1, 1 << 24);
    if (r.has("rate_hz")) s.wheels.rate_hz = read_rate(r, "rate_hz", physics, 1000);
  });
}

}  // namespace detail
}  // namespace pvb::scenes
