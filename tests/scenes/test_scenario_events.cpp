// A scenario's events: a kidnap (the robot carried to another place of
// the route) and a cover (the lens covered, the robot not carried), read,
// optional and refused in one line naming file, line and key; the blind
// bounds that need covered frames.
#include <gtest/gtest.h>

#include <string>

#include "pvb/common/error.hpp"
#include "pvb/scenes/scenario.hpp"
#include "scenario_errors.hpp"

using namespace pvb::scenes;

using pvb::test::error_of;
using pvb::test::kMinimal;

TEST(Scenario, KidnapIsReadAndOptional) {
  EXPECT_FALSE(parse_scenario(kMinimal, "min.yaml").kidnap);
  const Scenario s =
      parse_scenario(std::string(kMinimal) + "duration_s: 60\nkidnap: {at_s: 40, to_route_s: 8}\n", "k.yaml");
  ASSERT_TRUE(s.kidnap);
  EXPECT_DOUBLE_EQ(s.kidnap->at_s, 40.0);
  EXPECT_DOUBLE_EQ(s.kidnap->covered_s, 2.0);  // the default
  EXPECT_DOUBLE_EQ(s.kidnap->to_route_s, 8.0);
  // At 30 fps: frames 1200 to 1259 are covered, 1230 is the first in the
  // new place, which is where the robot was at frame 240.
  const KidnapFrames f = kidnap_frames(*s.kidnap, 30.0);
  EXPECT_EQ(f.cover_begin, 1200);
  EXPECT_EQ(f.cover_end, 1260);
  EXPECT_EQ(f.teleport, 1230);
  EXPECT_EQ(f.target, 240);
  EXPECT_FALSE(f.covered(1199));
  EXPECT_TRUE(f.covered(1200));
  EXPECT_TRUE(f.covered(1259));
  EXPECT_FALSE(f.covered(1260));
  // Times between frames: covered from the first frame at or after at_s,
  // carried to the frame at or just before to_route_s.
  const KidnapFrames g = kidnap_frames(Kidnap{10.01, 0.5, 3.02}, 30.0);
  EXPECT_EQ(g.cover_begin, 301);
  EXPECT_EQ(g.cover_end, 316);
  EXPECT_EQ(g.teleport, 308);
  EXPECT_EQ(g.target, 90);
}

TEST(Scenario, KidnapIsValidatedWithFileAndLine) {
  const std::string base = std::string(kMinimal) + "duration_s: 20\nkidnap:\n";
  const auto err = [&](const std::string& body) { return error_of(base + body); };
  std::string e = err("  at_s: 10\n  to_route_s: 3\n  covered: 2\n");
  EXPECT_NE(e.find("bad.yaml:6: kidnap.covered: expected a known key"), std::string::npos) << e;
  e = err("  at_s: 10\n  to_route_s: 12\n");
  EXPECT_NE(e.find("bad.yaml:5: kidnap.to_route_s: expected a time at least one frame before kidnap.at_s (10 "
                   "s), got 12"),
            std::string::npos)
      << e;
  e = err("  at_s: 10\n  to_route_s: 10\n");  // the same time is not before it
  EXPECT_NE(e.find("kidnap.to_route_s: expected a time at least one frame before"), std::string::npos) << e;
  e = err("  at_s: 10\n  to_route_s: 9.99999999\n");  // on the frame of at_s
  EXPECT_NE(e.find("kidnap.to_route_s: expected a time at least one frame before"), std::string::npos) << e;
  e = err("  at_s: 17\n  covered_s: 3\n  to_route_s: 2\n");  // the cover would end with the run
  EXPECT_NE(
      e.find("bad.yaml:5: kidnap.covered_s: expected at_s + covered_s before duration_s (20 s), got 20 s"),
      std::string::npos)
      << e;
  e = err("  at_s: 19\n  to_route_s: 2\n");  // the default cover of 2 s
  EXPECT_NE(e.find("kidnap.covered_s: expected at_s + covered_s before duration_s"), std::string::npos) << e;
  e = err("  at_s: -1\n  to_route_s: 0\n");
  EXPECT_NE(e.find("bad.yaml:4: kidnap.at_s: expected a value in [0, 43200], got -1"), std::string::npos) << e;
  e = err("  at_s: 10\n  to_route_s: -2\n");
  EXPECT_NE(e.find("kidnap.to_route_s: expected a value in [0, 43200], got -2"), std::string::npos) << e;
  e = err("  at_s: 10\n  covered_s: 0\n  to_route_s: 2\n");
  EXPECT_NE(e.find("kidnap.covered_s: expected a value in"), std::string::npos) << e;
  e = err("  at_s: 10.001\n  covered_s: 0.02\n  to_route_s: 2\n");  // no frame between 10.001 and 10.021 s
  EXPECT_NE(e.find("kidnap.covered_s: expected at least one frame period"), std::string::npos) << e;
  e = err("  covered_s: 2\n  to_route_s: 2\n");
  EXPECT_NE(e.find("bad.yaml:3: kidnap.at_s: expected a time in seconds (required in kidnap)"),
            std::string::npos)
      << e;
  e = err("  at_s: 10\n");
  EXPECT_NE(e.find("kidnap.to_route_s: expected a time in seconds (required"), std::string::npos) << e;
  e = error_of(std::string(kMinimal) + "kidnap: 40\n");
  EXPECT_NE(e.find("kidnap: expected a mapping of keys"), std::string::npos) << e;
  for (const std::string& body : {err("  at_s: 10\n  to_route_s: 3\n  covered: 2\n"), err("  at_s: 10\n")})
    EXPECT_EQ(body.find('\n'), std::string::npos) << body;
}

