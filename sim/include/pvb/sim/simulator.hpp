#pragma once
// The simulated station: physics of the robot following its route, and the
// RGB-D camera on its mast.  Ground truth is read from here by the harness;
// it never travels with the frames.
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>

#include "pvb/geometry/pinhole.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sensor/rgbd_frame.hpp"
#include "pvb/sim/active_stereo.hpp"
#include "pvb/sim/ground_stream.hpp"
#include "pvb/sim/motion_sensors.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/robot.hpp"
#include "pvb/sim/scene_builder.hpp"

namespace pvb::sim {

class CarryPath;

class Simulator {
 public:
  /// Generates and compiles the scene, calibrates the drive kinematics and
  /// lets the robot settle on the ground.  Frame 0 is the settled state.
  /// A geometry-only scene (SceneDetail::kGeometry) moves exactly as the
  /// full one and renders the same depth, but gives no colour frames
  /// (RgbdCamera refuses it).
  explicit Simulator(scenes::Scenario scenario, SceneDetail detail = SceneDetail::kFull);
  ~Simulator();
  Simulator(Simulator&&) = delete;

  /// Frames in the scenario (duration x fps + 1).
  int frame_count() const { return scenes::frame_count(scenario_); }
  /// Index of the frame the current state belongs to.
  int frame_index() const { return frame_; }
  /// Time of the current frame: exactly frame_index / fps.
  std::int64_t t_ns() const;
  /// Advances the physics by one camera period, steering at camera rate.
  /// With a kidnap (scenario `kidnap:`), the robot is lifted at the first
  /// covered frame and carried, its wheels still, along a smooth path to the
  /// state kept at frame kidnap_frames()->target, which it reaches at frame
  /// kidnap_frames()->teleport with that state's velocities; from there it
  /// is that state (pose, velocities, the route follower's progress) and
  /// drives on; time goes on.  A cover (scenario `cover:`) only covers
  /// the lens: the robot drives on along its route.
  void advance();
  /// The IMU and encoder readings (and their truth) since the last call.
  MotionBatch take_motion() { return motion_ ? motion_->take() : MotionBatch{}; }
  const MotionSensors& motion_sensors() const { return *motion_; }
  /// The camera's optical frame in the robot's base (its free body).
  geom::SE3d T_b_c() const;
  /// Ground truth: the robot's base (free body frame: axle centre) in the world.
  geom::SE3d T_w_b() const;
  /// The scenario's kidnap in frames, if it has one.
  const std::optional<scenes::KidnapFrames>& kidnap_frames() const { return kidnap_; }

  /// Ground truth: camera optical frame (x right, y down, z forward) in the world.
  geom::SE3d T_w_c() const;
  /// Ground truth planar pose of the robot's axle centre.
  Pose2d base_pose() const;
  geom::PinholeIntrinsics intrinsics() const;
  /// The sun's projection in the image (may lie outside it) when it is in
  /// front of the camera.
  std::optional<cv::Point2d> sun_pixel() const;
  /// The unit direction towards the sun in the world (scenario light).
  Eigen::Vector3d to_sun_w() const;

  /// Steer from this pose instead of ground truth (closed loop), or from
  /// ground truth again with nullopt.
  void set_steering_pose(const std::optional<Pose2d>& pose) { steering_pose_ = pose; }
  /// Stops the robot while true (for example while tracking is lost).
  void set_hold(bool hold) { hold_ = hold; }
  /// Overrides the route follower with fixed wheel speeds (rad/s); nullopt restores it.
  void set_wheel_override(const std::optional<Eigen::Vector2d>& left_right) { wheel_override_ = left_right; }

  const scenes::Scenario& scenario() const { return scenario_; }
  const SceneAssets& assets() const { return assets_; }
  const DriveKinematics& kinematics() const { return kinematics_; }
  const RouteFollower& follower() const { return *follower_; }
  const mjModel* model() const { return model_.get(); }
  mjData* data() { return data_.get(); }
  const mjData* data() const { return data_.get(); }
  int camera_id() const { return camera_id_; }
  /// The images of the ground's tiles near the camera, kept up to date with
  /// every frame (GroundStream), or null where the ground has none.
  const GroundStream* ground_stream() const { return ground_stream_.get(); }
  /// The lowest ground a shadow can fall on in the sun's shadow map now
  /// (around the camera, or over the route): z = 0 on flat ground; on a
  /// relief, the lowest of its heights sampled over the map, 0.1 m lower.
  double shadow_floor_z_m() const;

