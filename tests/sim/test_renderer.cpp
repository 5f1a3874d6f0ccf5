// Rendering on a hand-written model: metric depth of a plane and the
// projection of known points, on each GL backend.  ctest runs every test in
// its own process, so each process loads one backend only.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/geometry/pinhole.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/simulator.hpp"

using namespace pvb;

namespace {

constexpr int kW = 640, kH = 480;

// Camera at the origin looking along +x (MuJoCo camera: x right = -y world,
// y up = +z world), a movable wall, and small emissive markers.
std::string test_model_xml() {
  scenes::Camera cam;  // Kinect-like defaults: fy = 525 at 640x480
  char buf[4096];
  std::snprintf(buf, sizeof buf, R"(<mujoco>
  <statistic extent="10" center="0 0 0"/>
  <visual><global offwidth="%d" offheight="%d"/><quality offsamples="0"/>
    <map znear="0.005" zfar="10"/><headlight ambient="0.4 0.4 0.4" diffuse="0.3 0.3 0.3"/></visual>
  <asset><material name="marker" rgba="1 0 0 1" emission="1"/></asset>
  <worldbody>
    <camera name="cam" pos="0 0 0" xyaxes="0 -1 0 0 0 1" fovy="%.9f"/>
    <body name="wall" mocap="true" pos="100 0 0"><geom type="box" size="0.5 50 50" rgba="0.5 0.5 0.5 1"/></body>
    <body name="m0" mocap="true" pos="2.0 0.3 -0.2"><geom type="sphere" size="0.02" material="marker"/></body>
    <body name="m1" mocap="true" pos="3.0 -0.8 0.5"><geom type="sphere" size="0.02" material="marker"/></body>
    <body name="m2" mocap="true" pos="1.5 0.45 0.3"><geom type="sphere" size="0.02" material="marker"/></body>
  </worldbody></mujoco>)",
                kW, kH, cam.fovy_deg());
  return buf;
}

struct Fixture {
  sim::ModelPtr model;
  mjData* data = nullptr;
  std::unique_ptr<sim::Renderer> renderer;
  ~Fixture() {
    if (data) mj_deleteData(data);
  }
};

// Returns false (and skips) when this process already holds the other backend.
bool make_fixture(Fixture* f, sim::GlBackend backend) {
  sim::SceneAssets a;
  a.xml = test_model_xml();
  f->model = sim::compile_scene(a);
  f->data = mj_makeData(f->model.get());
  try {
    f->renderer = std::make_unique<sim::Renderer>(f->model.get(), backend, kW, kH);
  } catch (const UnavailableError& e) {
    if (std::strstr(e.what(), "already loaded") != nullptr) return false;
    throw;
  }
  return true;
}

geom::PinholeIntrinsics intrinsics() {
  scenes::Camera c;
  return {c.fx, c.fy, c.cx(), c.cy(), c.width, c.height};
}

void check_plane_depth(sim::GlBackend backend) {
  Fixture f;
  if (!make_fixture(&f, backend)) GTEST_SKIP() << "another GL backend is loaded in this process";
  const int wall = mj_name2id(f.model.get(), mjOBJ_BODY, "wall");
  const int mocap = f.model->body_mocapid[wall];
  for (double d : {0.6, 1.0, 2.5, 4.0, 4.5}) {
    f.data->mocap_pos[3 * mocap] = d + 0.5;  // front face at x = d
    mj_forward(f.model.get(), f.data);
    cv::Mat rgb, depth;
    f.renderer->render(f.model.get(), f.data, 0, &rgb, &depth);
    double worst = 0;
    for (int r = 0; r < kH; r += 7)
      for (int c = 0; c < kW; c += 7) {
        const double z = depth.at<float>(r, c);
        if (rgb.at<cv::Vec3b>(r, c)[0] > 200 && rgb.at<cv::Vec3b>(r, c)[1] < 50) continue;  // a marker
        worst = std::max(worst, std::abs(z - d));
      }
    EXPECT_LT(worst, 1e-4) << "plane at " << d << " m";
    std::printf("%s: plane at %.1f m, worst depth error %.2e m\n", sim::to_string(backend), d, worst);
  }
}

