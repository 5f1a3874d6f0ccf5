#include "pvb/sim/simulator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "pvb/common/error.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/scenes/route.hpp"
#include "pvb/sim/sensor_model.hpp"
#include "pvb/sim/sun_shadow.hpp"
#include "pvb/sim/textures.hpp"
#include "carry_path.hpp"

namespace pvb::sim {
namespace {

constexpr double kSettleS = 0.3;

double yaw_of(const mjtNum* q) {  // MuJoCo quaternion w, x, y, z
  return std::atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]));
}

int actuator(const mjModel* m, const char* name) {
  const int id = mj_name2id(m, mjOBJ_ACTUATOR, name);
  if (id < 0) throw Error(std::string("generated model lacks actuator ") + name);
  return id;
}

}  // namespace

Simulator::Simulator(scenes::Scenario scenario, SceneDetail detail) : scenario_(std::move(scenario)) {
  install_mujoco_handlers();
  // Compiled in memory only: the textures' pixels, no PNG (write_scene()
  // writes them as a recording's files are).
  assets_ = build_scene(scenario_, detail, TextureEncoding::kPixels);
  model_ = compile_scene(assets_);
  data_.reset(mj_makeData(model_.get()));
  if (GroundStream::wanted(scenario_, detail)) ground_stream_ = std::make_unique<GroundStream>(model_.get(), scenario_);
  phys_model_ = compile_scene(physics_assets(assets_));
  phys_data_.reset(mj_makeData(phys_model_.get()));
  relief_ = scenes::GroundRelief(scenario_);
  shadow_map_ = shadow_map_for(scenario_.light, scenes::route_polyline(scenario_));
  const mjModel* m = phys_model_.get();
  if (m->nq != model_->nq || m->nv != model_->nv || m->nu != model_->nu || m->nbody != model_->nbody ||
      m->ncam != model_->ncam)
    throw Error("the physics model lost part of the robot");
  camera_id_ = mj_name2id(m, mjOBJ_CAMERA, kCameraName);
  const int body = mj_name2id(m, mjOBJ_BODY, kRobotBody);
  if (camera_id_ < 0 || body < 0) throw Error("generated model lacks the robot or its camera");
  free_qpos_ = m->jnt_qposadr[m->body_jntadr[body]];
  free_dof_ = m->jnt_dofadr[m->body_jntadr[body]];
  act_left_ = actuator(m, kLeftActuator);
  act_right_ = actuator(m, kRightActuator);

  // Calibrate the drive on scratch data: the effective rolling radius from a
  // straight run and the effective track from turning on the spot.
  kinematics_.wheel_radius_m = scenario_.robot.wheel_radius_m;
  kinematics_.track_m = scenario_.robot.track_m;
  kinematics_.max_wheel_radps = scenario_.robot.max_wheel_speed_radps;
  {
    DataPtr scratch(mj_makeData(m));
    const int settle = static_cast<int>(kSettleS / m->opt.timestep);
    const int second = static_cast<int>(1.0 / m->opt.timestep);
    auto run = [&](double wl, double wr, int steps) {
      scratch->ctrl[act_left_] = wl;
      scratch->ctrl[act_right_] = wr;
      for (int i = 0; i < steps; ++i) mj_step(m, scratch.get());
    };
    const double w = std::min(scenario_.route.speed_mps / kinematics_.wheel_radius_m, 0.8 * kinematics_.max_wheel_radps);
    run(0, 0, settle);
    run(w, w, second / 2);
    const Eigen::Vector2d p0(scratch->qpos[free_qpos_], scratch->qpos[free_qpos_ + 1]);
    run(w, w, second);
    const Eigen::Vector2d p1(scratch->qpos[free_qpos_], scratch->qpos[free_qpos_ + 1]);
    const double v = (p1 - p0).norm();
    if (v > 1e-3) kinematics_.wheel_radius_m = v / w;
    run(0, 0, second / 2);
    const double wt = std::min(3.0, 0.8 * kinematics_.max_wheel_radps);
    run(-wt, wt, second / 2);
    const double y0 = yaw_of(scratch->qpos + free_qpos_ + 3);
    run(-wt, wt, second);
    double dyaw = yaw_of(scratch->qpos + free_qpos_ + 3) - y0;
    while (dyaw < 0) dyaw += 2 * M_PI;
    if (dyaw > 1e-3) kinematics_.track_m = 2.0 * kinematics_.wheel_radius_m * wt / dyaw;
  }

  std::vector<Eigen::Vector2d> path;
  for (std::size_t i = 0; i + 1 < assets_.route_xy.size(); i += 2)
    path.emplace_back(assets_.route_xy[i], assets_.route_xy[i + 1]);
  follower_ = std::make_unique<RouteFollower>(std::move(path), scenario_.route.speed_mps, scenario_.route.lookahead_m);

  // Settle: the robot starts 2 mm above the ground.
  step_physics(static_cast<int>(kSettleS / m->opt.timestep));
  mj_forward(m, phys_data_.get());
  if (scenario_.kidnap) kidnap_ = scenes::kidnap_frames(*scenario_.kidnap, scenario_.camera.fps);
  motion_ = std::make_unique<MotionSensors>(m, scenario_, body, T_b_c());
  kidnap_step();
  sync_scene();
}