TEST(Scenario, KidnapTimesAreJudgedByTheKeyThatIsWrong) {
  const std::string base = std::string(kMinimal) + "duration_s: 20\nkidnap:\n";
  // A cover shorter than one frame period is refused even where it happens
  // to straddle a frame boundary (10.0 s is on a frame at 30 fps).
  std::string e = error_of(base + "  at_s: 10\n  covered_s: 0.01\n  to_route_s: 2\n");
  EXPECT_NE(e.find("bad.yaml:5: kidnap.covered_s: expected at least one frame period (1 / camera.fps = 0.0333333 s), "
                   "got 0.01"),
            std::string::npos)
      << e;
  EXPECT_EQ(error_of(base + "  at_s: 10\n  covered_s: 0.0333333333\n  to_route_s: 2\n"), "");
  // A cover that starts after the run is at_s's fault, not covered_s's.
  e = error_of(base + "  at_s: 25\n  to_route_s: 2\n");
  EXPECT_NE(e.find("bad.yaml:4: kidnap.at_s: expected a time before duration_s (20 s), got 25"), std::string::npos) << e;
}

// cover: covers the lens as a kidnap does; the robot is not carried.
TEST(Scenario, CoverIsReadAndOptional) {
  const Scenario none = parse_scenario(kMinimal, "min.yaml");
  EXPECT_FALSE(none.cover);
  EXPECT_FALSE(camera_cover_frames(none));
  const Scenario s = parse_scenario(std::string(kMinimal) + "duration_s: 30\ncover: {at_s: 12}\n", "c.yaml");
  ASSERT_TRUE(s.cover);
  EXPECT_FALSE(s.kidnap);
  EXPECT_DOUBLE_EQ(s.cover->at_s, 12.0);
  EXPECT_DOUBLE_EQ(s.cover->covered_s, 2.0);  // the default, as a kidnap's
  // At 30 fps frames 360 to 419 are covered; the same frames as a kidnap's.
  const auto f = camera_cover_frames(s);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->begin, 360);
  EXPECT_EQ(f->end, 420);
  EXPECT_FALSE(f->covered(359));
  EXPECT_TRUE(f->covered(419));
  EXPECT_FALSE(f->covered(420));
  const KidnapFrames k = kidnap_frames(Kidnap{12, 2, 3}, 30.0);
  EXPECT_EQ(k.cover_begin, f->begin);
  EXPECT_EQ(k.cover_end, f->end);
  // Times between frames: from the first frame at or after at_s.
  const CoverFrames g = cover_frames(Cover{10.01, 0.5}, 30.0);
  EXPECT_EQ(g.begin, 301);
  EXPECT_EQ(g.end, 316);
  // A kidnap's covered frames are the scenario's camera cover too.
  const Scenario kidnapped =
      parse_scenario(std::string(kMinimal) + "duration_s: 60\nkidnap: {at_s: 40, to_route_s: 8}\n", "k.yaml");
  ASSERT_TRUE(camera_cover_frames(kidnapped));
  EXPECT_EQ(camera_cover_frames(kidnapped)->begin, 1200);
  EXPECT_EQ(camera_cover_frames(kidnapped)->end, 1260);
}