void check_projection(sim::GlBackend backend) {
  Fixture f;
  if (!make_fixture(&f, backend)) GTEST_SKIP() << "another GL backend is loaded in this process";
  mj_forward(f.model.get(), f.data);
  cv::Mat rgb, depth;
  f.renderer->render(f.model.get(), f.data, 0, &rgb, &depth);
  const geom::PinholeIntrinsics K = intrinsics();
  // World (x forward, y left, z up) to optical (x right, y down, z forward).
  for (const char* name : {"m0", "m1", "m2"}) {
    const int b = mj_name2id(f.model.get(), mjOBJ_BODY, name);
    const double* p = f.model->body_pos + 3 * b;
    const auto uv = K.project(Eigen::Vector3d(-p[1], -p[2], p[0]));
    ASSERT_TRUE(uv.has_value());
    double su = 0, sv = 0, n = 0;
    for (int r = static_cast<int>(uv->y()) - 15; r <= static_cast<int>(uv->y()) + 15; ++r)
      for (int c = static_cast<int>(uv->x()) - 15; c <= static_cast<int>(uv->x()) + 15; ++c) {
        const cv::Vec3b px = rgb.at<cv::Vec3b>(r, c);
        if (px[0] > 128 && px[1] < 100) {
          su += c;
          sv += r;
          n += 1;
        }
      }
    ASSERT_GT(n, 20) << name;
    std::printf("%s: %s projects %.3f px, %.3f px from the pinhole model\n", sim::to_string(backend), name,
                su / n - uv->x(), sv / n - uv->y());
    EXPECT_NEAR(su / n, uv->x(), 0.2) << name;
    EXPECT_NEAR(sv / n, uv->y(), 0.2) << name;
  }
  // Sky (nothing within zfar) reads as 0 depth; the wall is 100 m away, beyond zfar.
  EXPECT_EQ(depth.at<float>(10, 10), 0.0f);
}

// Depth at the image centre with the wall's front face at d metres.
float centre_depth(Fixture* f, double d) {
  const int wall = mj_name2id(f->model.get(), mjOBJ_BODY, "wall");
  f->data->mocap_pos[3 * f->model->body_mocapid[wall]] = d + 0.5;
  mj_forward(f->model.get(), f->data);
  cv::Mat rgb, depth;
  f->renderer->render(f->model.get(), f->data, 0, &rgb, &depth);
  return depth.at<float>(kH / 2, kW / 2 + 40);  // beside the markers
}

// Two renderers in one process (one per scene, say): each render must go to
// its own context, also after the other renderer was destroyed (EGL: the
// shared display must outlive it).
void check_two_renderers(sim::GlBackend backend) {
  Fixture a;
  if (!make_fixture(&a, backend)) GTEST_SKIP() << "another GL backend is loaded in this process";
  auto b = std::make_unique<Fixture>();
  ASSERT_TRUE(make_fixture(b.get(), backend));
  EXPECT_NEAR(centre_depth(&a, 1.0), 1.0, 1e-4);
  EXPECT_NEAR(centre_depth(b.get(), 2.5), 2.5, 1e-4);
  EXPECT_NEAR(centre_depth(&a, 1.5), 1.5, 1e-4);
  b.reset();
  EXPECT_NEAR(centre_depth(&a, 3.0), 3.0, 1e-4);
  Fixture c;  // and a new one after that
  ASSERT_TRUE(make_fixture(&c, backend));
  EXPECT_NEAR(centre_depth(&c, 2.0), 2.0, 1e-4);
  EXPECT_NEAR(centre_depth(&a, 0.8), 0.8, 1e-4);
}