void Simulator::sync_scene() {
  const mjModel* m = model_.get();
  mjData* d = data_.get();
  const mjData* p = phys_data_.get();
  std::copy(p->qpos, p->qpos + m->nq, d->qpos);
  std::copy(p->qvel, p->qvel + m->nv, d->qvel);
  std::copy(p->act, p->act + m->na, d->act);
  std::copy(p->ctrl, p->ctrl + m->nu, d->ctrl);
  std::copy(p->mocap_pos, p->mocap_pos + 3 * m->nmocap, d->mocap_pos);
  std::copy(p->mocap_quat, p->mocap_quat + 4 * m->nmocap, d->mocap_quat);
  d->time = p->time;
  mj_forward(m, d);
  if (ground_stream_) ground_stream_->update(Eigen::Vector3d(d->cam_xpos[3 * camera_id_], d->cam_xpos[3 * camera_id_ + 1],
                                                           d->cam_xpos[3 * camera_id_ + 2]));
}

Simulator::~Simulator() = default;

geom::SE3d Simulator::T_b_c() const {
  const mjModel* m = model_.get();
  const mjtNum* q = m->cam_quat + 4 * camera_id_;
  const mjtNum* p = m->cam_pos + 3 * camera_id_;
  const Eigen::Matrix3d R_b_mj = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  // MuJoCo camera: x right, y up, looking along -z.  Optical: y down, z forward.
  return geom::make_se3(R_b_mj * Eigen::Vector3d(1, -1, -1).asDiagonal(), Eigen::Vector3d(p[0], p[1], p[2]));
}

geom::SE3d Simulator::T_w_b() const {
  const FreeState f = free_state(data_.get(), free_qpos_, free_dof_);
  return geom::make_se3(f.R_w_b, f.p_w);
}

std::int64_t Simulator::t_ns() const { return geom::frame_time_ns(0, frame_, scenario_.camera.fps); }

void Simulator::step_physics(int steps) {
  for (int i = 0; i < steps; ++i) {
    if (motion_) motion_->before_step(phys_data_.get());
    mj_step(phys_model_.get(), phys_data_.get());
    if (motion_) motion_->after_step(phys_model_.get(), phys_data_.get(), false);
  }
}

bool Simulator::carrying() const {
  return kidnap_ && kidnap_data_ && frame_ >= kidnap_->cover_begin && frame_ < kidnap_->teleport;
}

