// local_bundle_adjustment(): ORB-SLAM2's LocalBundleAdjustment on synthetic
// keyframes and points with known ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <set>
#include <stdexcept>

#include "pvb/slam/optim/optimizer.hpp"
#include "pvb/slam/optim/synthetic.hpp"

namespace pvb::slam {
namespace {

using testing::make_ba_scene;
using testing::perturb_ba;
using testing::position_error_m;
using testing::rotation_error_deg;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

std::vector<double> point_errors(const BaProblem& p, const std::vector<Eigen::Vector3d>& gt) {
  std::vector<double> e;
  for (std::size_t i = 0; i < gt.size(); ++i) e.push_back((p.points[i].p_w - gt[i]).norm());
  return e;
}

TEST(LocalBundleAdjustment, ConvergesToGroundTruthAndKeepsFixedKeyframes) {
  auto s = make_ba_scene(5, 2, 500, 1.0, 21);
  perturb_ba(&s.problem, 0.05, 2.0, 0.05, 22);
  for (std::size_t k = 2; k < 5; ++k) {
    ASSERT_GT(position_error_m(s.problem.keyframes[k].T_c_w, s.T_c_w_gt[k]), 0.04);
  }
  const BaProblem before = s.problem;
  const double median_before = median(point_errors(s.problem, s.points_gt));

  const BaResult r = local_bundle_adjustment(&s.problem, testing::default_intrinsics());
  EXPECT_GT(r.iterations, 0);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(0, std::memcmp(s.problem.keyframes[k].T_c_w.matrix().data(),
                             before.keyframes[k].T_c_w.matrix().data(), sizeof(double) * 16))
        << "fixed keyframe " << k << " moved";
  }
  for (std::size_t k = 2; k < 5; ++k) {
    EXPECT_LT(position_error_m(s.problem.keyframes[k].T_c_w, s.T_c_w_gt[k]), 0.01) << "keyframe " << k;
    EXPECT_LT(rotation_error_deg(s.problem.keyframes[k].T_c_w, s.T_c_w_gt[k]), 0.2) << "keyframe " << k;
  }
  EXPECT_LT(median(point_errors(s.problem, s.points_gt)), median_before);
  // Ids are not touched.
  for (std::size_t i = 0; i < s.problem.points.size(); ++i) EXPECT_EQ(s.problem.points[i].id, before.points[i].id);
}

TEST(LocalBundleAdjustment, FlagsInjectedBadEdges) {
  auto s = make_ba_scene(5, 2, 500, 1.0, 23);
  perturb_ba(&s.problem, 0.05, 2.0, 0.05, 24);
  std::mt19937 rng(25);
  std::uniform_int_distribution<std::size_t> pick(0, s.problem.edges.size() - 1);
  std::uniform_real_distribution<double> angle(0, 2 * testing::kPi), shift(20.0, 40.0);
  std::set<std::size_t> bad;
  while (bad.size() < 20) bad.insert(pick(rng));
  for (std::size_t e : bad) {
    const double a = angle(rng), d = shift(rng);
    s.problem.edges[e].obs.uv += d * Eigen::Vector2d(std::cos(a), std::sin(a));
    s.problem.edges[e].obs.u_right += d * std::cos(a);
  }

  const BaResult r = local_bundle_adjustment(&s.problem, testing::default_intrinsics());
  const std::set<std::size_t> flagged(r.outlier_edges.begin(), r.outlier_edges.end());
  EXPECT_EQ(flagged.size(), r.outlier_edges.size()) << "duplicate outlier indices";
  for (std::size_t e : bad) EXPECT_TRUE(flagged.count(e)) << "bad edge " << e << " not flagged";
  // Good edges have 1 px noise at a model sigma of 1 px: the 95 % chi2 gate
  // flags ~5 % of them by design; twice that means something is wrong.
  const std::size_t good = s.problem.edges.size() - bad.size();
  const std::size_t good_flagged = flagged.size() - bad.size();
  EXPECT_LT(good_flagged, 0.10 * good);
  for (std::size_t k = 2; k < 5; ++k) {
    EXPECT_LT(position_error_m(s.problem.keyframes[k].T_c_w, s.T_c_w_gt[k]), 0.01) << "keyframe " << k;
  }
}

TEST(LocalBundleAdjustment, SameInputGivesBitIdenticalOutput) {
  auto s = make_ba_scene(5, 2, 300, 1.0, 26);
  perturb_ba(&s.problem, 0.05, 2.0, 0.05, 27);
  s.problem.edges[3].obs.uv.x() += 30.0;  // exercise the outlier path too
  BaProblem a = s.problem, b = s.problem;
  const BaResult ra = local_bundle_adjustment(&a, testing::default_intrinsics());
  const BaResult rb = local_bundle_adjustment(&b, testing::default_intrinsics());
  EXPECT_EQ(ra.outlier_edges, rb.outlier_edges);
  EXPECT_EQ(ra.iterations, rb.iterations);
  for (std::size_t k = 0; k < a.keyframes.size(); ++k) {
    EXPECT_EQ(0, std::memcmp(a.keyframes[k].T_c_w.matrix().data(), b.keyframes[k].T_c_w.matrix().data(),
                             sizeof(double) * 16));
  }
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(0, std::memcmp(a.points[i].p_w.data(), b.points[i].p_w.data(), sizeof(double) * 3));
  }
}

