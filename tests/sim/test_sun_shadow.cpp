#include <gtest/gtest.h>

#include <string>

#include "mjcf_scene.hpp"
#include "pvb/sim/sun_shadow.hpp"

using namespace pvb;

namespace {

using Scene = pvb::test::MjcfScene;

// A ground plane, a 2 x 2 m roof 1 m up and a ball hidden from drawing
// (group 3), from MuJoCo's own parser.
Scene roof_scene() {
  static const std::string xml = R"(<mujoco><worldbody>
    <geom type="plane" size="10 10 1"/>
    <geom type="box" pos="0 0 1" size="1 1 0.02"/>
    <geom type="sphere" pos="4 0 1" size="0.5" group="3"/>
  </worldbody></mujoco>)";
  Scene s = pvb::test::load_mjcf(xml);
  EXPECT_TRUE(s.m) << s.error;
  return s;
}

}  // namespace

TEST(SunShadow, ARoofShadesTheGroundUnderItAlongTheSunsDirection) {
  const Scene s = roof_scene();
  ASSERT_TRUE(s.m);
  const sim::SunShadowCaster overhead(s.m.get(), s.d.get(), Eigen::Vector3d(0, 0, 1));
  EXPECT_TRUE(overhead.shadowed({0.5, 0.5, 0}));
  EXPECT_FALSE(overhead.shadowed({1.5, 0, 0}));
  EXPECT_FALSE(overhead.shadowed({0, 0, 1.1}));  // on the roof
  EXPECT_FALSE(overhead.shadowed({4, 0, 0}));    // under the undrawn ball
  // A sun 45 degrees up in +x: the shadow moves 1 m towards -x.
  const sim::SunShadowCaster low(s.m.get(), s.d.get(), Eigen::Vector3d(1, 0, 1));
  EXPECT_TRUE(low.shadowed({-1.5, 0, 0}));
  EXPECT_FALSE(low.shadowed({0.5, 0, 0}));
}

TEST(SunShadow, VisibilityOnBlocksEqualsEveryPixelTested) {
  const Scene s = roof_scene();
  ASSERT_TRUE(s.m);
  const sim::SunShadowCaster caster(s.m.get(), s.d.get(), Eigen::Vector3d(0.3, 0.2, 1));
  // A camera 3 m above the ground looking straight down.
  const geom::PinholeIntrinsics K{200, 200, 79.5, 59.5, 160, 120};
  const geom::SE3d T_w_c =
      geom::make_se3(geom::so3_exp(Eigen::Vector3d(M_PI, 0, 0)), Eigen::Vector3d(0.5, 0, 3));
  cv::Mat depth(120, 160, CV_32FC1, cv::Scalar(3.0f));
  depth(cv::Rect(0, 0, 20, 10)).setTo(0.0f);  // a hole: no depth, not lit
  const cv::Mat blocks = sim::sun_visibility(caster, depth, K, T_w_c);
  const cv::Mat every = sim::sun_visibility(caster, depth, K, T_w_c, 1);
  EXPECT_EQ(cv::countNonZero(blocks != every), 0);
  EXPECT_EQ(cv::countNonZero(blocks(cv::Rect(0, 0, 20, 10))), 0);
  const int lit = cv::countNonZero(every);
  EXPECT_GT(lit, 1000);                    // the open ground
  EXPECT_LT(lit, 160 * 120 - 200 - 1000);  // and the roof's shadow
  // Points deeper than asked for are not lit.
  EXPECT_EQ(cv::countNonZero(sim::sun_visibility(caster, depth, K, T_w_c, 16, 2.5f)), 0);
}

TEST(SunShadow, ARegionLeavesOutOnlyGeomsThatCannotShadeItsPoints) {
  // A row of roofs 1 m up, 3 m apart; a sun 45 degrees up in +x.
  std::string xml = "<mujoco><worldbody><geom type=\"plane\" size=\"50 50 1\"/>";
  for (int k = -10; k <= 10; ++k)
    xml += "<geom type=\"box\" pos=\"" + std::to_string(3 * k) + " 0 1\" size=\"0.5 0.5 0.02\"/>";
  xml += "</worldbody></mujoco>";
  const Scene s = pvb::test::load_mjcf(xml);
  ASSERT_TRUE(s.m) << s.error;
  const Eigen::Vector3d sun(1, 0, 1);
  const sim::SunShadowCaster all(s.m.get(), s.d.get(), sun);
  const sim::ShadeRegion region{Eigen::Vector3d(0.5, 0, 0.5), 2.0};
  const sim::SunShadowCaster near(s.m.get(), s.d.get(), sun, region);
  int shaded = 0;
  for (double x = -1.5; x <= 2.5; x += 0.05)
    for (double y = -1.5; y <= 1.5; y += 0.25) {
      const Eigen::Vector3d p(x, y, 0);
      if ((p - region.centre_w).norm() > region.radius_m) continue;
      EXPECT_EQ(near.shadowed(p), all.shadowed(p)) << p.transpose();
      shaded += all.shadowed(p) ? 1 : 0;
    }
  EXPECT_GT(shaded, 10);  // the roofs at 0 and 3 m shade the region
  // Far outside the region the roof that shades a point was left out.
  EXPECT_TRUE(all.shadowed({-25, 0, 0}));
  EXPECT_FALSE(near.shadowed({-25, 0, 0}));
}
