// The simulated camera on scenes built by the generator: poses against
// rendered depth, the d435 model, the frame source's frames (skipped,
// threaded, covered, kidnapped), a geometry-only scene against the full
// one, and shipped stations driven to the end of their routes.
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

TEST(Simulator, OpticalFramePoseAndDepthAgreeWithTheWallPlane) {
  sim::Simulator sim(wall_scenario());
  sim::RgbdCamera camera(sim, sim::GlBackend::kAuto);
  const sim::Capture cap = camera.capture(sim);
  const geom::SE3d& T_w_c = cap.T_w_c;

  // Optical convention: z forward along the robot heading (yaw 8 deg, pitch
  // -5 deg), y down, x right.
  const Eigen::Vector3d z_w = T_w_c.linear().col(2), y_w = T_w_c.linear().col(1), x_w = T_w_c.linear().col(0);
  const double yaw = sim.base_pose().yaw + 8.0 * M_PI / 180;
  EXPECT_NEAR(z_w.x(), std::cos(-5.0 * M_PI / 180) * std::cos(yaw), 0.01);
  EXPECT_NEAR(z_w.z(), std::sin(-5.0 * M_PI / 180), 0.01);
  EXPECT_LT(y_w.z(), -0.99);  // y points down
  EXPECT_LT(x_w.dot(Eigen::Vector3d(-std::sin(yaw), std::cos(yaw), 0)), -0.99);  // x points right
  EXPECT_NEAR(T_w_c.translation().z(), 0.8, 0.01);  // mount height

  // Wall face towards the robot.
  const Eigen::Vector2d a(2.5, -3), b(4.0, 3);
  const Eigen::Vector2d d = (b - a).normalized();
  Eigen::Vector2d n(d.y(), -d.x());
  if (n.dot(-a) < 0) n = -n;  // towards the origin
  const Eigen::Vector3d n3(n.x(), n.y(), 0);
  const Eigen::Vector3d p0(a.x() + 0.1 * n.x(), a.y() + 0.1 * n.y(), 0);
  const geom::PinholeIntrinsics K = sim.intrinsics();
  int checked = 0;
  double worst = 0;
  for (int r = 0; r < K.height; r += 5)
    for (int c = 0; c < K.width; c += 5) {
      // predicted depth: intersect the pixel's ray with the face plane
      const Eigen::Vector3d ray_c((c - K.cx) / K.fx, (r - K.cy) / K.fy, 1.0);
      const Eigen::Vector3d ray_w = T_w_c.linear() * ray_c;
      const double t = n3.dot(p0 - T_w_c.translation()) / n3.dot(ray_w);
      const Eigen::Vector3d hit = T_w_c.translation() + t * ray_w;
      const double along = (Eigen::Vector2d(hit.x(), hit.y()) - a).dot(d);
      if (t <= 0 || hit.z() < 0.1 || hit.z() > 2.8 || along < 0.3 || along > (b - a).norm() - 0.3) continue;
      const float z = cap.depth_gt_m.at<float>(r, c);
      ASSERT_GT(z, 0) << r << "," << c;
      worst = std::max(worst, std::abs(z - t));
      ++checked;
    }
  EXPECT_GT(checked, 2000);
  EXPECT_LT(worst, 2e-4);
  // noise-free model within range: sensor depth is ground truth on the
  // output grid (0.2 mm steps), so within half a step
  EXPECT_NEAR(cap.frame.depth_m.at<float>(240, 320), cap.depth_gt_m.at<float>(240, 320),
              0.5 / sensor::kTumDepthFactor + 1e-6);
  EXPECT_NE(cap.frame.depth_m.at<float>(240, 320), 0.0f);
}

