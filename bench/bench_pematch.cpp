// PE-match time per call on synthetic two-view data with 50 % outliers
// (target: <= 1 ms at 500 coarse matches on one core).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>
#include <vector>

#include "pvb/slam/pematch/pe_match.hpp"

namespace {

std::vector<pvb::slam::PointMatch> make_matches(int n, double outlier_ratio, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(0, 640), uy(0, 480), uz(2.0, 8.0), u01(0, 1);
  std::normal_distribution<double> noise(0.0, 0.5);
  Eigen::Matrix3d K;
  K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d t(0.4, 0.05, 0.1);
  std::vector<pvb::slam::PointMatch> m;
  while (static_cast<int>(m.size()) < n) {
    const Eigen::Vector2d u1(ux(rng), uy(rng));
    const Eigen::Vector3d P2 = R * (uz(rng) * (K.inverse() * u1.homogeneous())) + t;
    Eigen::Vector2d u2 = (K * P2).hnormalized();
    if (P2.z() <= 0 || u2.x() < 0 || u2.x() >= 640 || u2.y() < 0 || u2.y() >= 480) continue;
    if (u01(rng) < outlier_ratio) u2 = {ux(rng), uy(rng)};
    m.push_back({u1 + Eigen::Vector2d(noise(rng), noise(rng)), u2 + Eigen::Vector2d(noise(rng), noise(rng))});
  }
  return m;
}

void run(benchmark::State& state, pvb::slam::PeMatchParams params) {
  const auto m = make_matches(static_cast<int>(state.range(0)), 0.5, 11);
  pvb::slam::PeMatcher pm(params);
  pvb::slam::PeMatchResult r;
  unsigned seed = 1;
  double iters = 0, evals = 0, calls = 0, inliers = 0, min_inliers = 1e9;
  for (auto _ : state) {
    pm.params().seed = seed++;
    pm.match(m.data(), m.size(), r);
    benchmark::DoNotOptimize(r.num_inliers);
    iters += r.iterations;
    evals += r.evaluations;
    calls += 1;
    inliers += r.num_inliers;
    min_inliers = std::min<double>(min_inliers, r.num_inliers);
  }
  state.counters["iterations"] = iters / calls;
  state.counters["evaluations"] = evals / calls;
  state.counters["inliers_mean"] = inliers / calls;
  state.counters["inliers_min"] = min_inliers;
}

void BM_PeMatchPairs(benchmark::State& state) { run(state, pvb::slam::PeMatchParams::for_pairs()); }
void BM_PeMatchSlam(benchmark::State& state) { run(state, pvb::slam::PeMatchParams::for_slam()); }
void BM_PeMatchPairsRefined(benchmark::State& state) {
  auto p = pvb::slam::PeMatchParams::for_pairs();
  p.refine = true;
  run(state, p);
}

}  // namespace

BENCHMARK(BM_PeMatchPairs)->Arg(200)->Arg(500)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PeMatchSlam)->Arg(200)->Arg(500)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PeMatchPairsRefined)->Arg(200)->Arg(500)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
