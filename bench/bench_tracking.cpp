// Tracking cost per frame at 640x480 with 1000 ORB features (target:
// median tracking <= 20 ms on one core, PE-match adding <= 10 %).
//
// Runs on a recorded TUM folder (`pvbench record`), named by the
// environment variable PVB_BENCH_SEQUENCE (its camera.yaml is the
// settings).  PVB_BENCH_FRAMES (default 300) frames are tracked per run.
//
//   BM_OrbExtract        ORB extraction of one frame (grey image in memory), CPU time
//   BM_TrackFrame/pe:1   System::track in sync mode with PE-match, one iteration per frame;
//   BM_TrackFrame/pe:0   the same without PE-match (the ORB-SLAM2 baseline)
//
// BM_TrackFrame reports the system's own tracking_ms (extraction +
// tracking, FrameResult) as manual time: frame loading and the inline
// local mapping that sync mode runs after a keyframe are not counted.  The
// counters give the median and the ORB part, which the mean hides, and
// cpu_median_ms: the calling thread's CPU time in System::track over the
// frames that made no keyframe (so without inline mapping), which other
// processes on the same core do not inflate as they do wall time.
// Pin to one core, as docs/slam.md, "Speed" does: `taskset -c 1 build/bin/bench_tracking`.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"
#include "pvb/slam/features/orb_extractor.hpp"

namespace {

std::string sequence_dir() {
  const char* s = std::getenv("PVB_BENCH_SEQUENCE");
  return s ? std::string(s) : std::string();
}

std::size_t frames_per_run() {
  const char* s = std::getenv("PVB_BENCH_FRAMES");
  const long n = s ? std::atol(s) : 300;
  return static_cast<std::size_t>(std::max(10L, n));
}

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(mid), v.end());
  return v[mid];
}

void BM_OrbExtract(benchmark::State& state, const std::string& dir) {
  const pvb::slam::Settings settings = pvb::slam::read_settings(dir + "/camera.yaml");
  const pvb::dataset::TumSequenceReader reader(dir, settings.depth_map_factor);
  const std::size_t i = std::min<std::size_t>(100, reader.size_hint() - 1);
  cv::Mat grey;
  cv::cvtColor(reader.load(i).rgb, grey, cv::COLOR_RGB2GRAY);
  pvb::slam::OrbExtractor extractor(settings.orb);
  std::size_t n = 0;
  for (auto _ : state) {
    const pvb::slam::OrbFeatures f = extractor.extract(grey);
    n = f.keypoints.size();
    benchmark::DoNotOptimize(f.descriptors.data);
  }
  state.counters["features"] = static_cast<double>(n);
}

void BM_TrackFrame(benchmark::State& state, const std::string& dir) {
  pvb::slam::Settings settings = pvb::slam::read_settings(dir + "/camera.yaml");
  settings.pe_match.enabled = state.range(0) != 0;
  settings.dense.enabled = false;
  const pvb::dataset::TumSequenceReader reader(dir, settings.depth_map_factor);
  const std::size_t frames = std::min(frames_per_run(), reader.size_hint());
  pvb::slam::SystemOptions options;
  options.synchronous = true;
  std::unique_ptr<pvb::slam::System> system;
  std::size_t next = 0;
  std::vector<double> tracking_ms, orb_ms, pe_ms, cpu_ms, align_ms;
  double tried = 0, aligned = 0;
  int lost = 0;
  for (auto _ : state) {
    if (!system || next == frames) {
      system = std::make_unique<pvb::slam::System>(settings, options);
      next = 0;
    }
    const pvb::sensor::RgbdFrame frame = reader.load(next++);
    const double cpu0_ms = thread_cpu_ms();
    const pvb::slam::FrameResult r = system->track(frame);
    if (!r.tracking.new_keyframe) cpu_ms.push_back(thread_cpu_ms() - cpu0_ms);
    state.SetIterationTime(r.tracking_ms / 1e3);
    tracking_ms.push_back(r.tracking_ms);
    orb_ms.push_back(r.orb_ms);
    if (r.tracking.method == pvb::slam::TrackingMethod::kMotionModel) pe_ms.push_back(r.tracking.pe_match_ms);
    lost += r.state == pvb::slam::TrackingState::kLost;
    align_ms.push_back(r.tracking.align_ms);
    tried += r.tracking.align_tried;
    aligned += r.tracking.aligned;
  }
  state.counters["median_ms"] = median(tracking_ms);
  state.counters["cpu_median_ms"] = median(cpu_ms);
  state.counters["orb_median_ms"] = median(orb_ms);
  state.counters["pe_median_ms"] = median(pe_ms);
  state.counters["align_median_ms"] = median(align_ms);
  state.counters["aligned_share"] = tried > 0 ? aligned / tried : 0.0;
  state.counters["lost"] = lost;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  const std::string dir = sequence_dir();
  if (dir.empty()) {
    std::fprintf(stderr,
                 "bench_tracking: set PVB_BENCH_SEQUENCE to a recorded TUM folder, e.g.\n"
                 "  build/bin/pvbench record --scenario scenes/pv_station.yaml --out /tmp/seq_pv\n"
                 "  PVB_BENCH_SEQUENCE=/tmp/seq_pv taskset -c 1 build/bin/bench_tracking\n");
    return 1;
  }
  const auto frames = static_cast<benchmark::IterationCount>(frames_per_run());
  benchmark::RegisterBenchmark("BM_OrbExtract", BM_OrbExtract, dir)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("BM_TrackFrame", BM_TrackFrame, dir)
      ->ArgName("pe")
      ->Arg(1)
      ->Arg(0)
      ->UseManualTime()
      ->Iterations(frames)
      ->Unit(benchmark::kMillisecond);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