// The d435 model end to end on the default station: two infrared renders,
// matching, registration; the depth agrees with the rendered truth.
TEST(Simulator, TheD435ModelsDepthAgreesWithTheTruthOnTheStation) {
  scenes::Scenario s = scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml");
  s.camera.model = scenes::CameraKind::kD435;
  s.camera.use_d435_colour_camera();
  sim::Simulator sim(s);
  sim::RgbdCamera camera(sim, sim::GlBackend::kAuto);
  for (int i = 0; i < 30; ++i) sim.advance();
  sim::RenderedFrame rendered = camera.render(sim);
  ASSERT_TRUE(rendered.stereo.has_value());
  EXPECT_EQ(rendered.stereo->left.grey.cols, 848);
  const sim::Capture cap = camera.sensor_model().apply(std::move(rendered));
  EXPECT_GT(cap.stereo.match_ms, 0.0);
  int in_range = 0, valid = 0;
  std::vector<double> rel;
  for (int r = 0; r < 480; r += 4)
    for (int c = 0; c < 640; c += 4) {
      const float zt = cap.depth_gt_m.at<float>(r, c), z = cap.frame.depth_m.at<float>(r, c);
      if (zt < 0.5f || zt > 4.5f) continue;
      ++in_range;
      if (z <= 0) continue;
      ++valid;
      rel.push_back(std::abs(z - zt) / zt);
    }
  ASSERT_GT(in_range, 5000);
  EXPECT_GT(static_cast<double>(valid) / in_range, 0.8);
  std::nth_element(rel.begin(), rel.begin() + static_cast<std::ptrdiff_t>(rel.size() / 2), rel.end());
  EXPECT_LT(rel[rel.size() / 2], 0.03) << "median relative depth error";
}

// A scene built for its geometry only (no texture drawn) moves as the full
// scene does, bit for bit, and renders the same depth and geom ids; it
// gives no colour frames.
TEST(Simulator, AGeometryOnlySceneMovesAndRendersAsTheFullOne) {
  const scenes::Scenario s = scenes::parse_scenario(R"(
name: geometry_test
seed: 4
duration_s: 1
ground: {size_m: [20, 20]}
pv_arrays: [{origin_m: [2, -1], rows: 1, tables_per_row: 1, panels_per_table: 4}]
walls: [{start_m: [5, -3], end_m: [5, 3], height_m: 2}]
vegetation: {shrubs: 4, area_m: [-5, -5, 5, 5]}
route: {waypoints_m: [[0, 0], [1.5, 0]], speed_mps: 0.5}
camera: {width: 160, height: 120, fx: 131.25, fy: 131.25, depth_noise: {sunlight: off}}
)",
                                                    "geometry_test.yaml");
  sim::Simulator full(s), geometry(s, sim::SceneDetail::kGeometry);
  EXPECT_EQ(full.assets().xml, geometry.assets().xml);
  ASSERT_EQ(full.assets().files.size(), geometry.assets().files.size());
  for (int i = 1; i < full.frame_count(); ++i) {
    full.advance();
    geometry.advance();
    ASSERT_TRUE(full.T_w_c().matrix() == geometry.T_w_c().matrix()) << "frame " << i;
  }
  sim::Renderer a(full.model(), sim::GlBackend::kAuto, 160, 120), b(geometry.model(), sim::GlBackend::kAuto, 160, 120);
  cv::Mat rgb_a, depth_a, ids_a, rgb_b, depth_b, ids_b;
  a.render(full.model(), full.data(), full.camera_id(), &rgb_a, &depth_a);
  a.render_geom_ids(full.model(), full.data(), full.camera_id(), &ids_a);
  b.render(geometry.model(), geometry.data(), geometry.camera_id(), &rgb_b, &depth_b);
  b.render_geom_ids(geometry.model(), geometry.data(), geometry.camera_id(), &ids_b);
  EXPECT_EQ(cv::norm(depth_a, depth_b, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(ids_a, ids_b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(rgb_a, rgb_b, cv::NORM_INF), 0.0);  // the textures are not there
  EXPECT_THROW(sim::RgbdCamera(geometry, sim::GlBackend::kAuto), Error);
}

TEST(SimFrameSource, StreamsFramesWithGroundTruthThroughItsOwnSink) {
  std::vector<geom::StampedPose> gt;
  sim::SimFrameSource src(wall_scenario(), sim::GlBackend::kAuto, 5,
                          [&gt](const geom::StampedPose& p) { gt.push_back(p); });
  EXPECT_EQ(src.size_hint(), 5u);
  std::vector<sensor::RgbdFrame> frames;
  while (auto f = src.next()) frames.push_back(*f);
  ASSERT_EQ(frames.size(), 5u);
  ASSERT_EQ(gt.size(), 5u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].index, i);
    EXPECT_EQ(frames[i].t_ns, gt[i].t_ns);
    EXPECT_EQ(frames[i].t_ns, geom::frame_time_ns(0, static_cast<std::int64_t>(i), 30.0));
    EXPECT_EQ(frames[i].rgb.type(), CV_8UC3);
    EXPECT_EQ(frames[i].depth_m.type(), CV_32FC1);
  }
  EXPECT_FALSE(src.next().has_value());
  EXPECT_NE(src.describe().find("sim:wall_test"), std::string::npos);
}

