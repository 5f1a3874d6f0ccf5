// Memory per keyframe of a SLAM run on a recorded sequence.
//
// Runs on a recorded TUM folder (`pvbench record`), named by the
// environment variable PVB_BENCH_SEQUENCE (its camera.yaml is the
// settings); PVB_BENCH_FRAMES limits the frames (default: all).  One
// iteration is one System run in sync mode over the frames:
//
//   BM_KeyframeMemory/dense:0   sparse SLAM only
//   BM_KeyframeMemory/dense:1   with the dense point-cloud mapper
//
// Counters (MB = 1e6 bytes; "per keyframe": divided by the keyframes in
// the map at the end, as KeyFrameTrajectory.txt counts them):
//   keyframes, culled_keyframes   keyframes in the map; culled ones kept for the trajectory
//   kf_MB                         keyframe data per keyframe (System::memory(), by structure below)
//   outside_keyframes, kf_outside_MB  keyframes outside the local map (pyramid released) and
//                                 their data per keyframe: what an hour of driving adds
//   kf_pyramid_MB, kf_features_MB (keypoints, descriptors, per-keypoint arrays),
//   kf_grid_MB, kf_bow_MB, kf_other_MB (graph, objects)
//   culled_MB                     what the culled keyframes hold, per map keyframe
//   points_MB                     map points per keyframe
//   place_db_MB                   the place-recognition database (bags of words) per keyframe
//   dense_kf_MB                   the dense mapper's per-keyframe clouds, per keyframe
//   dense_map_MB                  its two voxel maps (grow with the area, not per keyframe)
//   rss_MB                        growth of the resident set (after malloc_trim) from the
//                                 first frame to the end, per keyframe: what the accounting
//                                 above should add up to
#include <benchmark/benchmark.h>
#include <malloc.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "pvb/common/memory.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"

namespace {

std::string sequence_dir() {
  const char* s = std::getenv("PVB_BENCH_SEQUENCE");
  return s ? std::string(s) : std::string();
}

std::size_t frames_limit(std::size_t available) {
  const char* s = std::getenv("PVB_BENCH_FRAMES");
  const long n = s ? std::atol(s) : 0;
  return n > 0 ? std::min(available, static_cast<std::size_t>(n)) : available;
}

/// The resident set with freed heap memory handed back first, so that it
/// counts what is live.
double live_rss_mb() {
  malloc_trim(0);
  return static_cast<double>(pvb::resident_bytes()) / 1e6;
}

constexpr double kMB = 1e6;

void report(benchmark::State& state, const pvb::slam::SystemMemory& m, double rss_growth_mb) {
  const double n = std::max<double>(1.0, static_cast<double>(m.map.keyframes));
  const pvb::slam::KeyFrameMemory& k = m.map.keyframe_bytes;
  const pvb::slam::FrameMemory& f = k.frame;
  state.counters["keyframes"] = static_cast<double>(m.map.keyframes);
  state.counters["culled_keyframes"] = static_cast<double>(m.culled_keyframes);
  state.counters["kf_MB"] = static_cast<double>(k.total()) / kMB / n;
  state.counters["kf_pyramid_MB"] = static_cast<double>(f.pyramid) / kMB / n;
  state.counters["kf_features_MB"] = static_cast<double>(f.keypoints + f.descriptors + f.per_keypoint) / kMB / n;
  state.counters["kf_grid_MB"] = static_cast<double>(f.grid) / kMB / n;
  state.counters["kf_bow_MB"] = static_cast<double>(k.bow) / kMB / n;
  state.counters["kf_other_MB"] = static_cast<double>(k.graph + k.object + f.object) / kMB / n;
  const double outside = std::max<double>(1.0, static_cast<double>(m.map.keyframes_outside));
  state.counters["outside_keyframes"] = static_cast<double>(m.map.keyframes_outside);
  state.counters["kf_outside_MB"] = static_cast<double>(m.map.outside_bytes.total()) / kMB / outside;
  state.counters["culled_MB"] = static_cast<double>(m.culled_bytes.total()) / kMB / n;
  state.counters["points_MB"] = static_cast<double>(m.map.point_bytes) / kMB / n;
  state.counters["place_db_MB"] = static_cast<double>(m.place_database_bytes) / kMB / n;
  state.counters["dense_kf_MB"] = static_cast<double>(m.dense.keyframe_bytes) / kMB / n;
  state.counters["dense_map_MB"] = static_cast<double>(m.dense.map_bytes) / kMB;
  state.counters["rss_MB"] = rss_growth_mb / n;
}

void BM_KeyframeMemory(benchmark::State& state, const std::string& dir) {
  pvb::slam::Settings settings = pvb::slam::read_settings(dir + "/camera.yaml");
  settings.dense.enabled = state.range(0) != 0;
  const pvb::dataset::TumSequenceReader reader(dir, settings.depth_map_factor);
  const std::size_t frames = frames_limit(reader.size_hint());
  pvb::slam::SystemOptions options;
  options.synchronous = true;
  for (auto _ : state) {
    pvb::slam::System system(settings, options);
    system.track(reader.load(0));
    const double rss0_mb = live_rss_mb();
    for (std::size_t i = 1; i < frames; ++i) system.track(reader.load(i));
    system.shutdown();
    const double rss1_mb = live_rss_mb();
    report(state, system.memory(), rss1_mb - rss0_mb);
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  const std::string dir = sequence_dir();
  if (dir.empty()) {
    std::fprintf(stderr,
                 "bench_memory: set PVB_BENCH_SEQUENCE to a recorded TUM folder, e.g.\n"
                 "  build/bin/pvbench record --scenario scenes/lawnmower.yaml --frames 1500 --out /tmp/seq_lawn\n"
                 "  PVB_BENCH_SEQUENCE=/tmp/seq_lawn build/bin/bench_memory\n");
    return 1;
  }
  benchmark::RegisterBenchmark("BM_KeyframeMemory", BM_KeyframeMemory, dir)
      ->ArgName("dense")
      ->Arg(0)
      ->Arg(1)
      ->Iterations(1)
      ->Unit(benchmark::kSecond);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
