// Render speed of a saved scene (a recording's scene.xml and textures/),
// on a machine that has no build of its own: links MuJoCo, the GL module
// loader and OpenCV's core only, so it runs where only those libraries are
// copied (a GPU machine, for example).  The robot drives forward, turning,
// and every frame is rendered and read back (RGB + depth) from its camera:
//   render_scene --scene REC/scene.xml --gl egl --frames 600 --out DIR
// prints the backend, frames/s over the timed frames and the median render
// time, and writes the first and last frame to DIR as PPM images.
#include <mujoco/mujoco.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/scene_builder.hpp"

namespace {

struct Options {
  std::string scene;
  std::string gl = "egl";
  std::string out;
  int frames = 600;
  int warmup = 30;
  int width = 640;
  int height = 480;
  std::vector<double> start;  // x, y, yaw (deg) of the robot; empty: the scene's own
  bool straight = false;
  bool cull = true;
  double far_tile_cull_m = 0;
};

void write_ppm(const std::string& path, const cv::Mat& rgb) {
  std::ofstream f(path, std::ios::binary);
  f << "P6\n" << rgb.cols << " " << rgb.rows << "\n255\n";
  for (int r = 0; r < rgb.rows; ++r) f.write(rgb.ptr<const char>(r), static_cast<std::streamsize>(rgb.cols) * 3);
  if (!f) throw pvb::IoError(path, "cannot write");
}

int actuator(const mjModel* m, const char* name) {
  const int id = mj_name2id(m, mjOBJ_ACTUATOR, name);
  if (id < 0) throw pvb::Error(std::string("the scene has no actuator ") + name);
  return id;
}

// Puts the robot's free joint at (x, y) heading yaw, keeping its height.
void place_robot(const mjModel* m, mjData* d, const std::vector<double>& start) {
  const int joint = mj_name2id(m, mjOBJ_JOINT, "robot_free");
  if (joint < 0) throw pvb::Error("the scene has no joint robot_free");
  double* q = d->qpos + m->jnt_qposadr[joint];
  const double half_yaw = 0.5 * start[2] * 3.14159265358979323846 / 180.0;
  q[0] = start[0];
  q[1] = start[1];
  q[3] = std::cos(half_yaw);
  q[4] = 0;
  q[5] = 0;
  q[6] = std::sin(half_yaw);
  mj_forward(m, d);
}

int run(const Options& o) {
  char err[1024] = {0};
  mjModel* m = mj_loadXML(o.scene.c_str(), nullptr, err, sizeof err);
  if (m == nullptr) throw pvb::Error(o.scene + ": " + err);
  // A relief under a varied ground keeps its tiles' heights beside scene.xml.
  const std::string dir = o.scene.substr(0, o.scene.find_last_of('/') + 1);
  std::ifstream tiles(dir + pvb::sim::kReliefTilesFile, std::ios::binary);
  if (tiles)
    pvb::sim::fill_relief_tiles(m, std::vector<unsigned char>(std::istreambuf_iterator<char>(tiles), {}));
  mjData* d = mj_makeData(m);
  const int camera = mj_name2id(m, mjOBJ_CAMERA, "rgbd");
  if (camera < 0) throw pvb::Error(o.scene + ": no camera named rgbd");
  if (!o.start.empty()) place_robot(m, d, o.start);
  d->ctrl[actuator(m, "wheel_left")] = 4.0;  // forward, turning slowly right unless straight
  d->ctrl[actuator(m, "wheel_right")] = o.straight ? 4.0 : 3.5;
  const int steps_per_frame = std::max(1, static_cast<int>(1.0 / 30.0 / m->opt.timestep + 0.5));

  pvb::sim::Renderer renderer(m, pvb::sim::parse_gl_backend(o.gl), o.width, o.height);
  renderer.set_culling(o.cull);
  renderer.set_far_tile_cull_m(o.far_tile_cull_m);
  cv::Mat rgb, depth;
  std::vector<double> ms, physics_ms;
  double depth_sum = 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto timed0 = t0;
  for (int i = 0; i < o.warmup + o.frames; ++i) {
    if (i == o.warmup) timed0 = std::chrono::steady_clock::now();
    const auto p = std::chrono::steady_clock::now();
    for (int s = 0; s < steps_per_frame; ++s) mj_step(m, d);
    const auto a = std::chrono::steady_clock::now();
    physics_ms.push_back(std::chrono::duration<double, std::milli>(a - p).count());
    renderer.render(m, d, camera, &rgb, &depth);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
    depth_sum += cv::mean(depth)[0];
    if (!o.out.empty() && i == 0) write_ppm(o.out + "/first.ppm", rgb);
  }
  const double timed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - timed0).count();
  if (!o.out.empty()) write_ppm(o.out + "/last.ppm", rgb);
  std::vector<double> timed(ms.begin() + o.warmup, ms.end());
  std::nth_element(timed.begin(), timed.begin() + static_cast<long>(timed.size() / 2), timed.end());
  std::vector<double> physics(physics_ms.begin() + o.warmup, physics_ms.end());
  std::nth_element(physics.begin(), physics.begin() + static_cast<long>(physics.size() / 2), physics.end());
  std::printf("backend: %s; %d model geoms, culling %s\n", renderer.description().c_str(), m->ngeom,
              o.cull ? "on" : "off");
  std::printf("%d frames of %dx%d (after %d warm-up), physics + render + readback: %.1f frames/s; "
              "render + readback median %.2f ms; physics median %.2f ms; mean RGB of the last frame %.1f; mean depth %.2f m\n",
              o.frames, o.width, o.height, o.warmup, o.frames / timed_s, timed[timed.size() / 2], physics[physics.size() / 2],
              cv::mean(rgb)[0], depth_sum / static_cast<double>(ms.size()));
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Render speed of a saved scene along a driven path"};
  app.add_option("--scene", o.scene, "scene.xml of a recording (textures/ beside it)")->required();
  app.add_option("--gl", o.gl, "egl, osmesa or auto");
  app.add_option("--frames", o.frames, "timed frames")->check(CLI::PositiveNumber);
  app.add_option("--warmup", o.warmup, "frames before the timing")->check(CLI::NonNegativeNumber);
  app.add_option("--width", o.width)->check(CLI::PositiveNumber);
  app.add_option("--height", o.height)->check(CLI::PositiveNumber);
  app.add_option("--out", o.out, "folder for first.ppm and last.ppm");
  app.add_option("--start", o.start, "the robot's x y (m) and yaw (deg) in the world")->expected(3);
  app.add_flag("--straight", o.straight, "drive straight instead of a slow right curve");
  app.add_flag("!--no-cull", o.cull, "draw every geom instead of those in view");
  app.add_option("--far-tile-cull-m", o.far_tile_cull_m, "leave out ground tiles further than this (0: none)");
  CLI11_PARSE(app, argc, argv);
  try {
    return run(o);
  } catch (const pvb::Error& e) {
    std::cerr << "render_scene: error: " << e.what() << "\n";
    return 1;
  }
}
