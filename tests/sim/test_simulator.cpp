// The simulated robot: pose conventions, driving, route following, the
// kidnap's carry and determinism, physics only (scenes built for their
// geometry: no texture drawn, nothing rendered).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <optional>
#include <thread>
#include <algorithm>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sensor/depth_encoding.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/sim_frame_source.hpp"
#include "pvb/sim/simulator.hpp"
#include "sim_scenarios.hpp"

using namespace pvb;
using namespace pvb::test;

TEST(Simulator, DrivesStraight) {
  sim::Simulator sim(wall_scenario(), sim::SceneDetail::kGeometry);
  const sim::Pose2d p0 = sim.base_pose();
  const double w = 4.0;
  sim.set_wheel_override(Eigen::Vector2d(w, w));
  for (int i = 0; i < 90; ++i) sim.advance();  // 3 s
  const sim::Pose2d p1 = sim.base_pose();
  const Eigen::Vector2d dir(std::cos(p0.yaw), std::sin(p0.yaw));
  const Eigen::Vector2d delta(p1.x - p0.x, p1.y - p0.y);
  const double along = delta.dot(dir);
  const double lateral = std::abs(delta.x() * dir.y() - delta.y() * dir.x());
  // accelerates from rest: close to the calibrated speed over 3 s
  EXPECT_GT(along, 0.9 * 3.0 * w * sim.kinematics().wheel_radius_m);
  EXPECT_LT(along, 1.01 * 3.0 * w * sim.kinematics().wheel_radius_m);
  EXPECT_LT(lateral, 0.01);
  EXPECT_LT(std::abs(wrap(p1.yaw - p0.yaw)), 0.5 * M_PI / 180);
}

TEST(Simulator, TurnsAtTheCalibratedRate) {
  sim::Simulator sim(wall_scenario(), sim::SceneDetail::kGeometry);
  const sim::DriveKinematics& k = sim.kinematics();
  // calibration sees the scrub: the effective track is wider than the geometric one
  EXPECT_GT(k.track_m, 0.42);
  EXPECT_LT(k.track_m, 0.42 * 1.5);
  const double v = 0.2, omega = 0.5;  // arc of radius 0.4 m
  sim.set_wheel_override(k.wheel_speeds(v, omega));
  for (int i = 0; i < 15; ++i) sim.advance();  // reach steady state
  const double yaw0 = sim.base_pose().yaw;
  for (int i = 0; i < 60; ++i) sim.advance();  // 2 s
  const double turned = wrap(sim.base_pose().yaw - yaw0);
  EXPECT_NEAR(turned, omega * 2.0, 0.05 * omega * 2.0);
}

TEST(Simulator, RouteFollowerReachesItsWaypoints) {
  scenes::Scenario s = scenes::parse_scenario(
      "duration_s: 40\nground: {size_m: [30, 30]}\n"
      "route: {waypoints_m: [[0, 0], [4, 0], [5, 2.5], [2, 4], [-1, 2]], speed_mps: 0.5, lookahead_m: 0.6}\n",
      "route_test.yaml");
  sim::Simulator sim(s, sim::SceneDetail::kGeometry);
  std::vector<double> closest(s.route.waypoints_m.size(), 1e9);
  double worst_cross_track = 0;
  for (int i = 1; i < sim.frame_count() && !sim.follower().finished(); ++i) {
    sim.advance();
    const sim::Pose2d p = sim.base_pose();
    for (std::size_t w = 0; w < closest.size(); ++w)
      closest[w] = std::min(closest[w], (Eigen::Vector2d(p.x, p.y) - s.route.waypoints_m[w]).norm());
    worst_cross_track = std::max(worst_cross_track, sim.follower().cross_track_error_m(p));
  }
  EXPECT_TRUE(sim.follower().finished());
  for (std::size_t w = 0; w < closest.size(); ++w) EXPECT_LT(closest[w], 0.15) << "waypoint " << w;
  EXPECT_LT(worst_cross_track, 0.25);
}