TEST(LocalBundleAdjustment, EmptyProblem) {
  BaProblem p;
  const BaResult r = local_bundle_adjustment(&p, testing::default_intrinsics());
  EXPECT_TRUE(r.outlier_edges.empty());
  EXPECT_EQ(r.iterations, 0);

  // Keyframes and points but no edges: nothing moves.
  auto s = make_ba_scene(3, 1, 20, 1.0, 28);
  s.problem.edges.clear();
  perturb_ba(&s.problem, 0.05, 2.0, 0.05, 29);
  const BaProblem before = s.problem;
  local_bundle_adjustment(&s.problem, testing::default_intrinsics());
  for (std::size_t k = 0; k < 3; ++k) EXPECT_TRUE(s.problem.keyframes[k].T_c_w.isApprox(before.keyframes[k].T_c_w, 0.0));
  for (std::size_t i = 0; i < 20; ++i) EXPECT_EQ(s.problem.points[i].p_w, before.points[i].p_w);
}

TEST(LocalBundleAdjustment, PointsWithoutEdgesAreUntouched) {
  auto s = make_ba_scene(4, 1, 100, 1.0, 30);
  BaPoint lonely;
  lonely.id = 7;
  lonely.p_w = Eigen::Vector3d(1.0, 2.0, 3.0);
  s.problem.points.push_back(lonely);
  perturb_ba(&s.problem, 0.02, 1.0, 0.02, 31);
  const Eigen::Vector3d lonely_before = s.problem.points.back().p_w;
  const BaResult r = local_bundle_adjustment(&s.problem, testing::default_intrinsics());
  EXPECT_EQ(s.problem.points.back().p_w, lonely_before);
  EXPECT_GT(r.iterations, 0);
}

TEST(LocalBundleAdjustment, AllKeyframesFixedOptimisesPointsOnly) {
  auto s = make_ba_scene(4, 4, 100, 0.5, 32);
  perturb_ba(&s.problem, 0.05, 2.0, 0.05, 33);  // keyframes fixed: only points move
  const BaProblem before = s.problem;
  const double median_before = median(point_errors(s.problem, s.points_gt));
  const BaResult r = local_bundle_adjustment(&s.problem, testing::default_intrinsics());
  EXPECT_GT(r.iterations, 0);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_TRUE(s.problem.keyframes[k].T_c_w.isApprox(before.keyframes[k].T_c_w, 0.0));
  }
  EXPECT_LT(median(point_errors(s.problem, s.points_gt)), median_before);
}

TEST(LocalBundleAdjustment, AbortFlagStopsEarly) {
  auto s = make_ba_scene(5, 2, 200, 1.0, 34);
  perturb_ba(&s.problem, 0.05, 2.0, 0.05, 35);
  s.problem.edges[3].obs.uv.x() += 30.0;  // an outlier a finished BA reports
  const BaProblem before = s.problem;
  BaOptions options;
  std::atomic<bool> stop{true};
  options.abort_flag = &stop;
  // Set before the call: nothing is solved, changed or reported.
  const BaResult r = local_bundle_adjustment(&s.problem, testing::default_intrinsics(), options);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_TRUE(r.stopped);
  EXPECT_TRUE(r.outlier_edges.empty());
  for (std::size_t k = 0; k < before.keyframes.size(); ++k)
    EXPECT_TRUE(s.problem.keyframes[k].T_c_w.isApprox(before.keyframes[k].T_c_w, 0.0));
  for (std::size_t p = 0; p < before.points.size(); ++p)
    EXPECT_EQ(s.problem.points[p].p_w, before.points[p].p_w);

  // Never set: both passes run and the outlier is found.
  stop = false;
  const BaResult r2 = local_bundle_adjustment(&s.problem, testing::default_intrinsics(), options);
  EXPECT_GT(r2.iterations, 0);
  EXPECT_FALSE(r2.stopped);
  EXPECT_NE(std::find(r2.outlier_edges.begin(), r2.outlier_edges.end(), 3u), r2.outlier_edges.end());
}

