#include <gtest/gtest.h>

#include <Eigen/SVD>

#include "pvb/slam/pematch/fundamental.hpp"
#include "synthetic.hpp"

namespace pvb::slam {
namespace {

TEST(Fundamental, EightPointExactSatisfiesEpipolarConstraintAndRank2) {
  const auto d = test::make_two_view(8, 0.0, 0.0, 7);
  std::array<PointMatch, 8> m;
  for (int i = 0; i < 8; ++i) m[i] = d.matches[i];
  Eigen::Matrix3d F;
  ASSERT_TRUE(fundamental_8point(m, F));
  EXPECT_NEAR(F.norm(), 1.0, 1e-12);
  for (const auto& c : m) {
    const double r = c.p2.homogeneous().dot(F * c.p1.homogeneous());
    EXPECT_NEAR(r, 0.0, 1e-9);
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(F);
  EXPECT_LT(svd.singularValues()(2), 1e-12 * svd.singularValues()(0));
  EXPECT_GT(svd.singularValues()(1), 1e-6 * svd.singularValues()(0));
  // Eight generic points determine F uniquely: it equals the true one up to sign.
  const double s = (F.cwiseProduct(d.F_true).sum() > 0) ? 1.0 : -1.0;
  EXPECT_LT((s * F - d.F_true).norm(), 1e-6);
}

TEST(Fundamental, EpipolarDistanceHandComputed) {
  // Rectified pair: l2 = F x1 = (0, -1, y1), the row y = y1.
  Eigen::Matrix3d F;
  F << 0, 0, 0, 0, 0, -1, 0, 1, 0;
  EXPECT_DOUBLE_EQ(epipolar_distance_px(F, {10, 20}, {5, 22}), 2.0);
  EXPECT_TRUE(within_epipolar_threshold(F, {10, 20}, {5, 22}, 2.0));
  EXPECT_FALSE(within_epipolar_threshold(F, {10, 20}, {5, 22}, 1.99));
  // Constant line 3x + 4y - 10 = 0; point (2, 3): |6 + 12 - 10| / 5 = 1.6.
  Eigen::Matrix3d G;
  G << 0, 0, 3, 0, 0, 4, 0, 0, -10;
  EXPECT_NEAR(epipolar_distance_px(G, {123, 45}, {2, 3}), 1.6, 1e-15);
  // Sampson: G^T x2 = (0, 0, 8), so the denominator is 3^2 + 4^2 and the
  // squared distance is 8^2 / 25 = 1.6^2.
  EXPECT_NEAR(sampson_distance_sq(G, {123, 45}, {2, 3}), 2.56, 1e-12);
}

TEST(Fundamental, CollinearSampleIsDegenerate) {
  std::array<PointMatch, 8> m;
  for (int i = 0; i < 8; ++i) m[i] = {{10.0 + 30 * i, 20.0 + 15 * i}, {5.0 + 7 * i * i, 100.0 - 3 * i}};
  Eigen::Matrix3d F;
  EXPECT_FALSE(fundamental_8point(m, F));
}

TEST(Fundamental, IrlsRefinementReducesErrorOnNoisyInliers) {
  // F from 8 noisy points vs the same F refined on all 200 noisy inliers:
  // refinement must move it closer to the true epipolar geometry.
  double err_plain = 0, err_refined = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const auto d = test::make_two_view(200, 0.0, 0.7, seed);
    std::array<PointMatch, 8> m;
    for (int i = 0; i < 8; ++i) m[i] = d.matches[i];
    Eigen::Matrix3d F;
    ASSERT_TRUE(fundamental_8point(m, F));
    Eigen::Matrix3d Fr = F;
    ASSERT_TRUE(refine_fundamental_irls(d.matches.data(), d.matches.size(), 3.0, 5, Fr));
    for (const auto& c : d.clean) {
      err_plain += epipolar_distance_px(F, c.p1, c.p2);
      err_refined += epipolar_distance_px(Fr, c.p1, c.p2);
    }
  }
  EXPECT_LT(err_refined, 0.5 * err_plain);
}

}  // namespace
}  // namespace pvb::slam
