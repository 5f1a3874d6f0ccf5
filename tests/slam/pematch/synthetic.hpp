#pragma once
// Synthetic two-view data with known inliers for the PE-match tests.
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "pvb/slam/pematch/fundamental.hpp"

namespace pvb::slam::test {

struct TwoViewData {
  std::vector<PointMatch> matches;
  std::vector<PointMatch> clean;   ///< noise-free positions of every match (inliers only meaningful)
  std::vector<bool> is_inlier;
  Eigen::Matrix3d F_true;          ///< x2^T F x1 = 0
};

/// Points in front of two 640x480 cameras (f = 500), camera 2 rotated and
/// translated; `outlier_ratio` of the matches get a random second point.
inline TwoViewData make_two_view(int n, double outlier_ratio, double noise_px, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(0, 640), uy(0, 480), uz(2.0, 8.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  Eigen::Matrix3d K;
  K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(0.10, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Vector3d t(0.4, 0.05, 0.1);  // p_2 = R p_1 + t
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  TwoViewData d;
  d.F_true = K.inverse().transpose() * tx * R * K.inverse();
  d.F_true /= d.F_true.norm();
  const int n_out = static_cast<int>(n * outlier_ratio + 0.5);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d p2c;
    Eigen::Vector2d u1, u2;
    // sample until the point is visible in both images
    for (;;) {
      u1 = {ux(rng), uy(rng)};
      const double z = uz(rng);
      const Eigen::Vector3d P1 = z * (K.inverse() * u1.homogeneous());
      p2c = R * P1 + t;
      const Eigen::Vector3d h = K * p2c;
      u2 = h.hnormalized();
      if (p2c.z() > 0 && u2.x() >= 0 && u2.x() < 640 && u2.y() >= 0 && u2.y() < 480) break;
    }
    PointMatch clean{u1, u2};
    // Each noise drawn v first: the order the pinned matches were made in.
    const double dv1 = noise(rng), du1 = noise(rng), dv2 = noise(rng), du2 = noise(rng);
    PointMatch m{u1 + Eigen::Vector2d(du1, dv1), u2 + Eigen::Vector2d(du2, dv2)};
    const bool inl = i >= n_out;
    if (!inl) m.p2 = {ux(rng), uy(rng)};
    d.matches.push_back(m);
    d.clean.push_back(clean);
    d.is_inlier.push_back(inl);
  }
  // shuffle so that outliers are not a prefix
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  TwoViewData s = d;
  for (int i = 0; i < n; ++i) {
    s.matches[i] = d.matches[order[i]];
    s.clean[i] = d.clean[order[i]];
    s.is_inlier[i] = d.is_inlier[order[i]];
  }
  return s;
}

}  // namespace pvb::slam::test