// The flag raised during a pass (as local mapping's worker sees it when a
// keyframe is queued): that pass ends after the iteration, the estimate
// reached so far is kept, a stop in pass 1 skips pass 2.
TEST(LocalBundleAdjustment, AbortFlagRaisedDuringAPassKeepsTheEstimateSoFar) {
  const auto scene = [] {
    auto s = make_ba_scene(5, 2, 200, 1.0, 38);
    perturb_ba(&s.problem, 0.05, 2.0, 0.05, 39);
    return s;
  };
  // Reference: no flag.  Count the iterations of each pass.
  auto full = scene();
  BaOptions count;
  int calls = 0;
  count.on_iteration = [&] { ++calls; };
  const BaResult r_full = local_bundle_adjustment(&full.problem, testing::default_intrinsics(), count);
  EXPECT_FALSE(r_full.stopped);
  ASSERT_GE(r_full.iterations, 4);
  const int total_calls = calls;  // iterations plus one start per pass

  // Raised at the third call (pass 1, after two steps).
  auto s1 = scene();
  const BaProblem before = s1.problem;
  std::atomic<bool> stop{false};
  BaOptions options;
  options.abort_flag = &stop;
  calls = 0;
  options.on_iteration = [&] {
    if (++calls == 3) stop = true;
  };
  const BaResult r1 = local_bundle_adjustment(&s1.problem, testing::default_intrinsics(), options);
  EXPECT_TRUE(r1.stopped);
  EXPECT_EQ(calls, 3);  // no further iteration, no second pass
  EXPECT_EQ(r1.iterations, 2);
  // The two steps are kept: the free keyframes moved towards the truth.
  for (std::size_t k = 2; k < 5; ++k)
    EXPECT_LT(position_error_m(s1.problem.keyframes[k].T_c_w, s1.T_c_w_gt[k]),
              position_error_m(before.keyframes[k].T_c_w, s1.T_c_w_gt[k]))
        << "keyframe " << k;

  // Raised at the last call of pass 2: reported as stopped too.
  auto s2 = scene();
  stop = false;
  calls = 0;
  options.on_iteration = [&] {
    if (++calls == total_calls) stop = true;
  };
  const BaResult r2 = local_bundle_adjustment(&s2.problem, testing::default_intrinsics(), options);
  EXPECT_TRUE(r2.stopped);
  EXPECT_EQ(r2.iterations, r_full.iterations);
}

TEST(LocalBundleAdjustment, PointBehindCameraEdgeIsOutlier) {
  auto s = make_ba_scene(4, 1, 50, 0.5, 36);
  // Edge 0's point moved behind its keyframe's camera.
  const BaEdge e0 = s.problem.edges[0];
  const geom::SE3d& T_c_w = s.problem.keyframes[e0.keyframe].T_c_w;
  s.problem.points[e0.point].p_w = T_c_w.inverse() * (-(T_c_w * s.problem.points[e0.point].p_w));
  const BaResult r = local_bundle_adjustment(&s.problem, testing::default_intrinsics());
  EXPECT_NE(std::find(r.outlier_edges.begin(), r.outlier_edges.end(), 0u), r.outlier_edges.end());
}

TEST(LocalBundleAdjustment, BadIndicesThrow) {
  auto s = make_ba_scene(3, 1, 10, 0.5, 37);
  s.problem.edges[0].point = s.problem.points.size();
  EXPECT_THROW(local_bundle_adjustment(&s.problem, testing::default_intrinsics()), std::invalid_argument);
  EXPECT_THROW(local_bundle_adjustment(nullptr, testing::default_intrinsics()), std::invalid_argument);
}

}  // namespace
}  // namespace pvb::slam
