// Specular module glass: Fresnel's angle dependence, which pixels show the
// glass, what the glass adds to colour, and what it does to Kinect depth.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "mjcf_scene.hpp"
#include "pvb/sim/glass.hpp"
#include "pvb/sim/sensor_model.hpp"

using namespace pvb;

namespace {

constexpr double kDegToRad = M_PI / 180.0;

using Scene = pvb::test::MjcfScene;

/// A 2 x 1 m panel of array 0 (its material named as the scene builder
/// names them) lying flat 1 m up, its glass face up, over a ground plane.
Scene panel_scene() {
  static const std::string xml = R"(<mujoco><asset><material name="a0panel0"/><material name="a1panel0"/></asset>
    <worldbody>
    <geom type="plane" size="10 10 1"/>
    <geom name="glass" type="box" pos="0 0 1" size="1 0.5 0.02" material="a0panel0"/>
    <geom name="other" type="box" pos="0 3 1" size="1 0.5 0.02" material="a1panel0"/>
  </worldbody></mujoco>)";
  Scene s = pvb::test::load_mjcf(xml);
  EXPECT_TRUE(s.m) << s.error;
  return s;
}

/// Depth along the optical axis by casting each pixel's ray, and the geom hit.
void cast_depth(const Scene& s, const geom::PinholeIntrinsics& K, const geom::SE3d& T_w_c, cv::Mat* depth,
                cv::Mat* geom_id) {
  *depth = cv::Mat::zeros(K.height, K.width, CV_32FC1);
  *geom_id = cv::Mat(K.height, K.width, CV_32SC1, cv::Scalar(-1));
  const Eigen::Vector3d eye = T_w_c.translation();
  for (int r = 0; r < K.height; ++r)
    for (int c = 0; c < K.width; ++c) {
      const Eigen::Vector3d ray_c((c - K.cx) / K.fx, (r - K.cy) / K.fy, 1.0);
      const Eigen::Vector3d dir = T_w_c.linear() * ray_c;
      int g = -1;
      const mjtNum t = mj_ray(s.m.get(), s.d.get(), eye.data(), dir.data(), nullptr, 1, -1, &g);
      if (g < 0 || t <= 0) continue;
      depth->at<float>(r, c) = static_cast<float>(t);  // dir has z = 1 in the camera: t is the depth
      geom_id->at<int>(r, c) = g;
    }
}

/// A camera 3 m from the panel's centre looking at it from `elevation_deg`
/// above its plane (from the +y side).
geom::SE3d looking_at_panel(double elevation_deg, double range_m = 3.0) {
  const double e = elevation_deg * kDegToRad;
  const Eigen::Vector3d target(0, 0, 1.02), eye = target + range_m * Eigen::Vector3d(0, std::cos(e), std::sin(e));
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d R;
  R << x, z.cross(x), z;
  return geom::make_se3(R, eye);
}

const geom::PinholeIntrinsics kK{100, 100, 79.5, 59.5, 160, 120};

}  // namespace

TEST(Glass, FresnelReflectanceOfGlassGrowsTowardsGrazingIncidence) {
  EXPECT_NEAR(sim::fresnel_reflectance(1.0), 0.040, 0.0005);  // ((n - 1) / (n + 1))^2 = 0.04
  EXPECT_NEAR(sim::fresnel_reflectance(std::cos(60 * kDegToRad)), 0.0892, 0.0005);
  EXPECT_NEAR(sim::fresnel_reflectance(std::cos(80 * kDegToRad)), 0.388, 0.001);
  EXPECT_NEAR(sim::fresnel_reflectance(0.0), 1.0, 1e-12);
  double last = 0;
  for (int deg = 0; deg <= 90; deg += 5) {
    const double R = sim::fresnel_reflectance(std::cos(deg * kDegToRad));
    EXPECT_GE(R, last - 1e-12) << deg;
    last = R;
  }
  // The cells' pattern comes back to 4 m sqrt(0.08 (1 - R)^2 / 0.5): 1.54 m head on.
  EXPECT_NEAR(sim::glass_pattern_range_m(1.0), 4.0 * std::sqrt(0.08 * 0.96 * 0.96 / 0.5), 1e-6);
  for (double c = 0.0; c <= 1.0; c += 0.0037) {
    const double R = sim::fresnel_reflectance(c);
    EXPECT_NEAR(sim::fresnel_glass(c), R, 2e-4) << c;
    // the mirror's image (R^2 0.3) against the cells' return (0.08 (1 - R)^2)
    if (std::abs(R * R * 0.3 - 0.08 * (1 - R) * (1 - R)) > 1e-3) {
      EXPECT_EQ(sim::mirror_depth_wins(c), R * R * 0.3 > 0.08 * (1 - R) * (1 - R)) << c;
    }
  }
  EXPECT_FALSE(sim::mirror_depth_wins(1.0));
  EXPECT_TRUE(sim::mirror_depth_wins(std::cos(85 * kDegToRad)));
}

