#pragma once
// Synthetic pose-optimisation and bundle-adjustment problems with known
// ground truth, shared by the optimiser tests and bench/bench_optim.cpp
// (target pvb::slam_optim_synthetic; never linked by the SLAM libraries).
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/optim/optimizer.hpp"

namespace pvb::slam::testing {

constexpr double kWidth = 640, kHeight = 480;
constexpr double kPi = 3.14159265358979323846;

inline StereoIntrinsics default_intrinsics() { return StereoIntrinsics{}; }  // fx 525, bf 40

/// (x, y, z) from three draws, z drawn first.  Every problem here draws a
/// vector's coordinates last to first, so that it is the same whichever
/// compiler builds it (C++ leaves the order of a constructor's arguments
/// open; GCC evaluates them last to first, as these problems were made).
template <class DistX, class DistY, class DistZ, class Rng>
Eigen::Vector3d draw_zyx(DistX& dx, DistY& dy, DistZ& dz, Rng& rng) {
  const double z = dz(rng);
  const double y = dy(rng);
  const double x = dx(rng);
  return {x, y, z};
}
template <class Dist, class Rng>
Eigen::Vector3d draw_zyx(Dist& d, Rng& rng) {
  return draw_zyx(d, d, d, rng);
}
/// (x, y) from two draws, y drawn first (see draw_zyx).
template <class Dist, class Rng>
Eigen::Vector2d draw_yx(Dist& d, Rng& rng) {
  const double y = d(rng);
  const double x = d(rng);
  return {x, y};
}

/// Rotates by rot_deg about a random axis and shifts by trans_m in a random
/// direction, applied in the camera frame: T <- dT * T.
inline geom::SE3d perturb(const geom::SE3d& T, double trans_m, double rot_deg, std::mt19937& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const Eigen::Vector3d axis = draw_zyx(n01, rng).normalized();
  const Eigen::Vector3d dir = draw_zyx(n01, rng).normalized();
  const geom::SE3d dT = geom::make_se3(geom::so3_exp(axis * rot_deg * kPi / 180.0), dir * trans_m);
  return dT * T;
}

/// Distance between the camera centres of two T_c_w poses (metres).
inline double position_error_m(const geom::SE3d& T_a_w, const geom::SE3d& T_b_w) {
  return (T_a_w.inverse().translation() - T_b_w.inverse().translation()).norm();
}
/// Angle between the rotations of two poses (degrees).
inline double rotation_error_deg(const geom::SE3d& T_a_w, const geom::SE3d& T_b_w) {
  return geom::rotation_angle_rad(T_a_w.linear() * T_b_w.linear().transpose()) * 180.0 / kPi;
}

/// Noisy observation of p_c (camera frame, z > 0); stereo adds u_right.
inline Observation observe(const StereoIntrinsics& K, const Eigen::Vector3d& p_c, bool stereo, double noise_px,
                           std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, noise_px);
  Observation o;
  const Eigen::Vector2d uv = project(K, p_c);
  o.uv = uv + draw_yx(noise, rng);
  o.u_right = stereo ? uv.x() - K.bf / p_c.z() + noise(rng) : -1.0;
  o.inv_sigma2 = 1.0;  // sigma 1 px (ORB-SLAM2 pyramid level 0)
  return o;
}

/// Ground-truth camera used by the pose-only problems.
inline geom::SE3d pose_gt() {
  return geom::make_se3(geom::so3_exp(Eigen::Vector3d(0.05, -0.3, 0.1)), Eigen::Vector3d(0.4, -0.2, 1.5));
}

struct PoseScene {
  geom::SE3d T_c_w_gt;
  std::vector<Eigen::Vector3d> points_w;
  std::vector<Observation> obs;
  std::vector<std::uint8_t> is_outlier;  ///< ground truth: observation replaced by a gross outlier
};