void Simulator::carry_steps(int steps) {
  const mjModel* m = phys_model_.get();
  mjData* d = phys_data_.get();
  if (!carry_) {
    const double duration_s = (kidnap_->teleport - kidnap_->cover_begin) / scenario_.camera.fps;
    carry_ = std::make_unique<CarryPath>(free_state(d, free_qpos_, free_dof_),
                                         free_state(kidnap_data_.get(), free_qpos_, free_dof_), duration_s);
    carry_step_ = 0;
  }
  for (int i = 0; i < steps; ++i) {
    motion_->before_step(d);
    ++carry_step_;
    set_free_state(d, free_qpos_, free_dof_, carry_->at(carry_step_ * m->opt.timestep));
    for (int dof = 0; dof < m->nv; ++dof)
      if (dof < free_dof_ || dof >= free_dof_ + 6) d->qvel[dof] = 0;  // the wheels stand still
    d->time += m->opt.timestep;
    motion_->after_step(m, d, true);
  }
}

void Simulator::advance() {
  Eigen::Vector2d lr = Eigen::Vector2d::Zero();
  if (wheel_override_) {
    lr = *wheel_override_;
  } else if (!hold_ && !carrying()) {
    const Eigen::Vector2d vw = follower_->command(steering_pose_ ? *steering_pose_ : base_pose());
    lr = kinematics_.wheel_speeds(vw.x(), vw.y());
  }
  if (scenario_.robot.max_wheel_accel_radps2) {  // ramp towards the command
    const double step = *scenario_.robot.max_wheel_accel_radps2 / scenario_.camera.fps;
    const Eigen::Vector2d last(phys_data_->ctrl[act_left_], phys_data_->ctrl[act_right_]);
    lr = last + (lr - last).cwiseMax(-step).cwiseMin(step);
  }
  phys_data_->ctrl[act_left_] = lr.x();
  phys_data_->ctrl[act_right_] = lr.y();
  if (carrying())
    carry_steps(assets_.substeps);
  else
    step_physics(assets_.substeps);
  mj_forward(phys_model_.get(), phys_data_.get());  // the state a frame ends with (the next step starts from it)
  ++frame_;
  kidnap_step();
  sync_scene();  // camera poses for the new state
}

void Simulator::kidnap_step() {
  if (!kidnap_) return;
  if (frame_ == kidnap_->target) {
    kidnap_data_.reset(mj_makeData(phys_model_.get()));
    mj_copyData(kidnap_data_.get(), phys_model_.get(), phys_data_.get());
    kidnap_follower_ = *follower_;
  } else if (frame_ == kidnap_->teleport && kidnap_data_) {
    // The whole physical state (positions, velocities, contacts, the
    // solver's warm start) and the follower as they were; only time goes on.
    const mjtNum time_s = phys_data_->time;
    if (motion_) motion_->rebase_wheels(phys_data_.get(), kidnap_data_.get());
    carry_.reset();
    mj_copyData(phys_data_.get(), phys_model_.get(), kidnap_data_.get());
    phys_data_->time = time_s;
    *follower_ = *kidnap_follower_;
  }
}

geom::SE3d Simulator::T_w_c() const {
  const mjtNum* x = data_->cam_xpos + 3 * camera_id_;
  const mjtNum* R = data_->cam_xmat + 9 * camera_id_;
  Eigen::Matrix3d R_w_mj;
  R_w_mj << R[0], R[1], R[2], R[3], R[4], R[5], R[6], R[7], R[8];
  // MuJoCo camera: x right, y up, looking along -z.  Optical: y down, z forward.
  const Eigen::Matrix3d R_mj_optical = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return geom::make_se3(R_w_mj * R_mj_optical, Eigen::Vector3d(x[0], x[1], x[2]));
}

Pose2d Simulator::base_pose() const {
  const mjtNum* q = data_->qpos + free_qpos_;
  return {q[0], q[1], yaw_of(q + 3)};
}

geom::PinholeIntrinsics Simulator::intrinsics() const {
  const scenes::Camera& c = scenario_.camera;
  return {c.fx, c.fy, c.cx(), c.cy(), c.width, c.height};
}