TEST(Scenario, CoverIsValidatedWithFileAndLine) {
  const std::string base = std::string(kMinimal) + "duration_s: 20\ncover:\n";
  const auto err = [&](const std::string& body) { return error_of(base + body); };
  std::string e = err("  at_s: 10\n  to_route_s: 3\n");  // a kidnap's key
  EXPECT_NE(e.find("bad.yaml:5: cover.to_route_s: expected a known key"), std::string::npos) << e;
  e = err("  covered_s: 2\n");
  EXPECT_NE(e.find("bad.yaml:3: cover.at_s: expected a time in seconds (required in cover)"),
            std::string::npos)
      << e;
  e = err("  at_s: 25\n");
  EXPECT_NE(e.find("bad.yaml:4: cover.at_s: expected a time before duration_s (20 s), got 25"),
            std::string::npos)
      << e;
  e = err("  at_s: -1\n");
  EXPECT_NE(e.find("bad.yaml:4: cover.at_s: expected a value in [0, 43200], got -1"), std::string::npos) << e;
  e = err("  at_s: 17\n  covered_s: 3\n");
  EXPECT_NE(
      e.find("bad.yaml:5: cover.covered_s: expected at_s + covered_s before duration_s (20 s), got 20 s"),
      std::string::npos)
      << e;
  e = err("  at_s: 19\n");  // the default cover of 2 s
  EXPECT_NE(e.find("cover.covered_s: expected at_s + covered_s before duration_s"), std::string::npos) << e;
  e = err("  at_s: 10\n  covered_s: 0.01\n");
  EXPECT_NE(
      e.find(
          "bad.yaml:5: cover.covered_s: expected at least one frame period (1 / camera.fps = 0.0333333 s), "
          "got 0.01"),
      std::string::npos)
      << e;
  e = err("  at_s: 10.001\n  covered_s: 0.02\n");  // no frame between 10.001 and 10.021 s
  EXPECT_NE(e.find("cover.covered_s: expected at least one frame period"), std::string::npos) << e;
  e = error_of(std::string(kMinimal) + "cover: 12\n");
  EXPECT_NE(e.find("cover: expected a mapping of keys"), std::string::npos) << e;
  for (const std::string& body : {err("  at_s: 10\n  to_route_s: 3\n"), err("  at_s: 25\n")})
    EXPECT_EQ(body.find('\n'), std::string::npos) << body;
}

TEST(Scenario, CoverAndKidnapAreNotBoth) {
  const std::string e = error_of(std::string(kMinimal) +
                                 "duration_s: 30\nkidnap: {at_s: 10, to_route_s: 3}\ncover: {at_s: 20}\n");
  EXPECT_NE(e.find("bad.yaml:4: cover: expected either kidnap or cover, not both"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

TEST(Scenario, BlindBoundsAreReadAndNeedCoveredFrames) {
  const std::string bounds =
      "expect:\n  blind_poses_all: true\n  blind_after_error_m_max: 0.05\n  blind_after_error_deg_max: 1\n"
      "  blind_no_global_relocalisation: true\n";
  const Scenario none = parse_scenario(kMinimal, "min.yaml");
  EXPECT_FALSE(none.expect.any_blind_bound());
  const Scenario s = parse_scenario(
      std::string(kMinimal) + "duration_s: 30\ncover: {at_s: 12, covered_s: 3}\n" + bounds, "b.yaml");
  EXPECT_TRUE(s.expect.blind_poses_all);
  EXPECT_TRUE(s.expect.blind_no_global_relocalisation);
  ASSERT_TRUE(s.expect.blind_after_error_m_max);
  EXPECT_DOUBLE_EQ(*s.expect.blind_after_error_m_max, 0.05);
  ASSERT_TRUE(s.expect.blind_after_error_deg_max);
  EXPECT_DOUBLE_EQ(*s.expect.blind_after_error_deg_max, 1.0);
  EXPECT_TRUE(s.expect.any_run_bound());
  // A kidnap's covered frames are a blind stretch too.
  EXPECT_EQ(error_of(std::string(kMinimal) + "duration_s: 30\nkidnap: {at_s: 12, to_route_s: 3}\n" + bounds),
            "");
  // Without covered frames there is nothing to bound.
  std::string e = error_of(std::string(kMinimal) + "expect:\n  blind_after_error_deg_max: 1\n");
  EXPECT_NE(
      e.find("bad.yaml:3: expect.blind_after_error_deg_max: expected a scenario with a cover: or kidnap: "
             "section"),
      std::string::npos)
      << e;
  e = error_of(std::string(kMinimal) +
               "duration_s: 30\ncover: {at_s: 12}\nexpect: {blind_after_error_m_max: 0}\n");
  EXPECT_NE(e.find("expect.blind_after_error_m_max: expected a value in"), std::string::npos) << e;
  e = error_of(std::string(kMinimal) + "duration_s: 30\ncover: {at_s: 12}\nexpect: {blind_poses_all: 3}\n");
  EXPECT_NE(e.find("expect.blind_poses_all: expected"), std::string::npos) << e;
}