TEST(Glass, TheFinderMarksTheSpecularArraysGlassFaceOnly) {
  const Scene s = panel_scene();
  ASSERT_TRUE(s.m);
  const int glass = mj_name2id(s.m.get(), mjOBJ_GEOM, "glass");
  const sim::GlassFinder finder(s.m.get(), {true, false});
  const geom::SE3d above = looking_at_panel(40);
  cv::Mat depth, ids;
  cast_depth(s, kK, above, &depth, &ids);
  const sim::GlassView v = finder.find(s.d.get(), depth, kK, above, true);
  ASSERT_EQ(v.normals_c.size(), 1u) << "one face turned to the camera; array 1 is diffuse";
  int on_glass = 0, agree = 0;
  for (int r = 0; r < kK.height; ++r)
    for (int c = 0; c < kK.width; ++c) {
      const bool truth = ids.at<int>(r, c) == glass, found = v.face.at<std::uint16_t>(r, c) != 0;
      on_glass += truth;
      agree += truth == found;
    }
  EXPECT_GT(on_glass, 1000);
  EXPECT_EQ(agree, kK.width * kK.height);
  // The normal points up (the camera's -y is up in the world here).
  EXPECT_GT((v.R_w_c * v.normals_c[0]).z(), 0.99f);
  // From below, the camera sees the back: no glass.
  const geom::SE3d below = looking_at_panel(-40);
  cast_depth(s, kK, below, &depth, &ids);
  EXPECT_EQ(cv::countNonZero(finder.find(s.d.get(), depth, kK, below, true).face), 0);
}

TEST(Glass, ColourMirrorsMoreOfTheSkyTowardsGrazingAndGlintsAtTheSunsMirror) {
  const Scene s = panel_scene();
  ASSERT_TRUE(s.m);
  const sim::GlassFinder finder(s.m.get(), {true});
  auto centre_after = [&](double elevation_deg, const Eigen::Vector3f& to_sun_w, bool sun_up) {
    const geom::SE3d T = looking_at_panel(elevation_deg);
    cv::Mat depth, ids;
    cast_depth(s, kK, T, &depth, &ids);
    const sim::GlassView v = finder.find(s.d.get(), depth, kK, T, true);
    cv::Mat rgb(kK.height, kK.width, CV_8UC3, cv::Scalar(20, 30, 60));
    const Eigen::Vector3f to_sun_c = T.linear().transpose().cast<float>() * to_sun_w.normalized();
    sim::apply_glass(&rgb, v, kK, to_sun_c, sun_up);
    return rgb.at<cv::Vec3b>(60, 80);
  };
  const Eigen::Vector3f away(0, -1, -1);  // under the horizon: no glint
  const cv::Vec3b steep = centre_after(80, away, false), grazing = centre_after(10, away, false);
  // Steep: (1 - R) c + R sky with R ~ 0.04: the cells' colour, a little lighter.
  const double R80 = sim::fresnel_reflectance(std::cos(10 * kDegToRad));
  const Eigen::Vector3f sky = sim::mirrored_colour(Eigen::Vector3f(0, -std::cos(80 * kDegToRad), std::sin(80 * kDegToRad)));
  EXPECT_NEAR(steep[0], (1 - R80) * 20 + 255 * R80 * sky.x(), 1.0);
  EXPECT_GT(grazing[0], steep[0] + 50) << "the sky mirrored at 80 degrees incidence";
  // The sun at the camera's mirror direction: saturated.
  const Eigen::Vector3f mirror_of_camera(0, -std::cos(40 * kDegToRad), std::sin(40 * kDegToRad));
  EXPECT_EQ(centre_after(40, mirror_of_camera, true)[1], 255);
  EXPECT_LT(centre_after(40, mirror_of_camera, false)[1], 200) << "no sun, no glint";
}

TEST(Glass, KinectDepthOnGlassIsLostBeyondTheCellsRangeOrTakenFromTheMirror) {
  scenes::Camera cam;
  cam.depth_noise.lateral_sigma_px = 0;
  cam.depth_noise.axial_scale = 0;
  cam.depth_noise.disparity_step_px = 0;
  const geom::PinholeIntrinsics K{525, 525, 319.5, 239.5, 640, 480};
  sim::GlassView glass;
  glass.face = cv::Mat(480, 640, CV_16UC1, cv::Scalar(1));
  glass.normals_c = {Eigen::Vector3f(0, 0, -1)};
  glass.mirror_m = cv::Mat::zeros(480, 640, CV_32FC1);
  auto centre = [&](float z) {
    const cv::Mat gt(480, 640, CV_32FC1, cv::Scalar(z));
    return sim::apply_depth_model(gt, K, cam, 1, 0, nullptr, &glass).at<float>(240, 320);
  };
  EXPECT_NEAR(centre(1.2f), 1.2f, 1e-3) << "within 1.54 m head on";
  EXPECT_EQ(centre(2.0f), 0.0f);
  glass.mirror_m.setTo(1.5f);
  EXPECT_NEAR(centre(2.0f), 3.5f, 1e-3) << "the mirror's image: 2 m to the glass, 1.5 m beyond";
}