// A post's shadow on the ground, seen from above by a world camera, under a
// sun that follows a movable carrier (as the scenes' sun follows the robot):
// 9 m shadow clip at 1024 texels, 17.6 mm a texel, about 3 px here.
std::string shadow_model_xml() {
  scenes::Camera cam;
  char buf[4096];
  std::snprintf(buf, sizeof buf, R"(<mujoco>
  <statistic extent="10" center="0 0 0"/>
  <visual><global offwidth="%d" offheight="%d"/><quality offsamples="0" shadowsize="1024"/>
    <map znear="0.005" zfar="10" shadowclip="0.9"/><headlight ambient="0.3 0.3 0.3" diffuse="0 0 0"/></visual>
  <worldbody>
    <geom type="plane" size="20 20 0.1" rgba="0.7 0.7 0.7 1"/>
    <geom type="box" size="0.03 0.6 0.5" pos="0.3 0 0.5" euler="0 0 27" rgba="0.5 0.5 0.5 1"/>
    <camera name="top" pos="1.0 0.8 3.0" xyaxes="0 -1 0 1 0 0" fovy="%.9f"/>
    <body name="carrier" mocap="true" pos="0 0 0">
      <light name="sun" mode="track" directional="true" castshadow="true" pos="-10.8 -3.9 16.4"
             dir="0.54 0.196 -0.82" diffuse="0.8 0.8 0.8"/>
    </body>
  </worldbody></mujoco>)",
                kW, kH, cam.fovy_deg());
  return buf;
}

struct ShadowRun {
  std::vector<int> changed_px;    ///< per offset: pixels that differ from offset 0
  std::vector<double> shift_px;   ///< per offset: shift of the shadow's centroid, pixels
};

// Renders the post's shadow with the sun's carrier moved by each offset
// (metres along `axis`) and compares each image with the first.
ShadowRun move_the_sun(sim::GlBackend backend, bool stable, const std::vector<double>& offsets_m,
                       const Eigen::Vector3d& axis) {
  sim::SceneAssets a;
  a.xml = shadow_model_xml();
  sim::ModelPtr model = sim::compile_scene(a);
  mjData* data = mj_makeData(model.get());
  sim::Renderer renderer(model.get(), backend, kW, kH);
  renderer.set_stable_shadows(stable);
  const int mocap = model->body_mocapid[mj_name2id(model.get(), mjOBJ_BODY, "carrier")];
  ShadowRun out;
  cv::Mat first;
  cv::Point2d first_centroid;

  for (double d : offsets_m) {
    for (int i = 0; i < 3; ++i) data->mocap_pos[3 * mocap + i] = d * axis[i];
    mj_forward(model.get(), data);
    cv::Mat rgb, grey;
    renderer.render(model.get(), data, 0, &rgb, nullptr);
    cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
    // the shadow on the ground (grey 70-110 here); the wall's shaded side is darker, the lit ground lighter
    const cv::Moments m = cv::moments((grey > 60) & (grey < 130), true);
    const cv::Point2d centroid(m.m10 / m.m00, m.m01 / m.m00);
    if (first.empty()) {
      first = grey;
      first_centroid = centroid;
      continue;
    }
    cv::Mat diff;
    cv::absdiff(grey, first, diff);
    out.changed_px.push_back(cv::countNonZero(diff > 8));
    out.shift_px.push_back(cv::norm(centroid - first_centroid));
  }
  mj_deleteData(data);
  return out;
}

}  // namespace

TEST(Renderer, DepthFromBufferFormula) {
  // Standard Z buffer: d = 0 at the near plane, 1 at the far plane.
  EXPECT_FLOAT_EQ(sim::depth_from_buffer(0.0f, 0.05, 50.0), 0.05f);
  EXPECT_FLOAT_EQ(sim::depth_from_buffer(1.0f, 0.05, 50.0), 0.0f);
  const double n = 0.05, fr = 50, z = 3.0;
  const double d = (1.0 / n - 1.0 / z) / (1.0 / n - 1.0 / fr);
  EXPECT_NEAR(sim::depth_from_buffer(static_cast<float>(d), n, fr), z, 1e-4);
}