Eigen::Vector3d Simulator::to_sun_w() const {
  const double az = scenario_.light.sun_azimuth_deg * M_PI / 180, el = scenario_.light.sun_elevation_deg * M_PI / 180;
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

std::optional<cv::Point2d> Simulator::sun_pixel() const {
  const Eigen::Vector3d d = T_w_c().linear().transpose() * to_sun_w();
  if (d.z() <= 0.05) return std::nullopt;
  const auto K = intrinsics();
  return cv::Point2d(K.fx * d.x() / d.z() + K.cx, K.fy * d.y() / d.z() + K.cy);
}

namespace {
/// A ground of shared soil images lays a tile every 3 m along the route:
/// those beyond where the soil's stones shrink below half a pixel are left
/// out (textures.hpp).  Other grounds keep every tile, and their bytes.
double far_tile_cull_m(const scenes::Scenario& s) {
  return s.ground.soil_images > 0 ? s.camera.fx * kSoilFeatureM / 0.5 : 0.0;
}

/// A tiled relief's tiles are drawn in full where the camera can measure
/// depth (its range, plus half a tile's diagonal and a metre), as their far
/// versions beyond.
double relief_detail_m(const scenes::Scenario& s) {
  return s.ground.relief ? s.camera.depth_range_m.y() + kGroundTileM / std::sqrt(2.0) + 1.0 : 0.0;
}

const Simulator& textured(const Simulator& sim) {
  if (sim.assets().detail != SceneDetail::kFull)
    throw Error("a simulator built for its geometry only gives no colour frames (build it with SceneDetail::kFull)");
  return sim;
}
}  // namespace

RgbdCamera::RgbdCamera(const Simulator& sim, GlBackend backend)
    : renderer_(textured(sim).model(), backend, sim.scenario().camera.width, sim.scenario().camera.height),
      sensor_(sim) {
  renderer_.set_shadows(sim.scenario().light.shadows);
  renderer_.set_far_tile_cull_m(far_tile_cull_m(sim.scenario()));
  renderer_.set_relief_detail_m(relief_detail_m(sim.scenario()));
  renderer_.set_ground_stream(sim.ground_stream());
  std::vector<bool> specular;
  for (const auto& a : sim.scenario().pv_arrays) specular.push_back(a.specular_glass);
  glass_ = std::make_unique<GlassFinder>(sim.model(), specular);
  if (glass_->empty()) glass_.reset();
  const scenes::Camera& cam = sim.scenario().camera;
  if (cam.model != scenes::CameraKind::kD435) return;
  ir_renderer_ = std::make_unique<Renderer>(sim.model(), renderer_.backend(), cam.stereo.ir_width, cam.stereo.ir_height);
  ir_renderer_->set_shadows(sim.scenario().light.shadows);
  ir_renderer_->set_far_tile_cull_m(far_tile_cull_m(sim.scenario()));
  ir_renderer_->set_relief_detail_m(relief_detail_m(sim.scenario()));
  ir_renderer_->set_ground_stream(sim.ground_stream());
  ir_left_id_ = mj_name2id(sim.model(), mjOBJ_CAMERA, kIrLeftCameraName);
  ir_right_id_ = mj_name2id(sim.model(), mjOBJ_CAMERA, kIrRightCameraName);
  if (ir_left_id_ < 0 || ir_right_id_ < 0)
    throw ConfigError("model", "camera", "the infrared cameras of the d435 model", "none");
}

namespace {

/// The ball that holds every point of an image of width x height pixels up
/// to max_depth_m along the optical axis, seen from T_w_c (its corner rays
/// are the longest), with a centimetre to spare.
ShadeRegion shade_region(const geom::SE3d& T_w_c, const geom::PinholeIntrinsics& K, int width, int height,
                         double max_depth_m) {
  const double x = std::max(K.cx, width - 1 - K.cx) / K.fx, y = std::max(K.cy, height - 1 - K.cy) / K.fy;
  return {T_w_c.translation(), max_depth_m * std::sqrt(1 + x * x + y * y) + 0.01};
}

}  // namespace

double Simulator::shadow_floor_z_m() const {
  if (relief_.flat()) return 0.0;
  const Eigen::Vector2d centre =
      shadow_map_.follows_robot ? Eigen::Vector2d(T_w_c().translation().head<2>()) : shadow_map_.centre_xy_m;
  const double reach = shadow_map_.half_width_m * std::sqrt(2.0);
  constexpr int kAcross = 9;
  double lowest = relief_.height_m(centre);
  for (int i = 0; i < kAcross; ++i)
    for (int j = 0; j < kAcross; ++j) {
      const Eigen::Vector2d d(-1.0 + 2.0 * i / (kAcross - 1), -1.0 + 2.0 * j / (kAcross - 1));
      lowest = std::min(lowest, relief_.height_m(centre + reach * d));
    }
  return lowest - 0.1;
}

StereoRender RgbdCamera::render_infrared(Simulator& sim, const geom::SE3d& T_w_c, const Eigen::Vector3d& to_sun_c) {
  const scenes::Scenario& s = sim.scenario();
  const scenes::ActiveStereo& p = s.camera.stereo;
  StereoRender out;
  out.to_sun_c = to_sun_c.cast<float>();
  const float sky = static_cast<float>(sim.assets().max_scene_depth_m);
  const geom::PinholeIntrinsics K_ir = sensor_.stereo_model()->ir_intrinsics();
  const float pattern_range_m = sensor_.stereo_model()->pattern_range_m();
  std::optional<SunShadowCaster> caster;
  if (s.light.sun_elevation_deg > 0)
    caster.emplace(sim.model(), sim.data(), sim.to_sun_w(),
                   shade_region(T_w_c, K_ir, p.ir_width, p.ir_height, pattern_range_m + p.baseline_m + p.colour_offset_m));
  ir_renderer_->set_shadow_floor_z_m(sim.shadow_floor_z_m());
  for (int k = 0; k < 2; ++k) {
    InfraredView& v = k == 0 ? out.left : out.right;
    cv::Mat rgb;
    ir_renderer_->render(sim.model(), sim.data(), k == 0 ? ir_left_id_ : ir_right_id_, &rgb, &v.depth_m);
    v.depth_m.setTo(0.0f, v.depth_m > sky);
    cv::cvtColor(rgb, v.grey, cv::COLOR_RGB2GRAY);
    const double x_m = -p.colour_offset_m + (k == 0 ? 0.0 : p.baseline_m);  // along the colour camera's x
    const geom::SE3d T_w_ir = T_w_c * geom::make_se3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(x_m, 0, 0));
    if (caster) v.lit = sun_visibility(*caster, v.depth_m, K_ir, T_w_ir, 16, pattern_range_m);
    if (glass_) v.glass = glass_->find(sim.data(), v.depth_m, K_ir, T_w_ir, false);  // no Kinect depth here
  }
  return out;
}

