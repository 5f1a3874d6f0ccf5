#pragma once
// Small scenes the simulator tests share: a wall at an angle, a straight
// drive with a kidnap or a cover, and helpers that read frames from them.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/sim_frame_source.hpp"
#include "pvb/sim/simulator.hpp"

namespace pvb::test {

// A wall at an angle in front of the robot, noise-free sensor.
inline scenes::Scenario wall_scenario() {
  return scenes::parse_scenario(R"(
name: wall_test
seed: 3
duration_s: 4
ground: {size_m: [20, 20]}
walls: [{start_m: [2.5, -3], end_m: [4.0, 3], height_m: 3, thickness_m: 0.2}]
route: {waypoints_m: [[0, 0], [1, 0]], speed_mps: 0.3}
camera: {pitch_deg: -5, yaw_deg: 8, depth_noise: {model: none}, rgb: {sigma: 0}}
)",
                                "wall_test.yaml");
}

inline double wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }

// A straight drive towards a wall; the camera is covered from 1.5 s for
// 0.4 s (frames 45 to 56), and at frame 51 the robot is carried back to its
// state at 0.5 s (frame 15).
inline scenes::Scenario kidnap_scenario() {
  return scenes::parse_scenario(R"(
name: kidnap_test
seed: 5
duration_s: 3
ground: {size_m: [20, 20]}
walls: [{start_m: [5, -3], end_m: [5, 3], height_m: 3}]
route: {waypoints_m: [[0, 0], [3, 0]], speed_mps: 0.5}
camera: {width: 160, height: 120, fx: 131.25, fy: 131.25, depth_noise: {sunlight: off}}
kidnap: {at_s: 1.5, covered_s: 0.4, to_route_s: 0.5}
)",
                                "kidnap_test.yaml");
}

// kidnap_scenario() without the kidnap, and with a cover of the same
// frames (45 to 56) or none.
inline scenes::Scenario cover_scenario(bool covered) {
  scenes::Scenario s = kidnap_scenario();
  s.name = "cover_test";
  s.kidnap.reset();
  if (covered) s.cover = scenes::Cover{1.5, 0.4};
  return s;
}

/// Every frame of a scenario on the pipeline's path, and the ground truth.
inline std::vector<sensor::RgbdFrame> all_frames(const scenes::Scenario& s, std::vector<geom::StampedPose>* gt) {
  sim::SimFrameSource src(s, sim::GlBackend::kAuto, 0,
                          [gt](const geom::StampedPose& p) { gt->push_back(p); });
  const sim::SensorModel model = src.sensor_model();
  std::vector<sensor::RgbdFrame> frames;
  while (auto r = src.next_rendered()) frames.push_back(model.apply(std::move(*r)).frame);
  return frames;
}

/// Rotation angle between two poses, radians.
inline double angle_between(const geom::SE3d& a, const geom::SE3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

/// The wall scenario with Kinect depth noise and colour noise on (and the
/// wall in the shade: in the sun the Kinect loses it).
inline scenes::Scenario noisy_wall_scenario() {
  scenes::Scenario s = wall_scenario();
  s.camera.depth_noise.model = scenes::DepthNoiseModel::kKinect;
  s.camera.depth_noise.sunlight.on = false;
  s.camera.rgb.sigma = 2.0;
  return s;
}

/// Every frame next() gives, from a source of its own (one at a time: a
/// renderer draws in the context made current last).
inline std::vector<sensor::RgbdFrame> all_frames(const scenes::Scenario& s, int frames) {
  std::vector<sensor::RgbdFrame> out;
  sim::SimFrameSource src(s, sim::GlBackend::kAuto, frames);
  while (auto f = src.next()) out.push_back(*f);
  return out;
}

/// The same frame: index, time and every pixel of colour and depth.
inline void expect_same_frame(const sensor::RgbdFrame& got, const sensor::RgbdFrame& want) {
  EXPECT_EQ(got.index, want.index);
  EXPECT_EQ(got.t_ns, want.t_ns);
  EXPECT_EQ(cv::norm(got.rgb, want.rgb, cv::NORM_INF), 0.0) << "frame " << want.index;
  EXPECT_EQ(cv::norm(got.depth_m, want.depth_m, cv::NORM_INF), 0.0) << "frame " << want.index;
}


/// The camera's pitch (its optical axis above the horizontal) and roll (the
/// image's x axis above it), degrees, at every frame of a physics-only drive.
struct TiltTrace {
  std::vector<double> pitch_deg, roll_deg;
};

inline double std_dev(const std::vector<double>& v) {
  double mean = 0, sq = 0;
  for (double x : v) mean += x / static_cast<double>(v.size());
  for (double x : v) sq += (x - mean) * (x - mean) / static_cast<double>(v.size());
  return std::sqrt(sq);
}

/// A shipped scenario's route, driven physics only (turns and U-turns
/// included): followed closely and finished within the scenario's duration.
inline void expect_route_driven_to_its_end(const char* name) {
  sim::Simulator sim(scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + name + ".yaml"),
                     sim::SceneDetail::kGeometry);
  double worst = 0;
  int finished_at = -1;
  for (int i = 1; i < sim.frame_count(); ++i) {
    sim.advance();
    worst = std::max(worst, sim.follower().cross_track_error_m(sim.base_pose()));
    if (finished_at < 0 && sim.follower().finished()) finished_at = i;
  }
  std::printf("%s: route finished at frame %d of %d, worst cross-track error %.3f m\n", name, finished_at,
              sim.frame_count(), worst);
  EXPECT_TRUE(sim.follower().finished()) << name << ": route not finished in time";
  EXPECT_LT(worst, 0.3) << name;
  const sim::Pose2d end = sim.base_pose();
  const Eigen::Vector2d goal = sim.follower().path().back();
  EXPECT_LT((Eigen::Vector2d(end.x, end.y) - goal).norm(), 0.2) << name;
}

}  // namespace pvb::test
