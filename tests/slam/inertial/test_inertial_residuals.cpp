// The inertial and wheel residuals (inertial_residuals.hpp) in doubles:
// about zero at the ground truth of a synthetic drive, chi-square
// distributed with noisy readings, and of the expected size for a known
// error of the poses.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <stdexcept>

#include "pvb/slam/inertial/inertial_residuals.hpp"
#include "pvb/slam/optim/synthetic_inertial.hpp"

namespace pvb::slam {
namespace {

using testing::BodyMotion;
using testing::ImuRig;
using testing::WheelRig;

std::array<double, 7> block(const geom::SE3d& T_c_w) {
  const Eigen::Quaterniond q(T_c_w.linear());
  return {q.x(), q.y(), q.z(), q.w(), T_c_w.translation().x(), T_c_w.translation().y(), T_c_w.translation().z()};
}

std::array<double, 6> bias_block(const ImuBias& b) {
  return {b.gyro_radps.x(), b.gyro_radps.y(), b.gyro_radps.z(), b.accel_mps2.x(), b.accel_mps2.y(), b.accel_mps2.z()};
}

/// A robot driving at ~1 m/s with turns and a gently pitching, rolling base.
BodyMotion drive_with_tilt() {
  BodyMotion m;
  m.speed_mps.c0 = 1.0;
  m.speed_mps.waves.push_back({0.3, 0.8, 0.0});
  m.yaw_rad.waves.push_back({0.6, 0.5, 0.3});
  m.pitch_rad.waves.push_back({0.03, 1.7, 0.0});
  m.roll_rad.waves.push_back({0.02, 1.3, 0.5});
  m.z_m.waves.push_back({0.02, 2.0, 0.0});
  return m;
}

struct Rig {
  BodyMotion motion = drive_with_tilt();
  ImuRig imu;
  geom::SE3d T_base_c = testing::default_T_base_camera();
  geom::SE3d T_b_c;  ///< camera in the IMU frame
  Rig() {
    imu.R_base_imu = testing::default_R_base_imu();
    imu.true_bias.gyro_radps = {0.003, -0.002, 0.004};
    imu.true_bias.accel_mps2 = {0.05, -0.03, 0.04};
    T_b_c = imu.T_base_imu().inverse() * T_base_c;
  }
  geom::SE3d T_c_w(double t) const { return testing::camera_pose(motion, T_base_c, t); }
};

TEST(InertialResiduals, ImuResidualVanishesAtGroundTruth) {
  Rig rig;
  rig.imu.white_noise = false;
  std::mt19937 rng(1);
  const double t0 = 1.0, t1 = 1.5;
  const auto pre = rig.imu.preintegrate(rig.motion, t0, t1, rig.imu.true_bias, &rng);
  ImuFactor f(*pre, rig.T_b_c);
  const auto pi = block(rig.T_c_w(t0)), pj = block(rig.T_c_w(t1));
  const Eigen::Vector3d vi = rig.motion.v_w(t0), vj = rig.motion.v_w(t1);
  const auto b = bias_block(rig.imu.true_bias);
  Eigen::Matrix<double, 9, 1> r;
  f.residual(pi.data(), vi.data(), b.data(), pj.data(), vj.data(), rig.imu.g_w.data(), r.data());
  const double whitened = r.norm();
  f.sqrt_info.setIdentity();  // the raw residual
  f.residual(pi.data(), vi.data(), b.data(), pj.data(), vj.data(), rig.imu.g_w.data(), r.data());
  std::printf("IMU residual at ground truth: raw |r_R| %.3g rad, |r_v| %.3g m/s, |r_p| %.3g m; whitened %.3g\n",
              r.head<3>().norm(), r.segment<3>(3).norm(), r.tail<3>().norm(), whitened);
  EXPECT_LT(r.head<3>().norm(), 1e-6);
  EXPECT_LT(r.segment<3>(3).norm(), 1e-5);
  EXPECT_LT(r.tail<3>().norm(), 1e-5);
  EXPECT_LT(whitened, 0.05);  // far below the noise of a real IMU

  // A known error: pose j turned by 0.01 rad about the world's z axis
  // shows as a rotation residual of 0.01 rad.
  const geom::SE3d T_w_cj = rig.T_c_w(t1).inverse();
  const geom::SE3d turned = (geom::make_se3(geom::so3_exp(Eigen::Vector3d(0, 0, 0.01)), Eigen::Vector3d::Zero()) *
                             geom::make_se3(T_w_cj.linear(), Eigen::Vector3d::Zero()));
  const geom::SE3d T_cj_w_turned = geom::make_se3(turned.linear(), T_w_cj.translation()).inverse();
  const auto pj_turned = block(T_cj_w_turned);
  f.residual(pi.data(), vi.data(), b.data(), pj_turned.data(), vj.data(), rig.imu.g_w.data(), r.data());
  EXPECT_NEAR(r.head<3>().norm(), 0.01, 1e-5);
}

TEST(InertialResiduals, WhitenedImuResidualIsChiSquare) {
  // With noisy readings the whitened residual at the truth has |r|^2 ~ chi2(9).
  Rig rig;
  std::mt19937 rng(2);
  double sum = 0;
  const int n = 60;
  for (int k = 0; k < n; ++k) {
    const double t0 = 0.5 + 0.25 * k, t1 = t0 + 0.25;
    const auto pre = rig.imu.preintegrate(rig.motion, t0, t1, rig.imu.true_bias, &rng);
    const ImuFactor f(*pre, rig.T_b_c);
    const auto pi = block(rig.T_c_w(t0)), pj = block(rig.T_c_w(t1));
    const Eigen::Vector3d vi = rig.motion.v_w(t0), vj = rig.motion.v_w(t1);
    const auto b = bias_block(rig.imu.true_bias);
    Eigen::Matrix<double, 9, 1> r;
    f.residual(pi.data(), vi.data(), b.data(), pj.data(), vj.data(), rig.imu.g_w.data(), r.data());
    sum += r.squaredNorm();
  }
  std::printf("whitened IMU residual: mean |r|^2 %.2f over %d intervals (chi2(9): 9)\n", sum / n, n);
  // Mean of 60 chi2(9) draws: 9 +- 0.55.
  EXPECT_GT(sum / n, 7.0);
  EXPECT_LT(sum / n, 11.0);
}

TEST(InertialResiduals, BiasWalk) {
  ImuPreintegration pre(ImuBias{}, sensor::ImuNoise{});
  for (int k = 0; k < 100; ++k) pre.integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.81), 0.01);
  const BiasWalkFactor f(pre);
  const std::array<double, 6> bi = {0.001, 0, 0, 0.01, 0, 0}, bj = {0.001, 0, 0, 0.01, 0, 0.004};
  double r[6];
  f.residual(bi.data(), bi.data(), r);
  for (double x : r) EXPECT_EQ(x, 0.0);
  f.residual(bi.data(), bj.data(), r);
  // 0.004 m/s^2 over 1 s at 4e-4 m/s^3/sqrt(Hz): 10 sigma.
  EXPECT_NEAR(r[5], 0.004 / (sensor::ImuNoise{}.accel_random_walk * 1.0), 1e-9);
  EXPECT_THROW(BiasWalkFactor(ImuPreintegration(ImuBias{}, sensor::ImuNoise{})), std::invalid_argument);
}