RenderedFrame RgbdCamera::render(Simulator& sim) {
  using Clock = std::chrono::steady_clock;
  RenderedFrame out;
  const auto t0 = Clock::now();
  renderer_.set_shadow_floor_z_m(sim.shadow_floor_z_m());
  renderer_.render(sim.model(), sim.data(), sim.camera_id(), &out.rgb, &out.depth_gt_m);
  // Sky: beyond every scene distance (the skybox is drawn far away).
  const float sky = static_cast<float>(sim.assets().max_scene_depth_m);
  out.depth_gt_m.setTo(0.0f, out.depth_gt_m > sky);
  out.sun_px = sim.sun_pixel();
  const geom::SE3d T_w_c = sim.T_w_c();
  out.to_sun_c = T_w_c.linear().transpose() * sim.to_sun_w();
  const scenes::Camera& cam = sim.scenario().camera;
  if (cam.model == scenes::CameraKind::kKinect && cam.depth_noise.model == scenes::DepthNoiseModel::kKinect &&
      cam.depth_noise.sunlight.on && sim.scenario().light.sun_elevation_deg > 0) {
    const float shade_range_m = sunlight_frame(cam.depth_noise.sunlight, sim.scenario().light.sun_elevation_deg,
                                               out.to_sun_c.cast<float>(), cv::Mat())
                                    .shade_range_m();
    const SunShadowCaster caster(sim.model(), sim.data(), sim.to_sun_w(),
                                 shade_region(T_w_c, sim.intrinsics(), cam.width, cam.height, shade_range_m));
    out.sun_lit = sun_visibility(caster, out.depth_gt_m, sim.intrinsics(), T_w_c, 16, shade_range_m);
  }
  if (glass_) out.glass = glass_->find(sim.data(), out.depth_gt_m, sim.intrinsics(), T_w_c, true);
  if (ir_renderer_) out.stereo = render_infrared(sim, T_w_c, out.to_sun_c);
  out.render_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  out.index = static_cast<std::uint64_t>(sim.frame_index());
  out.t_ns = sim.t_ns();
  out.T_w_c = T_w_c;
  out.motion = sim.take_motion();
  return out;
}

