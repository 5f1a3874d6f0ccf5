// Local bundle adjustment with inertial and wheel terms, and the inertial
// initialisation, on a synthetic robot driving with an IMU, wheel encoders
// and a forward-looking RGB-D camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>

#include "pvb/slam/optim/inertial_ba.hpp"
#include "pvb/slam/optim/optimizer.hpp"
#include "pvb/slam/optim/synthetic.hpp"
#include "pvb/slam/optim/synthetic_inertial.hpp"

namespace pvb::slam {
namespace {

using testing::BodyMotion;
using testing::ImuRig;
using testing::WheelRig;

constexpr double kDeg = M_PI / 180.0;

/// Angle between the true and the estimated direction of the world's z
/// axis seen from the camera: the tilt (pitch and roll) error, degrees.
double tilt_error_deg(const geom::SE3d& T_c_w, const geom::SE3d& T_c_w_true) {
  const Eigen::Vector3d a = T_c_w.linear().col(2), b = T_c_w_true.linear().col(2);
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kDeg;
}

struct DriveScene {
  BodyMotion motion;
  ImuRig imu;
  WheelRig wheels;
  geom::SE3d T_base_c = testing::default_T_base_camera();
  std::vector<double> t_s;             ///< keyframe times
  std::vector<geom::SE3d> T_c_w_true;  ///< ground truth
  BaProblem problem;                   ///< ground truth, noisy observations
  std::shared_ptr<BaInertial> inertial;
};

/// A robot driving forward at ~1 m/s with gentle turns and a slightly
/// pitching base (unless flat); keyframes every 0.5 s, the first num_fixed fixed;
/// points 2-12 m ahead, observed with 1 px noise (RGB-D).
DriveScene make_drive_scene(int num_keyframes, int num_fixed, int num_points, unsigned seed, bool flat = false) {
  DriveScene s;
  s.motion.speed_mps.c0 = 1.0;
  s.motion.yaw_rad.waves.push_back({0.1, 0.6, 0.0});
  if (!flat) s.motion.pitch_rad.waves.push_back({0.01, 1.1, 0.4});
  s.imu.R_base_imu = testing::default_R_base_imu();
  s.imu.true_bias.gyro_radps = {0.002, -0.001, 0.0015};
  s.imu.true_bias.accel_mps2 = {0.03, -0.02, 0.04};
  std::mt19937 rng(seed);
  const StereoIntrinsics K = testing::default_intrinsics();
  for (int k = 0; k < num_keyframes; ++k) {
    s.t_s.push_back(0.5 * k);
    s.T_c_w_true.push_back(testing::camera_pose(s.motion, s.T_base_c, s.t_s.back()));
    BaKeyframe kf;
    kf.id = static_cast<std::uint64_t>(k);
    kf.T_c_w = s.T_c_w_true.back();
    kf.fixed = k < num_fixed;
    s.problem.keyframes.push_back(kf);
  }
  const double x_end = s.motion.p_w(s.t_s.back()).x();
  std::uniform_real_distribution<double> ux(2.0, x_end + 12.0), uy(-5.0, 5.0), uz(-0.5, 3.0);
  while (static_cast<int>(s.problem.points.size()) < num_points) {
    const Eigen::Vector3d p_w = testing::draw_zyx(ux, uy, uz, rng);
    std::vector<BaEdge> edges;
    for (int k = 0; k < num_keyframes; ++k) {
      const Eigen::Vector3d p_c = s.T_c_w_true[static_cast<std::size_t>(k)] * p_w;
      if (p_c.z() < 1.0 || p_c.z() > 12.0) continue;
      const Eigen::Vector2d uv = project(K, p_c);
      if (uv.x() < 0 || uv.x() >= testing::kWidth || uv.y() < 0 || uv.y() >= testing::kHeight) continue;
      BaEdge e;
      e.keyframe = static_cast<std::size_t>(k);
      e.point = s.problem.points.size();
      e.obs = testing::observe(K, p_c, true, 1.0, rng);
      edges.push_back(e);
    }
    if (edges.size() < 2) continue;
    BaPoint pt;
    pt.id = 1000 + s.problem.points.size();
    pt.p_w = p_w;
    s.problem.points.push_back(pt);
    s.problem.edges.insert(s.problem.edges.end(), edges.begin(), edges.end());
  }
  s.inertial = std::make_shared<BaInertial>();
  s.inertial->T_b_c = s.imu.T_base_imu().inverse() * s.T_base_c;
  s.inertial->T_base_c = s.T_base_c;
  s.inertial->g_w = s.imu.g_w;
  for (int k = 0; k < num_keyframes; ++k) {
    BaInertialState st;
    st.v_w_mps = s.motion.v_w(s.t_s[static_cast<std::size_t>(k)]);  // the IMU sits at the base's origin
    st.bias = s.imu.true_bias;
    s.inertial->states.push_back(st);
  }
  return s;
}

void add_imu_edges(DriveScene* s, unsigned seed) {
  std::mt19937 rng(seed);
  for (std::size_t k = 0; k + 1 < s->t_s.size(); ++k) {
    BaImuEdge e;
    e.i = k;
    e.j = k + 1;
    e.pre = s->imu.preintegrate(s->motion, s->t_s[k], s->t_s[k + 1], s->inertial->states[k].bias, &rng);
    s->inertial->imu_edges.push_back(e);
  }
}

void add_wheel_edges(DriveScene* s) {
  for (std::size_t k = 0; k + 1 < s->t_s.size(); ++k)
    s->inertial->wheel_edges.push_back({k, k + 1, s->wheels.preintegrate(s->motion, s->t_s[k], s->t_s[k + 1])});
}

/// Visual drift in pitch: non-fixed keyframe k turned by drift_deg times
/// (k - num_fixed + 1) about the lateral axis through the last fixed
/// camera; the points moved by 2 cm at random.
void add_pitch_drift(BaProblem* p, int num_fixed, double drift_deg, unsigned seed) {
  const Eigen::Vector3d pivot = p->keyframes[static_cast<std::size_t>(num_fixed - 1)].T_c_w.inverse().translation();
  for (std::size_t k = static_cast<std::size_t>(num_fixed); k < p->keyframes.size(); ++k) {
    const double angle = drift_deg * kDeg * static_cast<double>(k - static_cast<std::size_t>(num_fixed) + 1);
    const geom::SE3d P = geom::make_se3(Eigen::Matrix3d::Identity(), pivot) *
                         geom::make_se3(geom::so3_exp(Eigen::Vector3d(0, angle, 0)), Eigen::Vector3d::Zero()) *
                         geom::make_se3(Eigen::Matrix3d::Identity(), -pivot);
    p->keyframes[k].T_c_w = (P * p->keyframes[k].T_c_w.inverse()).inverse();
  }
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (auto& pt : p->points) pt.p_w += 0.02 * testing::draw_zyx(n01, rng).normalized();
}

double max_tilt_error_deg(const DriveScene& s, int num_fixed) {
  double worst = 0;
  for (std::size_t k = static_cast<std::size_t>(num_fixed); k < s.T_c_w_true.size(); ++k)
    worst = std::max(worst, tilt_error_deg(s.problem.keyframes[k].T_c_w, s.T_c_w_true[k]));
  return worst;
}

/// Sum of the squared tilt errors (deg^2) of the non-fixed keyframes.
double sum_sq_tilt_error(const DriveScene& s, int num_fixed) {
  double sum = 0;
  for (std::size_t k = static_cast<std::size_t>(num_fixed); k < s.T_c_w_true.size(); ++k)
    sum += std::pow(tilt_error_deg(s.problem.keyframes[k].T_c_w, s.T_c_w_true[k]), 2);
  return sum;
}

enum class Terms { kVisual, kImu, kWheels };

/// One drift trial (on flat ground or a pitching base): 10 keyframes (2 fixed) with a pitch drift of 0.05 deg
/// per keyframe, solved with the given terms; returns the summed squared
/// tilt error after BA and, in *start, before.
double drift_trial(Terms terms, bool flat, unsigned seed, double* start) {
  const int n = 10, fixed = 2;
  DriveScene s = make_drive_scene(n, fixed, 250, seed, flat);
  add_pitch_drift(&s.problem, fixed, 0.05, seed + 1);
  *start = sum_sq_tilt_error(s, fixed);
  if (terms == Terms::kImu) add_imu_edges(&s, seed + 2);
  if (terms == Terms::kWheels) {
    // An indoor floor: the planar constraint's tilt sigma 0.3 mrad + 0.3 mrad/m.
    s.wheels.noise.planar_floor = 3e-4;
    s.wheels.noise.planar_tilt_per_m = 3e-4;
    add_wheel_edges(&s);
  }
  if (terms != Terms::kVisual) s.problem.inertial = s.inertial;
  const BaResult r = local_bundle_adjustment(&s.problem, testing::default_intrinsics());
  EXPECT_GT(r.iterations, 0);
  if (terms == Terms::kImu) {
    // Velocities and biases stay near the truth.
    for (std::size_t k = fixed; k < static_cast<std::size_t>(n); ++k) {
      EXPECT_LT((s.inertial->states[k].v_w_mps - s.motion.v_w(s.t_s[k])).norm(), 0.05) << k;
      EXPECT_LT((s.inertial->states[k].bias.gyro_radps - s.imu.true_bias.gyro_radps).norm(), 1e-3) << k;
    }
  }
  return sum_sq_tilt_error(s, fixed);
}

/// RMS tilt error (deg) over 5 seeds and the 8 free keyframes: after BA
/// with the given terms, and (in *start) before.
double drift_rms(Terms terms, bool flat, double* start_rms) {
  double sum = 0, start_sum = 0;
  const int trials = 5;
  for (int t = 0; t < trials; ++t) {
    double start = 0;
    sum += drift_trial(terms, flat, 31 + 10 * static_cast<unsigned>(t), &start);
    start_sum += start;
  }
  *start_rms = std::sqrt(start_sum / (trials * 8));
  return std::sqrt(sum / (trials * 8));
}

TEST(InertialBundleAdjustment, ImuTermsCutThePitchDrift) {
  double start = 0;
  const double visual = drift_rms(Terms::kVisual, false, &start);
  const double imu = drift_rms(Terms::kImu, false, &start);
  std::printf("pitch drift 0.05 deg/keyframe (RMS tilt %.3f deg at the start): RMS tilt error after visual-only BA "
              "%.4f deg, with IMU %.4f deg\n", start, visual, imu);
  EXPECT_GT(start, 0.2);
  EXPECT_LT(imu * 3.0, visual);
}

TEST(InertialBundleAdjustment, WheelTermsCutThePitchDriftOnAFlatFloor) {
  double start = 0;
  const double visual = drift_rms(Terms::kVisual, true, &start);
  const double wheels = drift_rms(Terms::kWheels, true, &start);
  std::printf("pitch drift 0.05 deg/keyframe, flat floor: RMS tilt error after visual-only BA %.4f deg, with wheels "
              "%.4f deg\n", visual, wheels);
  // Relative tilt only (the wheels know no gravity): a smaller gain than the IMU's.
  EXPECT_LT(wheels * 1.3, visual);
}

TEST(InertialBundleAdjustment, HuberAbsorbsAWheelSlip) {
  // The wheels of interval 4-5 spun 0.3 m without moving the robot: with the
  // Huber loss vision keeps the poses; without it the slip pulls them.
  double spin_m = 0.3;
  double err[3] = {0, 0, 0};  // without Huber, with Huber, without slip
  for (int robust = 0; robust < 3; ++robust) {
    DriveScene s = make_drive_scene(8, 2, 250, 101, true);
    add_wheel_edges(&s);
    if (robust == 2) spin_m = 0.0;
    auto slipped = std::make_shared<WheelPreintegration>(*s.inertial->wheel_edges[4].pre);
    WheelPreintegration spin(s.wheels.drive, s.wheels.noise);
    const auto ticks = static_cast<std::int64_t>(std::lround(spin_m / spin.metres_per_tick()));
    spin.add(ticks, ticks);
    slipped->append(spin);
    s.inertial->wheel_edges[4].pre = slipped;
    s.inertial->wheel_huber = robust > 0 ? 2.0 : 0.0;
    s.problem.inertial = s.inertial;
    local_bundle_adjustment(&s.problem, testing::default_intrinsics());
    for (std::size_t k = 2; k < 8; ++k)
      err[robust] = std::max(err[robust], testing::position_error_m(s.problem.keyframes[k].T_c_w, s.T_c_w_true[k]));
  }
  std::printf("0.3 m wheel slip: max position error %.4f m without Huber, %.4f m with (%.4f m without the slip)\n",
              err[0], err[1], err[2]);
  EXPECT_LT(err[1], err[2] + 0.01);
  EXPECT_LT(2.0 * err[1], err[0]);
}

TEST(InertialBundleAdjustment, NullInertialIsBitIdenticalAndFixedStatesStay) {
  DriveScene a = make_drive_scene(6, 2, 150, 51);
  add_pitch_drift(&a.problem, 2, 0.05, 52);
  DriveScene b = a;
  // An inertial block with no edges changes nothing either.
  b.problem.inertial = std::make_shared<BaInertial>();
  b.problem.inertial->states.resize(b.problem.keyframes.size());
  local_bundle_adjustment(&a.problem, testing::default_intrinsics());
  local_bundle_adjustment(&b.problem, testing::default_intrinsics());
  for (std::size_t k = 0; k < a.problem.keyframes.size(); ++k)
    EXPECT_EQ(0, std::memcmp(a.problem.keyframes[k].T_c_w.matrix().data(), b.problem.keyframes[k].T_c_w.matrix().data(),
                             sizeof(double) * 16));

  DriveScene c = make_drive_scene(6, 2, 150, 53);
  add_imu_edges(&c, 54);
  c.problem.inertial = c.inertial;
  c.inertial->states[1].v_w_mps += Eigen::Vector3d(0.1, 0, 0);  // a fixed keyframe's state stays as given
  const BaInertialState fixed_before = c.inertial->states[1];
  local_bundle_adjustment(&c.problem, testing::default_intrinsics());
  EXPECT_EQ(c.inertial->states[1].v_w_mps, fixed_before.v_w_mps);
  EXPECT_EQ(c.inertial->states[1].bias.accel_mps2, fixed_before.bias.accel_mps2);
}

TEST(InertialBundleAdjustment, KeyframesWithOnlyInertialEdgesMove) {
  // No observations at all: the IMU alone carries keyframe 2 from 0 and 1.
  DriveScene s = make_drive_scene(3, 2, 50, 61);
  s.problem.edges.clear();
  s.problem.points.clear();
  add_imu_edges(&s, 62);
  s.problem.inertial = s.inertial;
  const geom::SE3d truth = s.T_c_w_true[2];
  std::mt19937 rng(63);
  s.problem.keyframes[2].T_c_w = testing::perturb(truth, 0.05, 1.0, rng);
  local_bundle_adjustment(&s.problem, testing::default_intrinsics());
  EXPECT_LT(testing::position_error_m(s.problem.keyframes[2].T_c_w, truth), 0.01);
  EXPECT_LT(testing::rotation_error_deg(s.problem.keyframes[2].T_c_w, truth), 0.05);
}

TEST(InertialBundleAdjustment, GravityEdgesLevelTheCameras) {
  const int n = 6, fixed = 2;
  DriveScene s = make_drive_scene(n, fixed, 0, 71);
  add_pitch_drift(&s.problem, fixed, 0.5, 72);
  s.problem.inertial = s.inertial;
  for (std::size_t k = fixed; k < static_cast<std::size_t>(n); ++k)
    s.inertial->gravity_edges.push_back({k, s.T_c_w_true[k].linear() * -s.imu.g_w, 0.01});
  const double before = max_tilt_error_deg(s, fixed);
  local_bundle_adjustment(&s.problem, testing::default_intrinsics());
  const double after = max_tilt_error_deg(s, fixed);
  EXPECT_GT(before, 1.0);
  EXPECT_LT(after, 1e-3);
}

TEST(InertialBundleAdjustment, RejectsBadInertialInput) {
  DriveScene s = make_drive_scene(3, 1, 50, 81);
  s.problem.inertial = s.inertial;
  s.inertial->states.pop_back();
  EXPECT_THROW(local_bundle_adjustment(&s.problem, testing::default_intrinsics()), std::invalid_argument);
  s.inertial->states.resize(3);
  s.inertial->imu_edges.push_back({0, 7, nullptr});
  EXPECT_THROW(local_bundle_adjustment(&s.problem, testing::default_intrinsics()), std::invalid_argument);
}

// ---------------------------------------------------------------------------
// Inertial initialisation
// ---------------------------------------------------------------------------

struct InitCase {
  const char* name;
  BodyMotion motion;
};

InitCase standing_still() { return {"standing still", BodyMotion{}}; }
InitCase constant_speed() {
  InitCase c{"constant speed", BodyMotion{}};
  c.motion.speed_mps.c0 = 1.0;
  return c;
}
InitCase accelerating_and_turning() {
  InitCase c{"accelerating and turning", BodyMotion{}};
  c.motion.speed_mps.c0 = 0.6;
  c.motion.speed_mps.waves.push_back({0.5, 1.2, 0.0});
  c.motion.yaw_rad.waves.push_back({0.8, 0.9, 0.0});
  c.motion.pitch_rad.waves.push_back({0.02, 1.7, 0.0});
  return c;
}

TEST(InertialInitialisation, RecoversGravityAndGyroBias) {
  for (const InitCase& c : {standing_still(), constant_speed(), accelerating_and_turning()}) {
    ImuRig imu;
    imu.R_base_imu = testing::default_R_base_imu();
    imu.true_bias.gyro_radps = {0.003, -0.002, 0.004};
    // Standing still or driving straight, a horizontal accelerometer bias
    // and a tilt of gravity are the same reading: only the prior tells them
    // apart, so the gravity error is up to |b_a horizontal| / g.  A good
    // MEMS accelerometer's 0.01 m/s^2 gives 0.06 deg.
    imu.true_bias.accel_mps2 = {0.008, -0.006, 0.02};
    const geom::SE3d T_base_c = testing::default_T_base_camera();
    std::mt19937 rng(91);
    // The map's world is the first camera's frame, as SLAM makes it.
    const geom::SE3d T_w0_w = testing::camera_pose(c.motion, T_base_c, 0.0);
    const Eigen::Vector3d g_true = T_w0_w.linear() * imu.g_w;
    InertialInitProblem p;
    p.T_b_c = imu.T_base_imu().inverse() * T_base_c;
    p.g_w_guess = Eigen::Vector3d(0, 9.81, 0);  // the camera's down (optical y), roughly
    std::vector<Eigen::Vector3d> v_true;
    const int n = 11;
    for (int k = 0; k < n; ++k) {
      const double t = 0.25 * k;
      p.T_c_w.push_back(testing::camera_pose(c.motion, T_base_c, t) * T_w0_w.inverse());
      v_true.push_back(T_w0_w.linear() * c.motion.v_w(t));
      if (k > 0) p.pre.push_back(imu.preintegrate(c.motion, t - 0.25, t, ImuBias{}, &rng));
    }
    const InertialInitResult r = initialize_inertial(p);
    ASSERT_TRUE(r.ok) << c.name;
    ASSERT_EQ(r.v_w_mps.size(), static_cast<std::size_t>(n));
    const double g_err = std::atan2(r.g_w.cross(g_true).norm(), r.g_w.dot(g_true)) / kDeg;
    const double bg_err = (r.bias.gyro_radps - imu.true_bias.gyro_radps).norm() / imu.true_bias.gyro_radps.norm();
    const double ba_err = (r.bias.accel_mps2 - imu.true_bias.accel_mps2).norm();
    double v_err = 0;
    for (int k = 0; k < n; ++k) v_err = std::max(v_err, (r.v_w_mps[static_cast<std::size_t>(k)] - v_true[static_cast<std::size_t>(k)]).norm());
    std::printf("init, %s: gravity %.4f deg, gyro bias %.2f %%, accel bias error %.4f m/s^2, velocity %.4f m/s, rms %.2f\n",
                c.name, g_err, 100 * bg_err, ba_err, v_err, r.rms_whitened);
    EXPECT_LT(g_err, 0.1) << c.name;
    EXPECT_LT(bg_err, 0.1) << c.name;
    EXPECT_LT(ba_err, 0.05) << c.name;  // sane: the prior holds what the motion does not tell
    EXPECT_LT(v_err, 0.02) << c.name;
    EXPECT_NEAR(r.g_w.norm(), 9.81, 1e-9) << c.name;
    EXPECT_LT(r.rms_whitened, 2.0) << c.name;
  }
}

/// Gravity's error (degrees) from an initialisation on keyframes a few
/// frames apart whose poses carry vision's millimetre noise.
double gravity_error_with_noisy_poses(double pose_sigma_m, double pose_sigma_rad, unsigned seed) {
  const InitCase c = constant_speed();
  ImuRig imu;
  imu.R_base_imu = testing::default_R_base_imu();
  const geom::SE3d T_base_c = testing::default_T_base_camera();
  std::mt19937 rng(seed);
  std::normal_distribution<double> position(0.0, 0.0015), angle(0.0, 0.0003);
  const geom::SE3d T_w0_w = testing::camera_pose(c.motion, T_base_c, 0.0);
  const Eigen::Vector3d g_true = T_w0_w.linear() * imu.g_w;
  InertialInitProblem p;
  p.T_b_c = imu.T_base_imu().inverse() * T_base_c;
  p.g_w_guess = Eigen::Vector3d(0, 9.81, 0);
  p.pose_sigma_m = pose_sigma_m;
  p.pose_sigma_rad = pose_sigma_rad;
  const double spacing_s[] = {0.1, 1.0 / 30, 0.2, 0.1333, 0.3, 0.0667};  // as tracking makes keyframes
  double t = 0;
  const int n = 23;  // about 3 s
  for (int k = 0; k < n; ++k) {
    const geom::SE3d T_w_c = (testing::camera_pose(c.motion, T_base_c, t) * T_w0_w.inverse()).inverse();
    const Eigen::Vector3d dtheta = testing::draw_zyx(angle, rng);
    const Eigen::Vector3d dp = testing::draw_zyx(position, rng);
    const geom::SE3d noisy = geom::make_se3(Eigen::Quaterniond(T_w_c.linear() * geom::so3_exp(dtheta)),
                                            Eigen::Vector3d(T_w_c.translation() + dp));
    p.T_c_w.push_back(noisy.inverse());
    const double next = t + spacing_s[k % 6];
    if (k + 1 < n) p.pre.push_back(imu.preintegrate(c.motion, t, next, ImuBias{}, &rng));
    t = next;
  }
  const InertialInitResult r = initialize_inertial(p);
  EXPECT_TRUE(r.ok);
  return std::atan2(r.g_w.cross(g_true).norm(), r.g_w.dot(g_true)) / kDeg;
}

TEST(InertialInitialisation, VisionsPoseNoiseDoesNotTiltGravity) {
  double worst_modelled = 0, worst_ignored = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    worst_modelled = std::max(worst_modelled, gravity_error_with_noisy_poses(0.002, 0.0005, seed));
    worst_ignored = std::max(worst_ignored, gravity_error_with_noisy_poses(0.0, 0.0, seed));
  }
  std::printf(
      "init on noisy keyframe poses: gravity error %.3f deg with their noise modelled, %.3f deg without\n",
      worst_modelled, worst_ignored);
  EXPECT_LT(worst_modelled, 0.3);
  EXPECT_LT(worst_modelled, worst_ignored);
}

TEST(InertialInitialisation, RejectsBadInput) {
  InertialInitProblem p;
  EXPECT_THROW(initialize_inertial(p), std::invalid_argument);
  p.T_c_w.resize(3, geom::SE3d::Identity());
  p.pre.resize(1);
  EXPECT_THROW(initialize_inertial(p), std::invalid_argument);
}

}  // namespace
}  // namespace pvb::slam