// pvbench vocab renders only the frames it uses: skip() advances the
// physics without rendering, and the frames rendered are those next() gives.
TEST(SimFrameSource, SkippedFramesLeaveTheOthersAsNextGivesThem) {
  const scenes::Scenario s = noisy_wall_scenario();
  constexpr int kFrames = 5;
  const std::vector<sensor::RgbdFrame> all = all_frames(s, kFrames);
  ASSERT_EQ(all.size(), static_cast<std::size_t>(kFrames));
  std::vector<sensor::RgbdFrame> every_other;
  {
    sim::SimFrameSource src(s, sim::GlBackend::kAuto, kFrames);
    for (int i = 0; i < kFrames; ++i) {
      if (i % 2 == 1) {
        EXPECT_TRUE(src.skip());
      } else if (auto f = src.next()) {
        every_other.push_back(*f);
      }
    }
    EXPECT_FALSE(src.skip());  // past the last frame
  }
  ASSERT_EQ(every_other.size(), 3u);
  for (std::size_t k = 0; k < every_other.size(); ++k) expect_same_frame(every_other[k], all[2 * k]);
}

// The run's pipeline renders on one thread and applies the sensor model on
// another: that must give exactly the frames next() gives, noise included.
TEST(SimFrameSource, SensorModelOnAnotherThreadGivesTheFramesOfNext) {
  const scenes::Scenario s = noisy_wall_scenario();
  constexpr int kFrames = 4;
  const std::vector<sensor::RgbdFrame> direct = all_frames(s, kFrames);
  std::vector<geom::StampedPose> gt;
  std::vector<sim::RenderedFrame> rendered;
  std::optional<sim::SensorModel> model;
  {
    sim::SimFrameSource src(s, sim::GlBackend::kAuto, kFrames,
                            [&gt](const geom::StampedPose& p) { gt.push_back(p); });
    while (auto r = src.next_rendered()) rendered.push_back(std::move(*r));
    model = src.sensor_model();  // a copy outlives the source and its simulator
  }
  ASSERT_EQ(rendered.size(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(gt.size(), rendered.size());  // ground truth leaves at render time
  std::vector<sensor::RgbdFrame> split;
  std::thread worker([&] {
    for (auto& r : rendered) split.push_back(model->apply(std::move(r)).frame);
  });
  worker.join();
  ASSERT_EQ(split.size(), direct.size());
  for (std::size_t i = 0; i < split.size(); ++i) {
    expect_same_frame(split[i], direct[i]);
    EXPECT_EQ(split[i].t_ns, gt[i].t_ns);
    EXPECT_GT(cv::countNonZero(split[i].depth_m), 1000) << "frame " << i;
  }
  // The noise differs from frame to frame (seeded by the frame index).
  EXPECT_GT(cv::norm(split[1].depth_m, split[2].depth_m, cv::NORM_INF), 0.0);
}

// The covered frames are what a covered lens gives, on the pipeline's path
// (render, then a copy of the sensor model on the frame): black colour with
// the sensor's noise and no depth; the frames around them are ordinary, and
// the ground truth jumps with the robot.
TEST(SimFrameSource, KidnapCoversTheCameraAndTheGroundTruthFollowsTheCarry) {
  std::vector<geom::StampedPose> gt;
  sim::SimFrameSource src(kidnap_scenario(), sim::GlBackend::kAuto, 0,
                          [&gt](const geom::StampedPose& p) { gt.push_back(p); });
  const sim::SensorModel model = src.sensor_model();
  const scenes::KidnapFrames k = *src.simulator().kidnap_frames();
  std::vector<sensor::RgbdFrame> frames;
  while (auto r = src.next_rendered()) frames.push_back(model.apply(std::move(*r)).frame);
  ASSERT_EQ(frames.size(), 91u);
  ASSERT_EQ(gt.size(), frames.size());
  int covered = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const sensor::RgbdFrame& f = frames[i];
    EXPECT_EQ(f.index, i);
    EXPECT_EQ(f.t_ns, geom::frame_time_ns(0, static_cast<std::int64_t>(i), 30.0));
    const double mean_rgb = cv::mean(f.rgb.reshape(1))[0];
    const int valid_depth = cv::countNonZero(f.depth_m);
    if (k.covered(static_cast<std::int64_t>(i))) {
      ++covered;
      EXPECT_EQ(valid_depth, 0) << "frame " << i;
      EXPECT_LT(mean_rgb, 2.0) << "frame " << i;
      EXPECT_GT(mean_rgb, 0.0) << "frame " << i << ": the sensor noise stays";
    } else {
      EXPECT_GT(valid_depth, f.depth_m.total() / 2) << "frame " << i;
      EXPECT_GT(mean_rgb, 40.0) << "frame " << i;
    }
  }
  EXPECT_EQ(covered, 12);  // 1.5 s to 1.9 s at 30 Hz
  EXPECT_LT((gt[k.teleport].T_w_c.translation() - gt[k.target].T_w_c.translation()).norm(), 1e-3);
  // carried back over the covered frames: far in all, never far from one frame to the next
  EXPECT_GT((gt[k.cover_begin].T_w_c.translation() - gt[k.teleport].T_w_c.translation()).norm(), 0.4);
  for (int i = k.cover_begin + 1; i <= k.teleport; ++i)
    EXPECT_LT((gt[i].T_w_c.translation() - gt[i - 1].T_w_c.translation()).norm(), 0.25) << i;
}

// A cover blinds the camera exactly as a kidnap does (the same black,
// noisy colour and no depth on the same frames), but the robot drives on:
// the ground truth and every uncovered frame are those of the same
// scenario without a cover, bit for bit.
TEST(SimFrameSource, CoverBlindsTheCameraWhileTheRobotDrivesOn) {
  std::vector<geom::StampedPose> gt_cover, gt_plain, gt_kidnap;
  const std::vector<sensor::RgbdFrame> cover = all_frames(cover_scenario(true), &gt_cover);
  const std::vector<sensor::RgbdFrame> plain = all_frames(cover_scenario(false), &gt_plain);
  const std::vector<sensor::RgbdFrame> kidnap = all_frames(kidnap_scenario(), &gt_kidnap);
  EXPECT_FALSE(sim::Simulator(cover_scenario(true)).kidnap_frames()) << "nobody carries the robot";
  ASSERT_EQ(cover.size(), 91u);
  ASSERT_EQ(plain.size(), cover.size());
  ASSERT_EQ(gt_cover.size(), cover.size());
  const scenes::CoverFrames c = *scenes::camera_cover_frames(cover_scenario(true));
  ASSERT_EQ(c.begin, 45);
  ASSERT_EQ(c.end, 57);
  for (std::size_t i = 0; i < cover.size(); ++i) {
    EXPECT_TRUE(gt_cover[i].T_w_c.matrix() == gt_plain[i].T_w_c.matrix()) << "frame " << i;
    if (c.covered(static_cast<std::int64_t>(i))) {
      EXPECT_EQ(cv::countNonZero(cover[i].depth_m), 0) << "frame " << i;
      EXPECT_EQ(cv::norm(cover[i].rgb, kidnap[i].rgb, cv::NORM_INF), 0.0)
          << "frame " << i << ": a kidnap's cover";
      EXPECT_GT(cv::norm(cover[i].rgb, plain[i].rgb, cv::NORM_INF), 100.0) << "frame " << i;
    } else {
      EXPECT_EQ(cv::norm(cover[i].rgb, plain[i].rgb, cv::NORM_INF), 0.0) << "frame " << i;
      EXPECT_EQ(cv::norm(cover[i].depth_m, plain[i].depth_m, cv::NORM_INF), 0.0) << "frame " << i;
    }
  }
  // It drives on through the cover, about 0.5 m/s x 0.4 s, without a jump.
  const auto t = [&](int i) { return gt_cover[static_cast<std::size_t>(i)].T_w_c.translation(); };
  EXPECT_GT((t(c.end) - t(c.begin - 1)).norm(), 0.15);
  for (int i = c.begin; i <= c.end; ++i) EXPECT_LT((t(i) - t(i - 1)).norm(), 0.03) << i;
}

// The robot settles on the relief on its wheels and caster, drives the
// whole route of rough_station, and pitches and rolls with the ground: far
// more than on pv_station's flat ground, the same route.
TEST(Simulator, SettlesOnTheReliefAndDrivesRoughStationToItsEnd) {
  std::map<std::string, TiltTrace> traces;
  for (const char* name : {"pv_station", "rough_station"}) {
    const scenes::Scenario s = scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + name + ".yaml");
    const scenes::GroundRelief relief(s);
    sim::Simulator sim(s, sim::SceneDetail::kGeometry);
    const int body = mj_name2id(sim.model(), mjOBJ_BODY, sim::kRobotBody);
    const mjtNum* axle = sim.data()->xpos + 3 * body;
    EXPECT_NEAR(axle[2] - relief.height_m(axle[0], axle[1]), s.robot.wheel_radius_m, 0.01) << name << ": settled";
    EXPECT_LT(mju_norm3(sim.data()->cvel + 6 * body + 3), 0.01) << name << ": at rest before it drives";
    double worst = 0;
    TiltTrace& trace = traces[name];
    for (int i = 1; i < sim.frame_count(); ++i) {
      sim.advance();
      worst = std::max(worst, sim.follower().cross_track_error_m(sim.base_pose()));
      const Eigen::Matrix3d R = sim.T_w_c().linear();
      trace.pitch_deg.push_back(std::asin(R(2, 2)) * 180 / M_PI);
      trace.roll_deg.push_back(std::asin(R(2, 0)) * 180 / M_PI);
    }
    EXPECT_TRUE(sim.follower().finished()) << name << ": route not finished in time";
    EXPECT_LT(worst, 0.3) << name;
    const sim::Pose2d end = sim.base_pose();
    EXPECT_LT((Eigen::Vector2d(end.x, end.y) - sim.follower().path().back()).norm(), 0.2) << name;
    std::printf("%s: camera pitch std %.3f deg, roll std %.3f deg, worst cross-track error %.3f m\n", name,
                std_dev(trace.pitch_deg), std_dev(trace.roll_deg), worst);
  }
  const TiltTrace &flat = traces["pv_station"], &rough = traces["rough_station"];
  EXPECT_GT(std_dev(rough.pitch_deg), 0.3);
  EXPECT_GT(std_dev(rough.roll_deg), 0.3);
  EXPECT_GT(std_dev(rough.pitch_deg), 5 * std_dev(flat.pitch_deg));
  EXPECT_GT(std_dev(rough.roll_deg), 5 * std_dev(flat.roll_deg));
}

// Every shipped route, physics only: about 10 s on 2 cores.
TEST(Simulator, ShippedScenariosAreDrivenToTheEndOfTheirRoutes) {
  for (const char* name : {"pv_station", "along_row", "lawnmower", "loop", "aliasing", "lawnmower_return"})
    expect_route_driven_to_its_end(name);
}
