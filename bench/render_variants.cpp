// Not a benchmark with a verdict: the price and the picture of render
// settings.  Renders frames along the default station's drive with a
// reference setting and with each variant, and prints per variant the
// process CPU per render (llvmpipe's threads included; per frame the least
// of 4 renders, since other load on a shared machine only adds) and how far
// its colour and depth images are from the reference's.
//
//   render_variants [--gl=egl] [--step=N] [--out=DIR] VARIANT...
//   VARIANT = SHADOW_MAP_PX[:SLICES:STACKS:QUADS]
//
// The first variant is the reference.  SLICES/STACKS/QUADS override the
// scene's vis.quality tessellation of MuJoCo's builtin shapes (default: the
// generated scene's).  Depth is compared with the sky masked (0), as
// RgbdCamera delivers it.  With --out, a few frames are written as
// reference | variant | |difference| x 4.  Example (docs/run.md):
//   render_variants --gl=egl 1024 1024:28:16:1 512:28:16:1 512:16:8:1
#include <mujoco/mujoco.h>
#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/simulator.hpp"

namespace {

double process_cpu_ms() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return (u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-3;
}

struct Variant {
  int shadow_map_px = 1024;
  int slices = 0, stacks = 0, quads = 0;  ///< 0: the generated scene's
  std::string label() const {
    std::string l = std::to_string(shadow_map_px) + " px shadow map";
    if (slices > 0)
      l += ", tessellation " + std::to_string(slices) + "/" + std::to_string(stacks) + "/" +
           std::to_string(quads);
    return l;
  }
};

struct Result {
  double cpu_ms = 0;
  int renders = 0;
  double mean_abs_sum = 0;       ///< mean |colour difference| (0..255), summed over frames
  double changed_sum = 0;        ///< share of pixels with a channel off by more than 16
  double depth_changed_sum = 0;  ///< share of pixels whose depth is off by more than 1 mm
};

}  // namespace

int main(int argc, char** argv) {
  std::string backend = "auto", out_dir;
  int step = 25;
  std::vector<Variant> variants;
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--gl=", 5) == 0) {
      backend = argv[i] + 5;
    } else if (std::strncmp(argv[i], "--out=", 6) == 0) {
      out_dir = argv[i] + 6;
    } else if (std::strncmp(argv[i], "--step=", 7) == 0) {
      step = std::max(1, std::atoi(argv[i] + 7));
    } else {
      Variant v;
      const int got = std::sscanf(argv[i], "%d:%d:%d:%d", &v.shadow_map_px, &v.slices, &v.stacks, &v.quads);
      if ((got != 1 && got != 4) || v.shadow_map_px < 1) {
        std::fprintf(stderr, "render_variants: error: %s: expected SHADOW_MAP_PX[:SLICES:STACKS:QUADS]\n",
                     argv[i]);
        return 1;
      }
      variants.push_back(v);
    }
  }
  if (variants.empty()) variants = {{1024}, {1024, 28, 16, 1}, {512}};
  const pvb::sim::GlBackend gl = pvb::sim::parse_gl_backend(backend);
  const pvb::scenes::Scenario base = pvb::scenes::load_scenario(PVB_SOURCE_DIR "/scenes/pv_station.yaml");
  const int frames = pvb::scenes::frame_count(base);
  std::vector<Result> results;
  std::vector<cv::Mat> ref_rgb, ref_depth;
  int written = 0;
  // One variant at a time: a renderer draws into the GL context made
  // current last, so two renderers must not be alive at once here.
  for (const Variant& v : variants) {
    Result res;
    pvb::scenes::Scenario s = base;
    s.light.shadow_map_px = v.shadow_map_px;
    pvb::sim::Simulator sim(s);
    if (v.slices > 0) {  // read by mjr_makeContext when the renderer starts
      auto* m = const_cast<mjModel*>(sim.model());
      m->vis.quality.numslices = v.slices;
      m->vis.quality.numstacks = v.stacks;
      m->vis.quality.numquads = v.quads;
    }
    pvb::sim::Renderer renderer(sim.model(), gl, s.camera.width, s.camera.height);
    renderer.set_shadows(s.light.shadows);
    const float sky = static_cast<float>(sim.assets().max_scene_depth_m);
    const bool is_ref = ref_rgb.empty();
    std::size_t shot = 0;
    for (int f = 0; f < frames; ++f) {
      if (f > 0) sim.advance();
      if (f % step != 0) continue;
      cv::Mat rgb, depth;
      renderer.render(sim.model(), sim.data(), sim.camera_id(), &rgb, &depth);  // warm caches
      double best_ms = 1e9;
      for (int rep = 0; rep < 4; ++rep) {
        const double t0 = process_cpu_ms();
        renderer.render(sim.model(), sim.data(), sim.camera_id(), &rgb, &depth);
        best_ms = std::min(best_ms, process_cpu_ms() - t0);
      }
      res.cpu_ms += best_ms;
      ++res.renders;
      depth.setTo(0.0f, depth > sky);
      if (is_ref) {
        ref_rgb.push_back(rgb);
        ref_depth.push_back(depth);
      }
      cv::Mat diff, dz;
      cv::absdiff(rgb, ref_rgb[shot], diff);
      res.mean_abs_sum += cv::mean(diff).dot(cv::Scalar(1, 1, 1, 0)) / 3.0;
      std::vector<cv::Mat> ch;
      cv::split(diff, ch);
      const cv::Mat max_channel = cv::max(cv::max(ch[0], ch[1]), ch[2]);
      res.changed_sum += cv::countNonZero(max_channel > 16) / static_cast<double>(max_channel.total());
      cv::absdiff(depth, ref_depth[shot], dz);
      res.depth_changed_sum += cv::countNonZero(dz > 0.001f) / static_cast<double>(dz.total());
      if (!out_dir.empty() && !is_ref && shot % 6 == 0) {
        cv::Mat row, diff4;
        diff.convertTo(diff4, CV_8UC3, 4.0);
        cv::hconcat(std::vector<cv::Mat>{ref_rgb[shot], rgb, diff4}, row);
        cv::cvtColor(row, row, cv::COLOR_RGB2BGR);
        char name[512];
        std::snprintf(name, sizeof name, "%s/variant%zu_frame%03d.png", out_dir.c_str(), results.size(), f);
        if (cv::imwrite(name, row)) ++written;
      }
      ++shot;
    }
    results.push_back(res);
  }
  std::printf("%-44s %12s %14s %14s %12s\n", "variant (first: reference)", "CPU ms", "mean |diff|",
              "px off >16", "depth >1mm");
  for (std::size_t i = 0; i < variants.size(); ++i) {
    const Result& r = results[i];
    std::printf("%-44s %12.2f %14.3f %13.2f%% %11.3f%%\n", variants[i].label().c_str(), r.cpu_ms / r.renders,
                r.mean_abs_sum / r.renders, 100.0 * r.changed_sum / r.renders,
                100.0 * r.depth_changed_sum / r.renders);
  }
  if (written) std::printf("%d comparison images in %s\n", written, out_dir.c_str());
  return 0;
}
