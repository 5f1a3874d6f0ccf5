// Pose-only optimisation and local bundle adjustment times on synthetic
// problems (pvb/slam/optim/synthetic.hpp).  Tracking runs optimize_pose
// several times per frame, so it must stay at a few ms.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "pvb/slam/optim/optimizer.hpp"
#include "pvb/slam/optim/synthetic.hpp"

namespace {

namespace st = pvb::slam::testing;

// RGB-D tracking: stereo observations, 1 px noise, 10 % gross outliers,
// initial pose 5 cm / 2 deg off (a constant-velocity guess).
void optimize_pose_bench(benchmark::State& state, const pvb::slam::PoseOptimizerOptions& options) {
  const auto s = st::make_pose_scene(static_cast<int>(state.range(0)), 1.0, true, 0.10, 41);
  std::mt19937 rng(42);
  const auto T_init = st::perturb(s.T_c_w_gt, 0.05, 2.0, rng);
  const auto K = st::default_intrinsics();
  double inliers = 0, calls = 0, err_cm = 0;
  for (auto _ : state) {
    const auto r = pvb::slam::optimize_pose(T_init, s.points_w, s.obs, K, options);
    benchmark::DoNotOptimize(r.num_inliers);
    inliers += r.num_inliers;
    calls += 1;
    err_cm = 100.0 * st::position_error_m(r.T_c_w, s.T_c_w_gt);
  }
  state.counters["inliers"] = inliers / calls;
  state.counters["err_cm"] = err_cm;
}
void BM_OptimizePose(benchmark::State& state) { optimize_pose_bench(state, {}); }
BENCHMARK(BM_OptimizePose)->Arg(300)->Arg(1000)->Unit(benchmark::kMillisecond);

// Same, but each round continues from the previous round's pose instead of
// restarting from the initial guess as ORB-SLAM2 does.
void BM_OptimizePoseContinue(benchmark::State& state) {
  pvb::slam::PoseOptimizerOptions options;
  options.restart_from_initial = false;
  optimize_pose_bench(state, options);
}
BENCHMARK(BM_OptimizePoseContinue)->Arg(300)->Arg(1000)->Unit(benchmark::kMillisecond);

// Local mapping: keyframes (2 fixed), points seen by >= 2 of them, poses
// 5 cm / 2 deg and points 5 cm off, default iterations (5 + 10).
void BM_LocalBundleAdjustment(benchmark::State& state) {
  auto s = st::make_ba_scene(static_cast<int>(state.range(0)), 2, static_cast<int>(state.range(1)), 1.0, 43);
  st::perturb_ba(&s.problem, 0.05, 2.0, 0.05, 44);
  const auto K = st::default_intrinsics();
  double iterations = 0, calls = 0, outliers = 0;
  for (auto _ : state) {
    state.PauseTiming();
    pvb::slam::BaProblem p = s.problem;
    state.ResumeTiming();
    const auto r = pvb::slam::local_bundle_adjustment(&p, K);
    benchmark::DoNotOptimize(r.iterations);
    iterations += r.iterations;
    outliers += static_cast<double>(r.outlier_edges.size());
    calls += 1;
  }
  state.counters["edges"] = static_cast<double>(s.problem.edges.size());
  state.counters["iterations"] = iterations / calls;
  state.counters["outliers"] = outliers / calls;
}
BENCHMARK(BM_LocalBundleAdjustment)->Args({10, 2000})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
