// pvbench record: render a scenario into a TUM RGB-D sequence folder.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>

#include "command.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/progress.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/plot/contact_sheet.hpp"
#include "pvb/run/run.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/sim_frame_source.hpp"

namespace pvb::cli {
namespace {

struct RecordOptions {
  std::string scenario;
  std::string out;
  int frames = 0;
  std::optional<std::uint64_t> seed;
  std::string gl = "auto";
};

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

int run_record(const RecordOptions& opt) {
  const sim::GlBackend backend = sim::parse_gl_backend(opt.gl);
  scenes::Scenario scenario = scenes::load_scenario(opt.scenario);
  if (opt.seed) scenario.seed = *opt.seed;
  dataset::make_dirs(opt.out);  // fail early on an unwritable folder

  const auto t_start = Clock::now();
  const int n = scenes::frame_count(scenario, opt.frames);
  geom::StampedPose gt;  // ground truth arrives through its own sink
  sim::SimFrameSource source(scenario, backend, n, [&gt](const geom::StampedPose& p) { gt = p; });
  const double setup_ms = ms_since(t_start);
  const sim::Simulator& sim = source.simulator();

  sim::write_scene(sim.assets(), opt.out);
  dataset::write_orbslam_settings(opt.out + "/camera.yaml", run::orbslam_settings_for(scenario));
  dataset::TumSequenceWriter writer(opt.out, sensor::kTumDepthFactor, std::string("pvbench ") + pvb::version());

  double capture_ms = 0, write_ms = 0;
  const std::vector<int> sheet_frames = plot::spread_indices(n, 12);
  std::vector<plot::Thumbnail> thumbs;
  const auto t_loop = Clock::now();
  {
    ProgressBar bar("record " + scenario.name, static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      auto t0 = Clock::now();
      const std::optional<sensor::RgbdFrame> frame = source.next();
      capture_ms += ms_since(t0);
      if (!frame) break;
      t0 = Clock::now();
      writer.write(*frame, gt.T_w_c);
      write_ms += ms_since(t0);
      if (std::find(sheet_frames.begin(), sheet_frames.end(), i) != sheet_frames.end()) {
        char label[64];
        std::snprintf(label, sizeof label, "frame %d  t=%.2f s", i, geom::ns_to_seconds(frame->t_ns));
        thumbs.push_back({frame->rgb.clone(), label});
      }
      bar.update(static_cast<std::size_t>(i + 1));
    }
  }
  const double loop_s = ms_since(t_loop) / 1000.0;
  const double total_s = ms_since(t_start) / 1000.0;

  char meta[4096];
  std::snprintf(meta, sizeof meta,
                "{\n"
                "  \"scenario\": {\"name\": \"%s\", \"file\": \"%s\"},\n"
                "  \"seed\": %llu,\n"
                "  \"frames\": %d,\n"
                "  \"fps\": %.6g,\n"
                "  \"versions\": {\"pvbench\": \"%s\", \"mujoco\": \"%s\"},\n"
                "  \"renderer\": {\"backend\": \"%s\", \"description\": \"%s\"},\n"
                "  \"physics\": {\"timestep_s\": %.9g, \"substeps_per_frame\": %d},\n"
                "  \"kinematics\": {\"wheel_radius_m\": %.6f, \"track_m\": %.6f},\n"
                "  \"timings\": {\"total_s\": %.3f, \"setup_ms\": %.1f, \"capture_ms_per_frame\": %.3f, "
                "\"write_ms_per_frame\": %.3f, \"frames_per_s\": %.2f}\n"
                "}\n",
                json_escape(scenario.name).c_str(), json_escape(opt.scenario).c_str(),
                static_cast<unsigned long long>(scenario.seed), n, scenario.camera.fps, pvb::version(),
                mj_versionString(), sim::to_string(source.camera().backend()),
                json_escape(source.camera().description()).c_str(),
                sim.assets().timestep_s, sim.assets().substeps, sim.kinematics().wheel_radius_m,
                sim.kinematics().track_m, total_s, setup_ms, capture_ms / n, write_ms / n, n / loop_s);
  write_file(opt.out + "/meta.json", meta);
  plot::write_rgb_png(plot::make_contact_sheet(thumbs, 4, 320), opt.out + "/contact_sheet.png");
  std::printf("recorded %d frames of %s to %s (%s; %.1f frames/s, capture %.1f ms/frame)\n", n,
              scenario.name.c_str(), opt.out.c_str(), source.camera().description().c_str(), n / loop_s,
              capture_ms / n);
  return 0;
}

}  // namespace

Command add_record_command(CLI::App& app) {
  auto opt = std::make_shared<RecordOptions>();
  CLI::App* sub = app.add_subcommand("record", "Render a scenario into a TUM RGB-D sequence folder");
  sub->add_option("--scenario", opt->scenario, "scenario YAML file")->required();
  sub->add_option("--out", opt->out, "output folder (created)")->required();
  sub->add_option("--frames", opt->frames, "record at most N frames (default: the scenario's duration)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--seed", opt->seed, "override the scenario's seed");
  sub->add_option("--gl", opt->gl, "rendering backend")->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  return {sub, [opt] { return run_record(*opt); }};
}

}  // namespace pvb::cli
