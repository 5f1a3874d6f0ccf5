// Not a benchmark: the simulator's capture speed along a scenario's route,
// as `pvbench record` measures it but writing nothing, so that it runs on a
// machine with the simulator's libraries alone (no image codecs), a GPU
// machine for example:
//   capture_scenario --scenario scenes/pv_station.yaml --frames 300 --gl egl
// prints the set-up time, the capture time a frame (physics, render,
// sensor model), each stage's median and the process CPU a frame.
// --model, --sunlight and --glass override the scenario's camera and
// modules, as the depth tables do.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/sim_frame_source.hpp"

namespace {

struct Options {
  std::string scenario, model, sunlight, glass, gl = "auto";
  int frames = 300;
  int skip = 0;
};

/// The process's CPU time, all threads (std::clock on Linux).
double process_cpu_ms() { return 1e3 * static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

pvb::scenes::Scenario scenario_of(const Options& o) {
  pvb::scenes::Scenario s = pvb::scenes::load_scenario(o.scenario);
  if (o.model == "d435") {
    s.camera.model = pvb::scenes::CameraKind::kD435;
    s.camera.use_d435_colour_camera();
  }
  if (o.model == "kinect") s.camera.model = pvb::scenes::CameraKind::kKinect;
  if (!o.sunlight.empty()) s.camera.depth_noise.sunlight.on = o.sunlight == "on";
  if (!o.glass.empty())
    for (pvb::scenes::PvArray& a : s.pv_arrays) a.specular_glass = o.glass == "specular";
  return s;
}

int run(const Options& o) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  pvb::sim::SimFrameSource source(scenario_of(o), pvb::sim::parse_gl_backend(o.gl), o.skip + o.frames);
  const double setup_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  for (int i = 0; i < o.skip; ++i) source.skip();
  std::vector<double> physics, render, sensor, stereo;
  const double cpu0 = process_cpu_ms();
  const auto t1 = Clock::now();
  int frames = 0;
  while (source.next()) {
    const pvb::sim::SimFrameSource::StageTimes& t = source.last_stage_times();
    physics.push_back(t.physics_ms);
    render.push_back(t.render_ms);
    sensor.push_back(t.sensor_ms);
    stereo.push_back(t.stereo_match_ms);
    ++frames;
  }
  if (frames == 0) throw pvb::Error(o.scenario + ": the route ended before the first timed frame");
  const double wall_ms = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
  const double cpu_ms = process_cpu_ms() - cpu0;
  std::printf("%s\n", source.describe().c_str());
  std::printf("set-up %.0f ms; %d frames after %d skipped: capture %.2f ms a frame (%.1f frames/s), process CPU "
              "%.2f ms a frame; medians: physics %.2f ms, render %.2f ms, sensor model %.2f ms (stereo %.2f ms)\n",
              setup_ms, frames, o.skip, wall_ms / frames, 1e3 * frames / wall_ms, cpu_ms / frames, median(physics),
              median(render), median(sensor), median(stereo));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"capture_scenario: the simulator's capture speed along a scenario's route"};
  app.add_option("--scenario", o.scenario, "scenario YAML")->required();
  app.add_option("--frames", o.frames, "timed frames")->check(CLI::PositiveNumber);
  app.add_option("--skip", o.skip, "frames driven without rendering first")->check(CLI::NonNegativeNumber);
  app.add_option("--gl", o.gl, "egl, osmesa or auto");
  app.add_option("--model", o.model, "kinect or d435 (default: the scenario's)")->check(CLI::IsMember({"kinect", "d435"}));
  app.add_option("--sunlight", o.sunlight, "on or off: the Kinect model's sunlight")->check(CLI::IsMember({"on", "off"}));
  app.add_option("--glass", o.glass, "diffuse or specular: every array's glass")->check(CLI::IsMember({"diffuse", "specular"}));
  CLI11_PARSE(app, argc, argv);
  try {
    return run(o);
  } catch (const pvb::Error& e) {
    std::cerr << "capture_scenario: error: " << e.what() << "\n";
    return 1;
  }
}