// A session may start part-way along its route (route.start_m): the robot
// stands there, heading along the route, and drives the rest of it.
TEST(Simulator, RouteStartPartWayPutsTheRobotThereAndDrivesOn) {
  const std::string route =
      "duration_s: 12\nground: {size_m: [30, 30]}\n"
      "route: {waypoints_m: [[0, 0], [4, 0], [4, 4]], speed_mps: 0.5, lookahead_m: 0.6";
  const scenes::Scenario whole = scenes::parse_scenario(route + "}\n", "whole.yaml");
  const scenes::Scenario later = scenes::parse_scenario(route + ", start_m: 5}\n", "later.yaml");
  sim::Simulator a(whole, sim::SceneDetail::kGeometry), b(later, sim::SceneDetail::kGeometry);
  const sim::Pose2d p0 = a.base_pose(), p1 = b.base_pose();
  EXPECT_NEAR(p0.x, 0.0, 0.05);
  EXPECT_NEAR(p0.y, 0.0, 0.05);
  EXPECT_NEAR(p1.x, 4.0, 0.05);  // 5 m along: 4 m east, then 1 m north
  EXPECT_NEAR(p1.y, 1.0, 0.05);
  EXPECT_NEAR(p1.yaw, M_PI / 2, 0.05);  // heading north
  for (int i = 1; i < b.frame_count() && !b.follower().finished(); ++i) b.advance();
  EXPECT_TRUE(b.follower().finished());
  EXPECT_NEAR(b.base_pose().y, 4.0, 0.2);
  // Beyond the route's end, less 1 m, is refused where it is written.
  try {
    scenes::parse_scenario(route + ", start_m: 7.5}\n", "far.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("far.yaml:3: route.start_m: expected a distance at least 1 m before the "
                                         "route's end (8.00 m long), got 7.5"),
              std::string::npos)
        << e.what();
  }
}

TEST(Simulator, FrameTimesAreExactMultiplesOfThePeriod) {
  sim::Simulator sim(wall_scenario(), sim::SceneDetail::kGeometry);
  for (int i = 0; i < 4; ++i) sim.advance();
  EXPECT_EQ(sim.t_ns(), 133'333'333);  // 4 / 30 s
  EXPECT_NEAR(sim.assets().timestep_s * sim.assets().substeps, 1.0 / 30.0, 1e-15);
}

TEST(Simulator, PhysicsIsDeterministic) {
  sim::Simulator a(wall_scenario(), sim::SceneDetail::kGeometry), b(wall_scenario(), sim::SceneDetail::kGeometry);
  for (int i = 0; i < 60; ++i) {
    a.advance();
    b.advance();
  }
  EXPECT_EQ(a.base_pose().x, b.base_pose().x);
  EXPECT_EQ(a.base_pose().yaw, b.base_pose().yaw);
  EXPECT_TRUE(a.T_w_c().matrix() == b.T_w_c().matrix());
}

