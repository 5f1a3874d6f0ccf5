// Not a benchmark: a depth camera model against the true depth, by where
// the surface lies and by range.  Renders every --every'th frame of a
// scenario (the robot drives all of them) and compares the sensor's depth
// with the rendered truth:
//   depth_table --scenario scenes/days/pv_station_1200.yaml --model d435 --every 25
// prints one Markdown row per class of surface: "panels" (the modules'
// faces, from the truth's geoms), "under cover" (something above the
// point: a panel table, a tree) and "open" (the rest):
//   - the share of pixels whose true depth lies in 0.5-4.5 m that have depth;
//   - per range bin of the true depth, the median and 95th percentile of
//     |depth - truth| over the pixels that have depth.
// --model kinect|d435 and --sunlight on|off override the scenario's camera;
// --out DIR writes colour, depth, truth (TUM PNGs), sheet.png (the three
// side by side) and (d435) the infrared images of --sheet-frame.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/sim/sun_shadow.hpp"
#include "pvb/sim/truth_surface.hpp"

namespace {

constexpr std::array<double, 6> kBinEdgesM = {0.5, 1.0, 2.0, 3.0, 4.5, 6.0};
constexpr int kBins = static_cast<int>(kBinEdgesM.size()) - 1;
constexpr int kPixelStep = 4;  // every 4th pixel of every 4th row

struct ClassStats {
  long in_range = 0, valid = 0;
  std::array<std::vector<float>, kBins> error_m;
};

struct Options {
  std::string scenario, model, sunlight, out, gl = "auto";
  int every = 25;
  int sheet_frame = -1;
};

int bin_of(double z) {
  for (int b = 0; b < kBins; ++b)
    if (z >= kBinEdgesM[static_cast<std::size_t>(b)] && z < kBinEdgesM[static_cast<std::size_t>(b) + 1]) return b;
  return -1;
}

double quantile(std::vector<float> v, double q) {
  if (v.empty()) return -1;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

constexpr int kClasses = 3;

void add_frame(pvb::sim::Simulator& sim, const pvb::sim::Capture& cap, const cv::Mat& geom_id,
               std::array<ClassStats, kClasses>* stats) {
  const pvb::sim::SunShadowCaster above(sim.model(), sim.data(), Eigen::Vector3d::UnitZ());
  const auto K = sim.intrinsics();
  for (int r = 0; r < cap.depth_gt_m.rows; r += kPixelStep)
    for (int c = 0; c < cap.depth_gt_m.cols; c += kPixelStep) {
      const float zt = cap.depth_gt_m.ptr<float>(r)[c], z = cap.frame.depth_m.ptr<float>(r)[c];
      if (zt <= 0) continue;
      const Eigen::Vector3d p_w = cap.T_w_c * Eigen::Vector3d(zt * (c - K.cx) / K.fx, zt * (r - K.cy) / K.fy, zt);
      const int g = geom_id.ptr<int>(r)[c];
      const bool panel = g >= 0 && pvb::sim::classify_geom(sim.model(), g) == pvb::sim::SurfaceClass::kPanel;
      ClassStats& s = (*stats)[panel ? 0 : above.shadowed(p_w, 0.05) ? 1 : 2];
      if (zt >= 0.5 && zt <= 4.5) {
        ++s.in_range;
        if (z > 0) ++s.valid;
      }
      const int b = bin_of(zt);
      if (b >= 0 && z > 0) s.error_m[static_cast<std::size_t>(b)].push_back(std::abs(z - zt));
    }
}

void write_sheet(const std::string& dir, const pvb::sim::RenderedFrame& rendered,
                 const pvb::sim::Capture& cap, const pvb::sim::RgbdCamera& camera) {
  cv::Mat bgr;
  cv::cvtColor(cap.frame.rgb, bgr, cv::COLOR_RGB2BGR);
  cv::imwrite(dir + "/colour.png", bgr);
  cv::Mat tum;  // TUM depth PNGs: 5000 steps per metre
  cap.frame.depth_m.convertTo(tum, CV_16U, 5000.0);
  cv::imwrite(dir + "/depth.png", tum);
  cap.depth_gt_m.convertTo(tum, CV_16U, 5000.0);
  cv::imwrite(dir + "/truth.png", tum);
  // sheet.png: colour | depth | true depth, depth in jet over 0-6 m, black = none
  auto jet = [](const cv::Mat& z) {
    cv::Mat u8, out;
    z.convertTo(u8, CV_8U, 255.0 / 6.0);
    cv::applyColorMap(u8, out, cv::COLORMAP_JET);
    out.setTo(cv::Scalar::all(0), z <= 0);
    return out;
  };
  cv::Mat sheet;
  cv::hconcat(std::vector<cv::Mat>{bgr, jet(cap.frame.depth_m), jet(cap.depth_gt_m)}, sheet);
  cv::imwrite(dir + "/sheet.png", sheet);
  if (rendered.stereo && camera.sensor_model().stereo_model()) {
    const auto& m = *camera.sensor_model().stereo_model();
    cv::imwrite(dir + "/ir_left.png", m.infrared_image(rendered.stereo->left, false, rendered.stereo->to_sun_c,
                                                       rendered.index));
    cv::imwrite(dir + "/ir_right.png", m.infrared_image(rendered.stereo->right, true, rendered.stereo->to_sun_c,
                                                        rendered.index));
  }
}

int run(const Options& o) {
  pvb::scenes::Scenario s = pvb::scenes::load_scenario(o.scenario);
  if (o.model == "d435") s.camera.model = pvb::scenes::CameraKind::kD435;
  if (o.model == "kinect") s.camera.model = pvb::scenes::CameraKind::kKinect;
  if (!o.sunlight.empty()) s.camera.depth_noise.sunlight.on = o.sunlight == "on";
  if (o.model == "d435") s.camera.use_d435_colour_camera();
  pvb::sim::Simulator sim(s);
  pvb::sim::RgbdCamera camera(sim, pvb::sim::parse_gl_backend(o.gl));
  pvb::sim::Renderer ids(sim.model(), camera.backend(), s.camera.width, s.camera.height);
  std::array<ClassStats, kClasses> stats;
  double sensor_ms = 0, match_ms = 0;
  int rendered_frames = 0;
  for (int f = 0; f < sim.frame_count(); ++f) {
    if (f > 0) sim.advance();
    if (f % o.every != 0 && f != o.sheet_frame) continue;
    pvb::sim::RenderedFrame rendered = camera.render(sim);
    pvb::sim::RenderedFrame kept;
    if (f == o.sheet_frame) kept = rendered;
    const pvb::sim::Capture cap = camera.sensor_model().apply(std::move(rendered));
    if (f == o.sheet_frame && !o.out.empty()) write_sheet(o.out, kept, cap, camera);
    if (f % o.every != 0) continue;
    cv::Mat geom_id;
    ids.render_geom_ids(sim.model(), sim.data(), sim.camera_id(), &geom_id);
    add_frame(sim, cap, geom_id, &stats);
    sensor_ms += cap.sensor_ms;
    match_ms += cap.stereo.match_ms;
    ++rendered_frames;
  }
  std::printf("| %s | %s | class | valid 0.5-4.5 m |", s.name.c_str(), o.model.empty() ? "scenario" : o.model.c_str());
  for (int b = 0; b < kBins; ++b)
    std::printf(" %.1f-%.1f m median / p95 |", kBinEdgesM[static_cast<std::size_t>(b)],
                kBinEdgesM[static_cast<std::size_t>(b) + 1]);
  std::printf("\n");
  const char* names[kClasses] = {"panels", "under cover", "open"};
  for (int k = 0; k < kClasses; ++k) {
    const ClassStats& c = stats[static_cast<std::size_t>(k)];
    std::printf("| | | %s | %.1f %% of %ld |", names[k], c.in_range ? 100.0 * c.valid / c.in_range : 0.0, c.in_range);
    for (int b = 0; b < kBins; ++b) {
      const auto& e = c.error_m[static_cast<std::size_t>(b)];
      if (e.empty())
        std::printf(" - |");
      else
        std::printf(" %.1f / %.1f mm |", 1000 * quantile(e, 0.5), 1000 * quantile(e, 0.95));
    }
    std::printf("\n");
  }
  std::printf("frames %d, sensor model %.1f ms/frame, stereo matching %.1f ms/frame\n", rendered_frames,
              sensor_ms / std::max(rendered_frames, 1), match_ms / std::max(rendered_frames, 1));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"depth_table: a depth camera model against the true depth"};
  Options o;
  app.add_option("--scenario", o.scenario, "scenario file")->required();
  app.add_option("--model", o.model, "kinect or d435 (default: the scenario's)")->check(CLI::IsMember({"kinect", "d435"}));
  app.add_option("--sunlight", o.sunlight, "on or off: the Kinect model's sunlight")->check(CLI::IsMember({"on", "off"}));
  app.add_option("--every", o.every, "render every n-th frame")->check(CLI::Range(1, 100000));
  app.add_option("--sheet-frame", o.sheet_frame, "the frame whose images --out gets");
  app.add_option("--out", o.out, "folder for the images of --sheet-frame");
  app.add_option("--gl", o.gl, "auto, egl or osmesa");
  CLI11_PARSE(app, argc, argv);
  try {
    return run(o);
  } catch (const pvb::Error& e) {
    std::fprintf(stderr, "depth_table: error: %s\n", e.what());
    return 1;
  }
}
