// Local mapping with the motion sensors: the inertial initialisation, and
// the inertial, wheel and tilt terms of local BA (docs/slam_inertial.md).
#include <algorithm>
#include <cmath>
#include <map>

#include "pvb/slam/core/local_mapping.hpp"
#include "pvb/slam/optim/inertial_ba.hpp"

namespace pvb::slam {
namespace {

constexpr double kGravityMps2 = 9.81;

/// The chain in time that ends at kf, oldest first.
std::vector<std::shared_ptr<KeyFrame>> chain_to(const std::shared_ptr<KeyFrame>& kf) {
  std::vector<std::shared_ptr<KeyFrame>> chain;
  for (auto k = kf; k && !k->bad(); k = k->motion().prev.lock()) chain.push_back(k);
  std::reverse(chain.begin(), chain.end());
  return chain;
}

double seconds_between(const KeyFrame& a, const KeyFrame& b) { return static_cast<double>(b.t_ns() - a.t_ns()) * 1e-9; }

/// Camera + accelerometer: gravity is the mean of the keyframes'
/// specific forces turned into the map, pointing down.
bool initialize_tilt(const std::vector<std::shared_ptr<KeyFrame>>& chain, int min_keyframes, MapGravity* g) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& k : chain)
    if (const auto& f = k->motion().from_prev.f_c_mps2) {
      sum += k->T_c_w().inverse().linear() * f->normalized();
      ++n;
    }
  if (n < min_keyframes || !(sum.norm() > 0.5 * n)) return false;
  g->g_w = -kGravityMps2 * sum.normalized();
  g->ready = true;
  return true;
}

/// The tilt term's standard deviation: the accelerometer's mean is
/// gravity only when the camera does not accelerate, so the spread of the
/// readings and the mean's departure from g widen it.
double tilt_sigma_rad(const KeyframeInterval& in) {
  const double off = std::abs(in.f_c_mps2->norm() - kGravityMps2);
  return 0.005 + (off + 0.5 * in.f_spread_mps2) / kGravityMps2;
}

}  // namespace

void LocalMapping::initialize_inertial(const std::shared_ptr<KeyFrame>& kf) {
  std::lock_guard<std::mutex> lock(map_.mutex());
  MapGravity& g = map_.gravity();
  if (g.ready || kf->bad() || kf->provisional() != 0) return;
  const auto chain = chain_to(kf);
  if (options_.motion.setup == sensor::SensorSetup::kCameraAccel) {
    if (initialize_tilt(chain, options_.init_min_keyframes / 2, &g)) {
      g.ready_keyframe_id = kf->id();
      g.ready_t_ns = kf->t_ns();
    }
    return;
  }
  if (!uses_imu(options_.motion.setup)) return;
  // The newest run of keyframes linked by IMU intervals.
  std::size_t first = chain.size() - 1;
  while (first > 0 && chain[first]->motion().from_prev.imu) --first;
  const std::vector<std::shared_ptr<KeyFrame>> run(chain.begin() + static_cast<long>(first), chain.end());
  if (static_cast<int>(run.size()) < options_.init_min_keyframes ||
      seconds_between(*run.front(), *run.back()) < options_.init_min_span_s)
    return;
  InertialInitProblem problem;
  problem.T_b_c = options_.motion.imu.T_b_c;
  problem.g_w_guess = g.g_w;  // its magnitude; the direction comes from the increments
  problem.gyro_bias_prior_radps = options_.init_gyro_bias_sigma_radps;
  problem.accel_bias_prior_mps2 = options_.init_accel_bias_sigma_mps2;
  problem.pose_sigma_m = options_.init_pose_sigma_m;
  problem.pose_sigma_rad = options_.init_pose_sigma_rad;
  for (std::size_t k = 0; k < run.size(); ++k) {
    problem.T_c_w.push_back(run[k]->T_c_w());
    if (k > 0) problem.pre.push_back(run[k]->motion().from_prev.imu);
  }
  const InertialInitResult r = slam::initialize_inertial(problem);
  if (!r.ok) return;
  g.ready = true;
  g.g_w = r.g_w;
  g.bias = r.bias;
  g.ready_keyframe_id = kf->id();
  g.ready_t_ns = kf->t_ns();
  g.init_rms = r.rms_whitened;
  for (std::size_t k = 0; k < run.size(); ++k) {
    KeyFrameMotion& m = run[k]->motion();
    m.has_state = true;
    m.v_w_mps = r.v_w_mps[k];
    m.bias = r.bias;
    if (m.from_prev.imu) {  // integrated again at the bias found
      auto again = std::make_shared<ImuPreintegration>(*m.from_prev.imu);
      again->reintegrate(r.bias);
      m.from_prev.imu = std::move(again);
    }
  }
}

