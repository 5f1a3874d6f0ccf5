// The start from two views (slam/core/two_view_start): synthetic points
// seen from two poses, with a measured depth on a few of them.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pvb/slam/core/two_view_start.hpp"

namespace pvb::slam {
namespace two_view_start_test {

constexpr int kW = 640, kH = 480;

std::shared_ptr<const CameraModel> camera() {
  return std::make_shared<const CameraModel>(CameraModel::make(StereoIntrinsics{}, kW, kH, {}, 3.0, 1.2, 8));
}

/// Points in the first view's frame, each in its image, and their random
/// descriptors.
struct Scene {
  std::vector<Eigen::Vector3d> p_ref;
  cv::Mat descriptors;
};

Scene make_scene(int n, std::uint64_t seed) {
  cv::RNG rng(seed);
  Scene s;
  s.descriptors = cv::Mat(n, 32, CV_8U);
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform(20.0, kW - 20.0), v = rng.uniform(20.0, kH - 20.0), z = rng.uniform(2.0, 6.0);
    s.p_ref.push_back(camera()->unproject(Eigen::Vector2d(u, v), z));
    for (int b = 0; b < 32; ++b) s.descriptors.at<std::uint8_t>(i, b) = static_cast<std::uint8_t>(rng.uniform(0, 256));
  }
  return s;
}

/// The view of the scene from T_c_ref: every point in the image, 0.3 px
/// of noise, a measured depth (0.5 % noise) on the first `with_depth`.
Frame view(const Scene& s, const geom::SE3d& T_c_ref, int with_depth, std::uint64_t seed) {
  const auto cam = camera();
  cv::RNG rng(seed);
  std::vector<cv::Point2f> keys;
  std::vector<Keypoint> keys_un;
  std::vector<float> depth;
  cv::Mat desc;
  for (std::size_t i = 0; i < s.p_ref.size(); ++i) {
    const Eigen::Vector3d p = T_c_ref * s.p_ref[i];
    const double dv = rng.gaussian(0.3), du = rng.gaussian(0.3);
    const Eigen::Vector2d uv = cam->project(p) + Eigen::Vector2d(du, dv);
    if (!(p.z() > 0) || !cam->in_bounds(uv.x(), uv.y())) continue;
    const cv::Point2f pt(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
    keys.push_back(pt);
    keys_un.push_back({pt, 0.0f, 0});
    depth.push_back(static_cast<int>(i) < with_depth ? static_cast<float>(p.z() * (1 + rng.gaussian(0.005))) : 0.0f);
    desc.push_back(s.descriptors.row(static_cast<int>(i)));
  }
  return Frame::from_saved(seed, 0, keys, keys_un, desc, depth, cam);
}

geom::SE3d motion(double yaw_deg, const Eigen::Vector3d& t_m) {
  return geom::make_se3(Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix(), t_m);
}

double angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180 / M_PI;
}

TEST(TwoViewStart, RecoversTheMetricMotionFromAFewMeasuredDepths) {
  const Scene s = make_scene(400, 1);
  const geom::SE3d T = motion(2.0, Eigen::Vector3d(0.25, 0.02, -0.1));
  const Frame ref = view(s, geom::SE3d::Identity(), 8, 2), cur = view(s, T, 0, 3);
  std::string why;
  TwoViewFailure failure{};
  const auto r = two_view_start(ref, cur, TwoViewOptions{}, &why, &failure);
  ASSERT_TRUE(r) << why;
  EXPECT_LT((r->T_cur_ref.translation() - T.translation()).norm(), 0.01);  // 4 % of 0.27 m
  EXPECT_LT(angle_deg(r->T_cur_ref.linear(), T.linear()), 0.1);
  EXPECT_GE(r->scale_points, 5);
  EXPECT_GT(r->median_parallax_deg, 1.0);
  ASSERT_GE(r->matches.size(), 300u);
  // Points where they are (keypoint i of the first view is point i: every
  // point lies in its image): within 3 sigma of two-view triangulation,
  // z^2 x 0.3 px x sqrt(2) / (fx x baseline), and 2 % of the scale.
  int near_truth = 0;
  const double baseline_m = T.translation().norm();
  for (std::size_t k = 0; k < r->matches.size(); ++k) {
    const Eigen::Vector3d& truth = s.p_ref[r->matches[k].i1];
    const double sigma_m = truth.z() * truth.z() * 0.3 * std::sqrt(2.0) / (525.0 * baseline_m);
    near_truth += (r->p_ref_m[k] - truth).norm() < 3 * sigma_m + 0.02 * truth.norm();
  }
  EXPECT_GE(near_truth, static_cast<int>(r->matches.size()) * 95 / 100);
  // The same inputs, the same start.
  const auto again = two_view_start(ref, cur, TwoViewOptions{}, &why, &failure);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->T_cur_ref.matrix(), r->T_cur_ref.matrix());
}

TEST(TwoViewStart, WaitsForParallaxAndForMeasuredDepths) {
  const Scene s = make_scene(400, 4);
  std::string why;
  TwoViewFailure failure{};
  // 1 cm of motion: the rays of a point 4 m away meet at 0.14 degrees.
  const Frame ref = view(s, geom::SE3d::Identity(), 8, 5);
  EXPECT_FALSE(two_view_start(ref, view(s, motion(0.5, Eigen::Vector3d(0.01, 0, 0)), 0, 6), TwoViewOptions{}, &why,
                              &failure));
  EXPECT_EQ(failure, TwoViewFailure::kNotYet) << why;
  // Enough parallax, but no depth in either view: no scale.
  const Frame blind = view(s, geom::SE3d::Identity(), 0, 7);
  EXPECT_FALSE(two_view_start(blind, view(s, motion(2.0, Eigen::Vector3d(0.25, 0, 0)), 0, 8), TwoViewOptions{}, &why,
                              &failure));
  EXPECT_EQ(failure, TwoViewFailure::kNotYet);
  EXPECT_NE(why.find("measured depths"), std::string::npos) << why;
}

TEST(TwoViewStart, AnotherViewHasTooFewMatches) {
  const Scene a = make_scene(400, 9), b = make_scene(400, 10);  // other descriptors
  std::string why;
  TwoViewFailure failure{};
  EXPECT_FALSE(two_view_start(view(a, geom::SE3d::Identity(), 8, 11), view(b, geom::SE3d::Identity(), 8, 12),
                              TwoViewOptions{}, &why, &failure));
  EXPECT_EQ(failure, TwoViewFailure::kFewMatches) << why;
  EXPECT_NE(why.find("matches (need 100)"), std::string::npos) << why;
}

}  // namespace two_view_start_test
}  // namespace pvb::slam