TEST(InertialResiduals, WheelResidualVanishesOnFlatGround) {
  Rig rig;
  rig.motion.pitch_rad = {};
  rig.motion.roll_rad = {};
  rig.motion.z_m = {};
  WheelRig wheels;
  const double t0 = 2.0, t1 = 3.5;
  const auto pre = wheels.preintegrate(rig.motion, t0, t1);
  const WheelFactor f(*pre, rig.T_base_c);
  const auto pi = block(rig.T_c_w(t0)), pj = block(rig.T_c_w(t1));
  Eigen::Matrix<double, 6, 1> r;
  f.residual(pi.data(), pj.data(), r.data());
  std::printf("wheel residual on flat ground (1.5 s): whitened planar %.3g, tilt %.3g\n", r.head<3>().norm(),
              r.tail<3>().norm());
  ASSERT_GT(pre->delta().head<2>().norm(), 1.0);  // it did drive
  EXPECT_LT(r.head<3>().norm(), 0.3);
  EXPECT_LT(r.tail<3>().norm(), 1e-6);

  // The base at j lifted by 5 cm: z row = 0.05 / planar sigma.
  const geom::SE3d lifted = geom::make_se3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 0.05)) *
                            rig.motion.T_w_base(t1) * rig.T_base_c;
  const auto pj_lifted = block(lifted.inverse());
  f.residual(pi.data(), pj_lifted.data(), r.data());
  EXPECT_NEAR(r[3], 0.05 / pre->planar_sigma()[0], 1e-6);
  // A 5 cm slip sideways, with a metre of travel: a large planar residual.
  const geom::SE3d slipped = rig.motion.T_w_base(t1) * geom::make_se3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0.05, 0)) * rig.T_base_c;
  const auto pj_slipped = block(slipped.inverse());
  f.residual(pi.data(), pj_slipped.data(), r.data());
  EXPECT_GT(r.head<3>().norm(), 1.0);
}