TEST(RendererEgl, PlaneDepthIsExact) { check_plane_depth(sim::GlBackend::kEgl); }
TEST(RendererEgl, KnownPointsProjectWithinTwoTenthsOfAPixel) { check_projection(sim::GlBackend::kEgl); }
TEST(RendererOsmesa, PlaneDepthIsExact) { check_plane_depth(sim::GlBackend::kOsmesa); }
TEST(RendererOsmesa, KnownPointsProjectWithinTwoTenthsOfAPixel) { check_projection(sim::GlBackend::kOsmesa); }
TEST(RendererEgl, TwoRenderersInOneProcessEachUseTheirOwnContext) {
  check_two_renderers(sim::GlBackend::kEgl);
}
TEST(RendererOsmesa, TwoRenderersInOneProcessEachUseTheirOwnContext) {
  check_two_renderers(sim::GlBackend::kOsmesa);
}

// A sun that follows the robot drags its shadow map's texel grid along, and
// every shadow edge's texel steps crawl over the static ground.  Snapping
// the light to a world-fixed grid stops that for moves of a fraction of a
// texel...
TEST(RendererOsmesa, SnappedSunKeepsShadowEdgesStillUnderSmallMoves) {
  const std::vector<double> offsets_m = {0.0, 0.0041, 0.0093, 0.0137};
  const ShadowRun dragged = move_the_sun(sim::GlBackend::kOsmesa, false, offsets_m, Eigen::Vector3d::UnitX());
  const ShadowRun stable = move_the_sun(sim::GlBackend::kOsmesa, true, offsets_m, Eigen::Vector3d::UnitX());
  for (std::size_t i = 0; i < stable.changed_px.size(); ++i) {
    std::printf("sun moved %.4f m: %d pixels change as MuJoCo draws it, %d with the grid fixed\n",
                offsets_m[i + 1], dragged.changed_px[i], stable.changed_px[i]);
    EXPECT_GT(dragged.changed_px[i], 100) << "the control: a texel grid that moves must move the shadow edges";
    EXPECT_LE(stable.changed_px[i], 5) << "shadow edges moved with the sun by " << offsets_m[i + 1] << " m";
  }
}

// ...but not over metres: MuJoCo 2.2.2 renders the shadow map into its
// inner size - 2 texels and samples it over the whole texture, so shadows
// are drawn 2 / (size - 2) nearer the light's axis than they are, and move
// with the light by that share of its travel, even in whole-texel steps.
// This is why the scenes' sun is fixed in the world (sim::ShadowMap); if a
// MuJoCo update makes this test fail, a following sun has become safe.
TEST(RendererOsmesa, ShadowsCreepWithALightThatMovesMetres) {
  const double texel_m = sim::shadow_texel_m(9.0, 1024);
  const std::vector<double> offsets_m = {0.0, 200 * texel_m, 400 * texel_m};
  const ShadowRun run = move_the_sun(sim::GlBackend::kOsmesa, true, offsets_m, Eigen::Vector3d::UnitY());
  // the camera is 3 m above the ground: 3 / 525 m a pixel
  for (std::size_t i = 0; i < run.shift_px.size(); ++i) {
    const double creep_px = offsets_m[i + 1] * 2.0 / 1022 / (3.0 / 525.0);
    std::printf("sun moved %.3f m: shadow moved %.2f px, %.2f px expected from the 2-texel mismatch\n",
                offsets_m[i + 1], run.shift_px[i], creep_px);
    EXPECT_GT(run.shift_px[i], 0.4 * creep_px);
    EXPECT_LT(run.shift_px[i], 1.6 * creep_px);
  }
}