 private:
  void step_physics(int steps);
  /// Brings the whole scene's data to the physics' state (positions,
  /// velocities, controls, time) and its kinematics up to date.
  void sync_scene();
  /// One camera period of the kidnap's carry (frames cover_begin..teleport).
  void carry_steps(int steps);
  bool carrying() const;
  /// Kidnap: keeps the state of the target frame, restores it at the teleport frame.
  void kidnap_step();
  scenes::Scenario scenario_;
  SceneAssets assets_;
  ModelPtr model_;  ///< the whole scene: what is drawn, ray-cast and read
  DataPtr data_;
  /// The robot's physics: the scene without its scenery (physics_assets),
  /// stepped; data_ follows it once a frame.
  ModelPtr phys_model_;
  DataPtr phys_data_;
  DriveKinematics kinematics_;
  std::unique_ptr<RouteFollower> follower_;
  std::optional<Pose2d> steering_pose_;
  std::optional<Eigen::Vector2d> wheel_override_;
  bool hold_ = false;
  int frame_ = 0;
  int camera_id_ = -1;
  int free_qpos_ = 0;
  int free_dof_ = 0;
  int act_left_ = -1, act_right_ = -1;
  std::optional<scenes::KidnapFrames> kidnap_;
  DataPtr kidnap_data_;                           ///< the physics' state at kidnap_->target
  std::optional<RouteFollower> kidnap_follower_;  ///< the follower at kidnap_->target
  std::unique_ptr<MotionSensors> motion_;         ///< from frame 0 on
  std::unique_ptr<GroundStream> ground_stream_;  ///< follows camera_id_ in sync_scene
  std::unique_ptr<CarryPath> carry_;        ///< while the kidnap carries the robot
  scenes::GroundRelief relief_;             ///< what the ground under the sun's shadow map is
  ShadowMap shadow_map_;
  int carry_step_ = 0;
};

/// One captured frame with its ground truth.
struct Capture {
  sensor::RgbdFrame frame;   ///< what the sensor delivers (noisy)
  cv::Mat depth_gt_m;        ///< rendered depth, exact, sky = 0
  geom::SE3d T_w_c;          ///< ground-truth camera pose
  std::vector<ImuTruth> imu_truth;      ///< the truth behind frame.imu
  std::vector<WheelTruth> wheel_truth;  ///< the truth behind frame.wheel_ticks
  double render_ms = 0;      ///< time spent rendering (GL + read-back)
  double sensor_ms = 0;      ///< time spent in the sensor model (depth and RGB noise)
  StereoTimes stereo;        ///< the d435 model's share of sensor_ms
};

/// One rendered frame before the sensor model: the noise-free images and
/// what the sensor model needs from the simulator state at render time.
/// It carries no reference to the simulator, so the sensor model can run on
/// another thread while the next frame renders.
struct RenderedFrame {
  cv::Mat rgb;                        ///< noise-free colour, R, G, B order
  cv::Mat depth_gt_m;                 ///< rendered depth, exact, sky = 0
  std::optional<cv::Point2d> sun_px;  ///< the sun's projection (Simulator::sun_pixel)
  /// With the Kinect model's sunlight: 1 where the sun reaches the point a
  /// pixel sees (sun_visibility).
  cv::Mat sun_lit;
  Eigen::Vector3d to_sun_c = Eigen::Vector3d::UnitZ();  ///< the sun's direction in the camera
  std::optional<StereoRender> stereo;  ///< the d435 model's infrared views
  std::optional<GlassView> glass;      ///< the colour camera's specular glass
  std::uint64_t index = 0;            ///< frame index
  std::int64_t t_ns = 0;
  geom::SE3d T_w_c;                   ///< ground-truth camera pose
  MotionBatch motion;                 ///< motion sensor readings since the last rendered frame
  double render_ms = 0;               ///< GL rendering and read-back
};

/// The Kinect depth and RGB noise models with the scenario's parameters.
/// apply() is const and touches no shared state: safe on any thread.
class SensorModel {
 public:
  explicit SensorModel(const Simulator& sim);
  /// Applies the sensor model; the result does not depend on the thread
  /// or on which frames were processed before.  A frame the scenario's
  /// cover or kidnap covers (scenes::camera_cover_frames) is what a covered
  /// lens gives: black colour with the sensor's noise, and no depth (0
  /// everywhere).
  Capture apply(RenderedFrame rendered) const;
  /// The d435 model (null for the kinect model).
  const std::shared_ptr<const ActiveStereoModel>& stereo_model() const { return stereo_; }

 private:
  scenes::Camera camera_;
  geom::PinholeIntrinsics K_;
  double sun_elevation_deg_;
  std::uint64_t seed_;
  std::optional<scenes::CoverFrames> cover_;
  std::shared_ptr<const ActiveStereoModel> stereo_;  ///< with camera.model d435
};

/// Renders the simulator's camera and applies the sensor model.
class RgbdCamera {
 public:
  RgbdCamera(const Simulator& sim, GlBackend backend);
  /// render() then the sensor model, on the calling thread.
  Capture capture(Simulator& sim);
  /// Renders the current state (the GL thread's part of capture()).
  RenderedFrame render(Simulator& sim);
  const SensorModel& sensor_model() const { return sensor_; }
  const std::string& description() const { return renderer_.description(); }
  GlBackend backend() const { return renderer_.backend(); }

 private:
  /// The d435 model's two infrared views of the current state.
  StereoRender render_infrared(Simulator& sim, const geom::SE3d& T_w_c, const Eigen::Vector3d& to_sun_c);
  Renderer renderer_;
  SensorModel sensor_;
  std::unique_ptr<Renderer> ir_renderer_;  ///< with camera.model d435
  std::unique_ptr<GlassFinder> glass_;     ///< with specular glass on any array
  int ir_left_id_ = -1, ir_right_id_ = -1;
};

/// Installs MuJoCo's error and warning handlers where none is set: an error
/// throws pvb::Error, a warning is one `pvbench: warning: MuJoCo: ...` line
/// on stderr.  Without them MuJoCo prints, appends to MUJOCO_LOG.TXT in the
/// working directory and exits on errors.  Every entry point of this library
/// that calls MuJoCo (compile_scene, Renderer, Simulator) installs them first
/// (idempotent).
void install_mujoco_handlers();

}  // namespace pvb::sim
