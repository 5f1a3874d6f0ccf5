// Dense mapping cost per keyframe at 640x480: back-projection (stride 3,
// the default, and 1) plus the keyframe voxel filter, and the global
// rebuild (transform + voxel filter) for a map of N keyframes.  The scene
// is a tilted plane with a ripple (an analytic surface),
// so every pixel has depth in [1, 4] m: the worst case for the filter.
#include <benchmark/benchmark.h>

#include <cmath>

#include "pvb/slam/dense/dense_mapper.hpp"

namespace {

namespace dn = pvb::slam::dense;

struct Images {
  cv::Mat rgb, depth_m;
};

Images make_images() {
  Images im{cv::Mat(480, 640, CV_8UC3), cv::Mat(480, 640, CV_32FC1)};
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) {
      im.depth_m.at<float>(v, u) = static_cast<float>(1.0 + 3.0 * v / 480.0 + 0.05 * std::sin(0.1 * u));
      im.rgb.at<cv::Vec3b>(v, u) =
          cv::Vec3b(static_cast<unsigned char>(u), static_cast<unsigned char>(v), 90);
    }
  return im;
}

void BM_KeyframeCloud(benchmark::State& state) {
  const Images im = make_images();
  const pvb::geom::PinholeIntrinsics K;  // 525, 640x480
  dn::BackProjectionParams p;
  p.stride_px = static_cast<int>(state.range(0));
  std::size_t points = 0;
  for (auto _ : state) {
    const dn::PointCloud c = dn::voxel_filter(dn::back_project(im.rgb, im.depth_m, K, p), 0.02);
    points = c.size();
    benchmark::DoNotOptimize(c.data());
  }
  state.counters["points"] = static_cast<double>(points);
}
BENCHMARK(BM_KeyframeCloud)->Arg(3)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_GlobalRebuild(benchmark::State& state) {
  const Images im = make_images();
  dn::DenseMapperOptions o;
  dn::DenseMapper mapper(o);
  const int n = static_cast<int>(state.range(0));
  for (int i = 0; i < n; ++i)
    mapper.insert({static_cast<std::uint64_t>(i), i, im.rgb, im.depth_m,
                   pvb::geom::make_se3(pvb::geom::Mat3d::Identity(), Eigen::Vector3d(0.1 * i, 0, 0))});
  std::size_t points = 0;
  for (auto _ : state) {
    const dn::PointCloud c = mapper.global_cloud();
    points = c.size();
    benchmark::DoNotOptimize(c.data());
  }
  state.counters["points"] = static_cast<double>(points);
}
BENCHMARK(BM_GlobalRebuild)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);

/// A loop correction: n keyframes in the map, every one moved by 1 cm and
/// re-binned (update_poses), as after the loop scenario's correction.
/// Second argument: the mapper's memory budget, MB (0: none); a budget
/// below the map's size makes every update read spilled clouds and blocks
/// back and spill others.
void BM_LoopUpdate(benchmark::State& state) {
  const Images im = make_images();
  dn::DenseMapperOptions o;
  o.memory_budget_bytes = static_cast<std::size_t>(state.range(1)) << 20;
  dn::DenseMapper mapper(o);
  const int n = static_cast<int>(state.range(0));
  dn::PoseUpdate a, b;
  for (int i = 0; i < n; ++i) {
    const auto T = pvb::geom::make_se3(pvb::geom::Mat3d::Identity(), Eigen::Vector3d(0.05 * i, 0.01 * (i % 7), 0));
    mapper.insert({static_cast<std::uint64_t>(i), i, im.rgb, im.depth_m, T});
    a.T_w_c_by_id[i] = T;
    b.T_w_c_by_id[i] = pvb::geom::make_se3(pvb::geom::Mat3d::Identity(), Eigen::Vector3d(0, 0, 0.01)) * T;
  }
  bool flip = false;
  for (auto _ : state) {
    mapper.update_poses(flip ? a : b);
    flip = !flip;
  }
  state.counters["points_per_keyframe"] =
      static_cast<double>(mapper.stats().points) / static_cast<double>(mapper.stats().keyframes);
  state.counters["keyframes_moved_per_update"] =
      static_cast<double>(mapper.stats().keyframes_moved) / static_cast<double>(mapper.stats().pose_updates);
  state.counters["memory_mb"] = static_cast<double>(mapper.memory().total()) / (1 << 20);
  state.counters["spilled_mb"] =
      static_cast<double>(mapper.memory().spilled_keyframe_bytes + mapper.memory().spilled_map_bytes) / (1 << 20);
}
BENCHMARK(BM_LoopUpdate)->Args({250, 0})->Args({250, 32})->Args({250, 64})->Args({250, 128})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