/// n points seen by pose_gt() at depths 1..6 m with Gaussian pixel noise;
/// a fraction outlier_ratio of the observations replaced by random pixels at
/// least 20 px away from the true projection.
inline PoseScene make_pose_scene(int n, double noise_px, bool stereo, double outlier_ratio, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(0, kWidth), uy(0, kHeight), uz(1.0, 6.0), u01(0, 1);
  const StereoIntrinsics K = default_intrinsics();
  PoseScene s;
  s.T_c_w_gt = pose_gt();
  const geom::SE3d T_w_c = s.T_c_w_gt.inverse();
  for (int i = 0; i < n; ++i) {
    const double z = uz(rng);
    const double v = uy(rng), u = ux(rng);
    const Eigen::Vector3d p_c((u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z);
    s.points_w.push_back(T_w_c * p_c);
    Observation o = observe(K, p_c, stereo, noise_px, rng);
    const bool outlier = u01(rng) < outlier_ratio;
    if (outlier) {
      const Eigen::Vector2d uv_true = project(K, p_c);
      do {
        o.uv = {ux(rng), uy(rng)};
      } while ((o.uv - uv_true).norm() < 20.0);
      if (stereo) o.u_right = o.uv.x() - K.bf / uz(rng);
    }
    s.obs.push_back(o);
    s.is_outlier.push_back(outlier ? 1 : 0);
  }
  return s;
}

struct BaScene {
  std::vector<geom::SE3d> T_c_w_gt;
  std::vector<Eigen::Vector3d> points_gt;
  BaProblem problem;  ///< ground truth with noisy observations; perturb to start
};

/// num_keyframes cameras 0.25 m apart along x, looking along +z with small
/// rotations; num_points points in a box 2..6 m in front, each kept only if
/// at least two keyframes see it inside the image.  The first num_fixed
/// keyframes are fixed.
inline BaScene make_ba_scene(int num_keyframes, int num_fixed, int num_points, double noise_px, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(-1.5, 1.5 + 0.25 * num_keyframes), uy(-1.2, 1.2), uz(2.0, 6.0);
  std::uniform_real_distribution<double> small(-0.05, 0.05);
  const StereoIntrinsics K = default_intrinsics();
  BaScene s;
  for (int k = 0; k < num_keyframes; ++k) {
    const Eigen::Vector3d c_w(0.25 * k, 0.02 * k, 0.05 * std::sin(k));
    const Eigen::Matrix3d R_w_c = geom::so3_exp(draw_zyx(small, rng));
    const geom::SE3d T_c_w = geom::make_se3(R_w_c, c_w).inverse();
    s.T_c_w_gt.push_back(T_c_w);
    BaKeyframe kf;
    kf.id = 100 + static_cast<std::uint64_t>(k);
    kf.T_c_w = T_c_w;
    kf.fixed = k < num_fixed;
    s.problem.keyframes.push_back(kf);
  }
  while (static_cast<int>(s.points_gt.size()) < num_points) {
    const Eigen::Vector3d p_w = draw_zyx(ux, uy, uz, rng);
    std::vector<BaEdge> edges;
    for (int k = 0; k < num_keyframes; ++k) {
      const Eigen::Vector3d p_c = s.T_c_w_gt[static_cast<std::size_t>(k)] * p_w;
      if (p_c.z() <= 0.1) continue;
      const Eigen::Vector2d uv = project(K, p_c);
      if (uv.x() < 0 || uv.x() >= kWidth || uv.y() < 0 || uv.y() >= kHeight) continue;
      BaEdge e;
      e.keyframe = static_cast<std::size_t>(k);
      e.point = s.points_gt.size();
      e.obs = observe(K, p_c, true, noise_px, rng);
      edges.push_back(e);
    }
    if (edges.size() < 2) continue;
    BaPoint pt;
    pt.id = 1000 + s.points_gt.size();
    pt.p_w = p_w;
    s.points_gt.push_back(p_w);
    s.problem.points.push_back(pt);
    s.problem.edges.insert(s.problem.edges.end(), edges.begin(), edges.end());
  }
  return s;
}

/// Perturbs the non-fixed keyframes by trans_m / rot_deg and moves every
/// point by point_m in a random direction.
inline void perturb_ba(BaProblem* problem, double trans_m, double rot_deg, double point_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (auto& kf : problem->keyframes) {
    if (!kf.fixed) kf.T_c_w = perturb(kf.T_c_w, trans_m, rot_deg, rng);
  }
  for (auto& p : problem->points) {
    p.p_w += point_m * draw_zyx(n01, rng).normalized();
  }
}

}  // namespace pvb::slam::testing