TEST(InertialResiduals, GravityResidualIsTheTiltAngle) {
  Rig rig;
  const double t = 1.2;
  const geom::SE3d T_c_w = rig.T_c_w(t);
  const Eigen::Vector3d g_w(0, 0, -9.81);
  const Eigen::Vector3d f_c = T_c_w.linear() * -g_w;  // at rest: +g up, in the camera
  const double sigma = 0.01;
  const GravityFactor f(f_c, g_w, sigma);
  auto p = block(T_c_w);
  double r[2];
  f.residual(p.data(), r);
  EXPECT_LT(std::hypot(r[0], r[1]), 1e-9);
  // The camera tilted by 0.02 rad about an axis orthogonal to up: |r| = 0.02 / sigma.
  const Eigen::Vector3d axis = f_c.cross(Eigen::Vector3d::UnitZ()).normalized();
  const geom::SE3d tilted = geom::make_se3(geom::so3_exp(0.02 * axis), Eigen::Vector3d::Zero()) * T_c_w;
  p = block(tilted);
  f.residual(p.data(), r);
  EXPECT_NEAR(std::hypot(r[0], r[1]), 0.02 / sigma, 1e-6);
  // A turn about gravity does not change the tilt.
  const geom::SE3d yawed = T_c_w * geom::make_se3(geom::so3_exp(Eigen::Vector3d(0, 0, 0.3)), Eigen::Vector3d::Zero());
  p = block(yawed);
  f.residual(p.data(), r);
  EXPECT_LT(std::hypot(r[0], r[1]), 1e-9);
  EXPECT_THROW(GravityFactor(Eigen::Vector3d::Zero(), g_w, sigma), std::invalid_argument);
}

TEST(InertialResiduals, SqrtInformationWhitensAndRegularises) {
  Eigen::Matrix3d cov;
  cov << 4, 1, 0, 1, 2, 0.5, 0, 0.5, 1;
  const Eigen::Matrix3d W = sqrt_information<3>(cov);
  EXPECT_LT((W.transpose() * W - cov.inverse()).norm(), 1e-12);
  const Eigen::Matrix3d singular = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
  const Eigen::Matrix3d Ws = sqrt_information<3>(singular);
  EXPECT_TRUE(Ws.allFinite());
  EXPECT_NEAR(Ws.cwiseAbs().maxCoeff(), 1e5, 1.0);  // floor 1e-10 of the largest variance
}

}  // namespace
}  // namespace pvb::slam