Capture RgbdCamera::capture(Simulator& sim) { return sensor_.apply(render(sim)); }

SensorModel::SensorModel(const Simulator& sim)
    : camera_(sim.scenario().camera),
      K_(sim.intrinsics()),
      sun_elevation_deg_(sim.scenario().light.sun_elevation_deg),
      seed_(sim.scenario().seed),
      cover_(scenes::camera_cover_frames(sim.scenario())) {
  if (camera_.model == scenes::CameraKind::kD435)
    stereo_ = std::make_shared<ActiveStereoModel>(camera_, sun_elevation_deg_, seed_);
}

Capture SensorModel::apply(RenderedFrame rendered) const {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  Capture out;
  out.depth_gt_m = std::move(rendered.depth_gt_m);
  const bool covered = cover_ && cover_->covered(static_cast<std::int64_t>(rendered.index));
  if (covered) {  // no light reaches the colour sensor, no infrared pattern comes back
    rendered.rgb.setTo(cv::Scalar::all(0));
    out.frame.depth_m = cv::Mat::zeros(out.depth_gt_m.size(), CV_32FC1);
  } else if (stereo_ && rendered.stereo) {
    out.frame.depth_m = stereo_->depth(*rendered.stereo, rendered.index, &out.stereo);
  } else {
    std::optional<SunlightFrame> sun;
    if (!rendered.sun_lit.empty())
      sun = sunlight_frame(camera_.depth_noise.sunlight, sun_elevation_deg_, rendered.to_sun_c.cast<float>(),
                           std::move(rendered.sun_lit));
    out.frame.depth_m = apply_depth_model(out.depth_gt_m, K_, camera_, seed_, rendered.index, sun ? &*sun : nullptr,
                                          rendered.glass ? &*rendered.glass : nullptr);
  }
  if (rendered.glass && !covered)
    apply_glass(&rendered.rgb, *rendered.glass, K_, rendered.to_sun_c.cast<float>(), sun_elevation_deg_ > 0);
  apply_rgb_model(&rendered.rgb, camera_.rgb, covered ? std::nullopt : rendered.sun_px, seed_,
                  rendered.index);
  out.frame.rgb = std::move(rendered.rgb);
  out.frame.t_ns = rendered.t_ns;
  out.frame.index = rendered.index;
  out.T_w_c = rendered.T_w_c;
  out.frame.imu = std::move(rendered.motion.imu);
  out.frame.wheel_ticks = std::move(rendered.motion.ticks);
  out.imu_truth = std::move(rendered.motion.imu_truth);
  out.wheel_truth = std::move(rendered.motion.wheel_truth);
  out.render_ms = rendered.render_ms;
  out.sensor_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  return out;
}

}  // namespace pvb::sim