TEST(Renderer, SnappingKeepsTheLightOnItsRayAndOnTheGrid) {
  const float dir[3] = {0.54f, 0.196f, -0.82f};
  float pos[3] = {3.217f, -1.403f, 16.4f};
  const float before[3] = {pos[0], pos[1], pos[2]};
  const double texel = sim::shadow_texel_m(9.0, 1024);
  EXPECT_NEAR(texel, 18.0 / 1022, 1e-12);
  sim::snap_to_shadow_texels(pos, dir, texel);
  // moved across the light direction only, by at most half a texel diagonal
  const Eigen::Vector3d d = Eigen::Vector3d(dir[0], dir[1], dir[2]).normalized();
  const Eigen::Vector3d moved(pos[0] - before[0], pos[1] - before[1], pos[2] - before[2]);
  EXPECT_NEAR(moved.dot(d), 0.0, 1e-5);
  EXPECT_LE(moved.norm(), texel * std::sqrt(0.5) + 1e-6);
  // snapping twice changes nothing
  float again[3] = {pos[0], pos[1], pos[2]};
  sim::snap_to_shadow_texels(again, dir, texel);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(again[i], pos[i], 2e-6);
}

TEST(GlContext, OneProcessNeverLoadsBothBackends) {
  auto first = sim::GlContext::create(sim::GlBackend::kAuto, 64, 64);
  const sim::GlBackend other =
      first->backend() == sim::GlBackend::kEgl ? sim::GlBackend::kOsmesa : sim::GlBackend::kEgl;
  try {
    sim::GlContext::create(other, 64, 64);
    FAIL() << "loading a second backend must be refused";
  } catch (const UnavailableError& e) {
    EXPECT_NE(std::string(e.what()).find("already loaded"), std::string::npos) << e.what();
  }
  // auto resolves to what is loaded, never to the other one
  EXPECT_EQ(sim::resolve_gl_backend(sim::GlBackend::kAuto), first->backend());
}

// Without MUJOCO_GL, auto probes for a backend that renders (EGL first, in
// a child process) and the context it names is made.
TEST(GlContext, AutoWithoutMujocoGlProbesForABackendThatRenders) {
  unsetenv("MUJOCO_GL");
  const sim::GlBackend b = sim::resolve_gl_backend(sim::GlBackend::kAuto);
  ASSERT_TRUE(b == sim::GlBackend::kEgl || b == sim::GlBackend::kOsmesa);
  EXPECT_EQ(sim::GlContext::create(sim::GlBackend::kAuto, 64, 64)->backend(), b);
}

TEST(GlContext, ParseBackendNames) {
  EXPECT_EQ(sim::parse_gl_backend("egl"), sim::GlBackend::kEgl);
  EXPECT_EQ(sim::parse_gl_backend("osmesa"), sim::GlBackend::kOsmesa);
  EXPECT_EQ(sim::parse_gl_backend("auto"), sim::GlBackend::kAuto);
  EXPECT_THROW(sim::parse_gl_backend("glx"), ConfigError);
}

// The segmentation pass's depth is the colour pass's wherever a geom shows
// (the sky is not drawn there: nothing, 0).  Checked once over every shipped
// scenario (every 40th of their first 400 frames, 320 x 240); kept here on
// the default station with its sun and shadows.
TEST(RendererOsmesa, TheGeomIdPassGivesTheColourPassDepth) {
  sim::Simulator s(scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml"));
  sim::Renderer r(s.model(), sim::GlBackend::kOsmesa, 160, 120);
  cv::Mat rgb, depth, ids, ids_depth;
  for (int i = 0; i < 120; ++i) {
    if (i > 0) s.advance();
    if (i % 60) continue;
    // The id pass first: its depth cannot be what the colour pass left.
    r.render_geom_ids(s.model(), s.data(), s.camera_id(), &ids, &ids_depth);
    r.render(s.model(), s.data(), s.camera_id(), &rgb, &depth);
    const cv::Mat geom = ids >= 0, sky = ids < 0;
    ASSERT_GT(cv::countNonZero(geom), 0);
    ASSERT_GT(cv::countNonZero(sky), 0);
    EXPECT_EQ(cv::norm(depth, ids_depth, cv::NORM_INF, geom), 0.0) << "frame " << i;
    EXPECT_EQ(cv::norm(ids_depth, cv::NORM_INF, sky), 0.0) << "frame " << i;
  }
}
