// Map files: System::load_map (read, check, link, bags of words and the
// place database) and System::save_map (encode, atomic write) on a saved map
// (PVB_BENCH_MAP) with the settings of the run that made it
// (PVB_BENCH_SETTINGS, e.g. the run's camera.yaml).  Without them it skips.
// The file size per keyframe is reported as a counter.  Run pinned:
//   PVB_BENCH_MAP=DIR/maps/noon.pvbmap PVB_BENCH_SETTINGS=DIR/noon/camera.yaml
//   taskset -c 1 build/bin/bench_map_file --benchmark_repetitions=5
// (the two lines as one command).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"

namespace {

const char* env(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? v : nullptr;
}

std::unique_ptr<pvb::slam::System> make_system() {
  pvb::slam::SystemOptions o;
  o.synchronous = true;
  return std::make_unique<pvb::slam::System>(pvb::slam::read_settings(env("PVB_BENCH_SETTINGS")), o);
}

void BM_LoadMap(benchmark::State& state) {
  if (!env("PVB_BENCH_MAP") || !env("PVB_BENCH_SETTINGS")) {
    state.SkipWithError("set PVB_BENCH_MAP and PVB_BENCH_SETTINGS");
    return;
  }
  pvb::slam::MapLoadInfo info;
  for (auto _ : state) {
    state.PauseTiming();
    auto system = make_system();  // the vocabulary's load is not the map's
    state.ResumeTiming();
    info = system->load_map(env("PVB_BENCH_MAP"), pvb::slam::MapStart::kExtend);
    state.PauseTiming();
    system.reset();
    state.ResumeTiming();
  }
  state.counters["keyframes"] = static_cast<double>(info.keyframes);
  state.counters["MB"] = static_cast<double>(info.bytes) / 1e6;
  state.counters["kB_per_keyframe"] = static_cast<double>(info.bytes) / 1e3 / static_cast<double>(info.keyframes);
}

void BM_SaveMap(benchmark::State& state) {
  if (!env("PVB_BENCH_MAP") || !env("PVB_BENCH_SETTINGS")) {
    state.SkipWithError("set PVB_BENCH_MAP and PVB_BENCH_SETTINGS");
    return;
  }
  auto system = make_system();
  system->load_map(env("PVB_BENCH_MAP"), pvb::slam::MapStart::kExtend);
  system->shutdown();
  const std::string out = std::string(env("PVB_BENCH_MAP")) + ".bench_copy";
  for (auto _ : state) benchmark::DoNotOptimize(system->save_map(out, "{}"));
  std::remove(out.c_str());
}

BENCHMARK(BM_LoadMap)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_SaveMap)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