// The kidnap happens in the simulator: the robot is carried over the first
// half of the cover, and at the teleport frame it is in
// its exact state of the target frame (pose, velocities, the follower's
// progress) and drives the route on from there, as it did then.
TEST(Simulator, KidnapCarriesTheRobotBackToItsEarlierStateAndItDrivesOn) {
  sim::Simulator sim(kidnap_scenario(), sim::SceneDetail::kGeometry);
  ASSERT_TRUE(sim.kidnap_frames());
  const scenes::KidnapFrames k = *sim.kidnap_frames();
  ASSERT_EQ(k.target, 15);
  ASSERT_EQ(k.teleport, 51);
  std::vector<geom::SE3d> T_w_c{sim.T_w_c()};
  std::vector<sim::Pose2d> base{sim.base_pose()};
  std::vector<std::size_t> progress{sim.follower().progress_index()};
  for (int i = 1; i < sim.frame_count(); ++i) {
    sim.advance();
    EXPECT_EQ(sim.t_ns(), geom::frame_time_ns(0, i, 30.0)) << "time goes on at the frame rate";
    T_w_c.push_back(sim.T_w_c());
    base.push_back(sim.base_pose());
    progress.push_back(sim.follower().progress_index());
  }
  const auto t = [&](int i) { return T_w_c[static_cast<std::size_t>(i)].translation(); };
  // carried back about 0.5 m/s x 1.2 s over the covered frames before the
  // teleport frame: lifted, and no jump between two frames
  EXPECT_GT((t(k.cover_begin) - t(k.teleport)).norm(), 0.4);
  EXPECT_LT((t(k.cover_begin) - t(k.cover_begin - 1)).norm(), 0.03);  // the frames before: an ordinary drive
  double top_m = t(k.cover_begin).z();
  for (int i = k.cover_begin + 1; i <= k.teleport; ++i) {
    EXPECT_LT((t(i) - t(i - 1)).norm(), 0.25) << i;
    top_m = std::max(top_m, t(i).z());
  }
  EXPECT_GT(top_m - t(k.cover_begin).z(), 0.2);
  // just after the teleport: the ground truth of the target frame
  EXPECT_LT((t(k.teleport) - t(k.target)).norm(), 1e-3);
  EXPECT_LT(angle_between(T_w_c[k.teleport], T_w_c[k.target]), 1e-6);
  EXPECT_NEAR(wrap(base[k.teleport].yaw - base[k.target].yaw), 0.0, 1e-9);
  EXPECT_EQ(progress[k.teleport], progress[k.target]);
  EXPECT_LT(progress[k.teleport], progress[k.teleport - 1]);
  // and on from there as it drove then (velocities kept): frame teleport + j is frame target + j
  for (int j = 1; j <= 15; ++j) {
    EXPECT_LT((t(k.teleport + j) - t(k.target + j)).norm(), 1e-3) << j;
    EXPECT_LT(angle_between(T_w_c[k.teleport + j], T_w_c[k.target + j]), 1e-5) << j;
  }
  // the route goes on: the robot moves on past where it was taken from
  const std::size_t last = T_w_c.size() - 1;
  EXPECT_GT(base[last].x - base[k.teleport].x, 0.5);  // 1.3 s at 0.5 m/s
  EXPECT_GT(progress[last], progress[k.teleport - 1]);
}

TEST(Simulator, KidnapIsDeterministic) {
  sim::Simulator a(kidnap_scenario(), sim::SceneDetail::kGeometry), b(kidnap_scenario(), sim::SceneDetail::kGeometry);
  for (int i = 1; i < a.frame_count(); ++i) {
    a.advance();
    b.advance();
    ASSERT_TRUE(a.T_w_c().matrix() == b.T_w_c().matrix()) << "frame " << i;
  }
}

// The soil's friction is felt: from standstill at full wheel speed, the
// wheels of the same station spin more on wet earth than on dry.
TEST(Simulator, WetSoilSlipsMoreThanDryUnderFullThrottle) {
  std::map<std::string, double> slip;
  for (const char* day : {"rough_station_dry", "rough_station_wet"}) {
    scenes::Scenario s = scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/days/" + day + ".yaml");
    s.robot.max_wheel_accel_radps2.reset();  // full throttle at once
    s.ground.softness = 0;                   // the friction alone
    sim::Simulator sim(s, sim::SceneDetail::kGeometry);
    const int joint = mj_name2id(sim.model(), mjOBJ_JOINT, sim::kLeftActuator);
    ASSERT_GE(joint, 0);
    const double angle0 = sim.data()->qpos[sim.model()->jnt_qposadr[joint]];
    const sim::Pose2d p0 = sim.base_pose();
    sim.set_wheel_override(Eigen::Vector2d(s.robot.max_wheel_speed_radps, s.robot.max_wheel_speed_radps));
    for (int i = 0; i < 10; ++i) sim.advance();  // a third of a second
    const double turned_m = (sim.data()->qpos[sim.model()->jnt_qposadr[joint]] - angle0) * s.robot.wheel_radius_m;
    const sim::Pose2d p1 = sim.base_pose();
    slip[day] = 1.0 - std::hypot(p1.x - p0.x, p1.y - p0.y) / turned_m;
    std::printf("%s: friction %.2f, wheel slip %.3f over %.3f m of tread\n", day, *s.ground.friction, slip[day], turned_m);
  }
  EXPECT_GT(slip["rough_station_wet"], slip["rough_station_dry"] + 0.05);
}
