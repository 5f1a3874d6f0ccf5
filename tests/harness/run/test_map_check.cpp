// map-check on synthetic maps: unbiased noise reads as noise-limited; a
// measurement error that grows along the trajectory (a pitch drift in the
// image, as a miscalibrated or biased front end makes) reads as systematic.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pvb/run/map_check.hpp"
#include "pvb/slam/optim/synthetic.hpp"

namespace {

using pvb::slam::MapSnapshot;

struct Synthetic {
  MapSnapshot map;
  pvb::eval::Trajectory gt;
};

/// make_ba_scene's keyframes and points with noisy measurements; the
/// snapshot's poses are the truth.  `pitch_px_per_kf` shifts every
/// measurement of keyframe k by k times that many pixels in v.
Synthetic make(double noise_px, double pitch_px_per_kf) {
  const auto scene = pvb::slam::testing::make_ba_scene(24, 1, 400, 0.0, 5);
  Synthetic s;
  s.map.K = pvb::slam::testing::default_intrinsics();
  s.map.scale_factor = 1.2;
  for (std::size_t k = 0; k < scene.T_c_w_gt.size(); ++k) {
    const std::int64_t t_ns = 1'000'000'000 + static_cast<std::int64_t>(k) * 100'000'000;
    s.map.keyframes.push_back({scene.problem.keyframes[k].id, t_ns, scene.T_c_w_gt[k]});
    s.gt.poses.push_back({t_ns, scene.T_c_w_gt[k].inverse()});
  }
  s.gt.source = "synthetic";
  for (std::size_t i = 0; i < scene.points_gt.size(); ++i) s.map.points.push_back({static_cast<std::uint64_t>(1000 + i), scene.points_gt[i], 0});
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, noise_px);
  for (const auto& e : scene.problem.edges) {
    MapSnapshot::Measurement m;
    m.keyframe = e.keyframe;
    m.point = e.point;
    const double dv = n(rng), du = n(rng);  // drawn v first, as the pinned problems were
    m.uv = e.obs.uv + Eigen::Vector2d(du, dv + pitch_px_per_kf * static_cast<double>(e.keyframe));
    m.u_right = e.obs.u_right + (m.uv.x() - e.obs.uv.x()) + n(rng) * 0.2;
    m.octave = 0;
    s.map.measurements.push_back(m);
  }
  return s;
}

TEST(MapCheck, UnbiasedNoiseReadsAsNoiseLimited) {
  const Synthetic s = make(0.5, 0.0);
  pvb::run::MapCheckOptions o;
  o.draws = 8;
  const auto r = pvb::run::check_map(s.map, s.gt, o);
  EXPECT_EQ(r.keyframes, 24u);
  EXPECT_LT(r.estimate.ate_rmse_m, 1e-9);  // the snapshot holds the truth
  EXPECT_NEAR(r.residual_rms.x(), 0.5, 0.1);
  ASSERT_EQ(r.gaussian.size(), 8u);
  ASSERT_EQ(r.sign_flipped.size(), 8u);
  double flipped_max = 0;
  for (const auto& f : r.sign_flipped) flipped_max = std::max(flipped_max, f.ate_rmse_m);
  EXPECT_GT(r.measured.ate_rmse_m, 0.0);
  EXPECT_LT(r.measured.ate_rmse_m, 2 * flipped_max);
  for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(r.measured.rot_t[k]), 3.0) << k;
  EXPECT_NE(pvb::run::format_map_check(r).find("noise-limited"), std::string::npos) << pvb::run::format_map_check(r);
}

TEST(MapCheck, ErrorGrowingAlongTheTrajectoryReadsAsSystematic) {
  const Synthetic s = make(0.5, 0.2);
  pvb::run::MapCheckOptions o;
  o.draws = 8;
  const auto r = pvb::run::check_map(s.map, s.gt, o);
  // v grows by 0.2 px per keyframe: a pitch of 0.2 / fy rad per pair
  const double expected_deg = 0.2 / s.map.K.fy * 180 / M_PI;
  EXPECT_NEAR(std::abs(r.measured.rot_mean_deg.x()), expected_deg, 0.5 * expected_deg);
  EXPECT_GT(std::abs(r.measured.rot_t.x()), 3.0);
  for (const auto& f : r.sign_flipped) EXPECT_LT(std::abs(f.rot_t.x()), std::abs(r.measured.rot_t.x()));
  EXPECT_NE(pvb::run::format_map_check(r).find("systematic"), std::string::npos) << pvb::run::format_map_check(r);
}

TEST(MapCheck, KeyframeWithoutGroundTruthIsAnError) {
  Synthetic s = make(0.5, 0.0);
  s.gt.poses.pop_back();
  EXPECT_THROW(pvb::run::check_map(s.map, s.gt, {}), pvb::Error);
}

}  // namespace
