// Rendering on a hand-written model: metric depth of a plane and the
// projection of known points, on each GL backend.  ctest runs every test in
// its own process, so each process loads one backend only.
#include <gtest/gtest.h>

#include <cstring>

#include "pvb/common/error.hpp"
#include "pvb/geometry/pinhole.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/scene_builder.hpp"

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

TEST(GlContext, ParseBackendNames) {
  EXPECT_EQ(sim::parse_gl_backend("egl"), sim::GlBackend::kEgl);
  EXPECT_EQ(sim::parse_gl_backend("osmesa"), sim::GlBackend::kOsmesa);
  EXPECT_EQ(sim::parse_gl_backend("auto"), sim::GlBackend::kAuto);
  EXPECT_THROW(sim::parse_gl_backend("glx"), ConfigError);
}
