// Render + readback speed of the default station (or another scenario) at
// 640x480, per backend.
// One process loads one GL backend, so choose it on the command line:
//   bench_render --gl=egl      (or --gl=osmesa, --gl=auto; default auto)
//   bench_render --scenario=scenes/rough_station.yaml   (default: the station)
// Benchmarks: render+readback with and without shadows, the full capture
// (render, sky mask, Kinect depth model, RGB noise), one physics frame and
// one soil image.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cstring>
#include <memory>
#include <string>

#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/sim/textures.hpp"

namespace {

std::string g_backend = "auto";
std::string g_scenario = PVB_SOURCE_DIR "/scenes/pv_station.yaml";

// CPU time of the whole process (all llvmpipe threads), ms: less sensitive
// than wall time to other load on a small machine.
double process_cpu_ms() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return (u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-3;
}

struct World {
  std::unique_ptr<pvb::sim::Simulator> sim;
  std::unique_ptr<pvb::sim::Renderer> renderer;
  std::unique_ptr<pvb::sim::RgbdCamera> camera;
};

World& world() {
  static World w = [] {
    World x;
    auto s = pvb::scenes::load_scenario(g_scenario);
    x.sim = std::make_unique<pvb::sim::Simulator>(s);
    x.camera = std::make_unique<pvb::sim::RgbdCamera>(*x.sim, pvb::sim::parse_gl_backend(g_backend));
    x.renderer = std::make_unique<pvb::sim::Renderer>(x.sim->model(), pvb::sim::parse_gl_backend(g_backend), 640, 480);
    for (int i = 0; i < 60; ++i) x.sim->advance();  // somewhere along the lane
    return x;
  }();
  return w;
}

void BM_RenderReadback(benchmark::State& state) {
  World& w = world();
  w.renderer->set_shadows(state.range(0) != 0);
  cv::Mat rgb, depth;
  const double cpu0 = process_cpu_ms();
  for (auto _ : state) {
    w.renderer->render(w.sim->model(), w.sim->data(), w.sim->camera_id(), &rgb, &depth);
    benchmark::DoNotOptimize(rgb.data);
  }
  state.counters["process_cpu_ms/frame"] = (process_cpu_ms() - cpu0) / static_cast<double>(state.iterations());
  state.SetLabel(w.renderer->description() + (state.range(0) ? ", shadows" : ", no shadows"));
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderReadback)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Capture(benchmark::State& state) {
  World& w = world();
  const double cpu0 = process_cpu_ms();
  for (auto _ : state) {
    pvb::sim::Capture c = w.camera->capture(*w.sim);
    benchmark::DoNotOptimize(c.frame.rgb.data);
  }
  state.counters["process_cpu_ms/frame"] = (process_cpu_ms() - cpu0) / static_cast<double>(state.iterations());
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Capture)->Unit(benchmark::kMillisecond)->UseRealTime();

// The sensor-model stage alone (Kinect depth model and RGB noise) on one
// rendered frame: what the run's sensor thread does per frame.
void BM_SensorModel(benchmark::State& state) {
  World& w = world();
  const pvb::sim::RenderedFrame rendered = w.camera->render(*w.sim);
  const double cpu0 = process_cpu_ms();
  for (auto _ : state) {
    pvb::sim::RenderedFrame copy = rendered;
    copy.rgb = rendered.rgb.clone();
    pvb::sim::Capture c = w.camera->sensor_model().apply(std::move(copy));
    benchmark::DoNotOptimize(c.frame.depth_m.data);
  }
  state.counters["process_cpu_ms/frame"] = (process_cpu_ms() - cpu0) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_SensorModel)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PhysicsFrame(benchmark::State& state) {
  World& w = world();
  for (auto _ : state) w.sim->advance();
}
BENCHMARK(BM_PhysicsFrame)->Unit(benchmark::kMillisecond);

// One soil image drawn from its seed: what a ground tile near the camera
// costs when the camera comes near it (GroundStream).
void BM_GroundTexture(benchmark::State& state) {
  std::uint64_t seed = 1;
  for (auto _ : state) benchmark::DoNotOptimize(pvb::sim::make_ground_texture(pvb::scenes::GroundType::kSoil, ++seed));
}
BENCHMARK(BM_GroundTexture)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], "--gl=", 5) == 0)
      g_backend = argv[i] + 5;
    else if (std::strncmp(argv[i], "--scenario=", 11) == 0)
      g_scenario = argv[i] + 11;
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