void LocalMapping::add_motion_terms(BaProblem* problem, std::vector<std::shared_ptr<KeyFrame>>* kfs) {
  const MapGravity& g = map_.gravity();
  const bool imu = uses_imu(options_.motion.setup) && g.ready;
  const bool wheels = uses_wheels(options_.motion.setup);
  const bool tilt = options_.motion.setup == sensor::SensorSetup::kCameraAccel && g.ready;
  if (!imu && !wheels && !tilt) return;
  auto in = std::make_shared<BaInertial>();
  in->T_b_c = options_.motion.imu.T_b_c;
  in->T_base_c = options_.motion.robot.T_base_c;
  in->g_w = g.g_w;
  if (imu) in->gravity_sigma_rad = options_.gravity_sigma_rad;
  in->fixed_states_free = true;
  std::map<std::uint64_t, std::size_t> index;
  for (std::size_t k = 0; k < kfs->size(); ++k) index[(*kfs)[k]->id()] = k;
  const auto index_of = [&](const std::shared_ptr<KeyFrame>& k) {
    auto [it, fresh] = index.emplace(k->id(), kfs->size());
    if (fresh) {  // the chain's neighbour outside the window: held where it is
      problem->keyframes.push_back({k->id(), k->T_c_w(), true});
      kfs->push_back(k);
    }
    return it->second;
  };
  const auto link = [&](std::size_t i, std::size_t j) {
    const KeyFrameMotion& a = (*kfs)[i]->motion();
    const KeyFrameMotion& b = (*kfs)[j]->motion();
    if (imu && b.from_prev.imu && a.has_state && b.has_state) in->imu_edges.push_back({i, j, b.from_prev.imu});
    if (wheels && b.from_prev.wheels) in->wheel_edges.push_back({i, j, b.from_prev.wheels});
  };
  const std::size_t window = kfs->size();
  for (std::size_t k = 0; k < window; ++k) {
    if (problem->keyframes[k].fixed) continue;
    const auto self = (*kfs)[k];
    if (auto prev = self->motion().prev.lock(); prev && !prev->bad()) link(index_of(prev), k);
    if (auto next = self->motion().next.lock(); next && !next->bad()) {
      const auto it = index.find(next->id());
      if (it != index.end() && problem->keyframes[it->second].fixed) link(k, it->second);
    }
    const KeyframeInterval& from = self->motion().from_prev;
    if (tilt && from.f_c_mps2) in->gravity_edges.push_back({k, *from.f_c_mps2, tilt_sigma_rad(from)});
  }
  if (in->imu_edges.empty() && in->wheel_edges.empty() && in->gravity_edges.empty()) return;
  in->states.resize(kfs->size());
  for (std::size_t k = 0; k < kfs->size(); ++k) {
    const KeyFrameMotion& m = (*kfs)[k]->motion();
    in->states[k].v_w_mps = m.v_w_mps;
    in->states[k].bias = m.has_state ? m.bias : g.bias;
  }
  problem->inertial = std::move(in);
}

void LocalMapping::write_motion_states(const BaProblem& problem, const std::vector<std::shared_ptr<KeyFrame>>& kfs) {
  MapGravity& g = map_.gravity();
  if (g.ready && problem.inertial->gravity_sigma_rad > 0) g.g_w = problem.inertial->g_w;
  std::uint64_t newest = 0;
  for (std::size_t k = 0; k < kfs.size(); ++k) {
    KeyFrameMotion& m = kfs[k]->motion();
    if (problem.keyframes[k].fixed || kfs[k]->bad() || !m.has_state) continue;
    m.v_w_mps = problem.inertial->states[k].v_w_mps;
    m.bias = problem.inertial->states[k].bias;
    if (g.ready && uses_imu(options_.motion.setup) && kfs[k]->id() >= newest) {
      newest = kfs[k]->id();
      g.bias = m.bias;
    }
  }
}

bool LocalMapping::may_cull_in_time(const KeyFrame& kf) const {
  if (!uses_imu(options_.motion.setup) && !uses_wheels(options_.motion.setup)) return true;
  const auto prev = kf.motion().prev.lock();
  const auto next = kf.motion().next.lock();
  if (!next) return false;  // the chain's end: the next keyframe's interval starts here
  return !prev || seconds_between(*prev, *next) <= options_.max_inertial_gap_s;
}

void LocalMapping::calibrate_wheels(const std::shared_ptr<KeyFrame>& kf) {
  std::lock_guard<std::mutex> lock(map_.mutex());
  if (!wheels_resumed_) {  // a loaded map's fit (System::load_map kept it only for this robot's description)
    wheels_resumed_ = true;
    if (map_.wheels().intervals > 0) wheel_calibrator_->resume(map_.wheels());
  }
  std::shared_ptr<KeyFrame> to = kf;
  for (int i = 0; i < kWheelLag && to; ++i) to = to->motion().prev.lock();
  if (!to || to->bad() || to->id() <= wheels_fitted_to_) return;
  wheels_fitted_to_ = to->id();
  const std::shared_ptr<KeyFrame> from = to->motion().prev.lock();
  const std::shared_ptr<const WheelPreintegration> wheels = to->motion().from_prev.wheels;
  // Across a provisional map's edge or a long gap the poses say nothing of the wheels.
  if (!from || from->bad() || !wheels || map_.map_of(*from) != map_.map_of(*to) ||
      seconds_between(*from, *to) > options_.max_inertial_gap_s)
    return;
  const geom::SE3d& T_base_c = options_.motion.robot.T_base_c;
  const geom::SE3d T_from_to = T_base_c * from->T_c_w() * to->T_c_w().inverse() * T_base_c.inverse();
  const Eigen::Matrix3d& R = T_from_to.linear();
  const double yaw_rad = std::atan2(R(1, 0), R(0, 0));
  // The arc along the chord, as wheel_step lays it: at half the turn.
  const Eigen::Vector3d& t = T_from_to.translation();
  const double arc_m = t.x() * std::cos(0.5 * yaw_rad) + t.y() * std::sin(0.5 * yaw_rad);
  wheel_calibrator_->add(wheels->described_left_m(), wheels->described_right_m(), arc_m, yaw_rad);
  map_.wheels() = wheel_calibrator_->fit();
  map_.wheels().described_radius_m = options_.motion.robot.drive.wheel_radius_m;
}

}  // namespace pvb::slam
