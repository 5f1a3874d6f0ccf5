// Pose-only optimisation and local bundle adjustment (ORB-SLAM2's
// Optimizer::PoseOptimization and Optimizer::LocalBundleAdjustment): the
// pose-only problem by a dense 6x6 Levenberg-Marquardt written here, local
// BA on Ceres.
#include "pvb/slam/optim/optimizer.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "inertial_cost_functions.hpp"
#include "inertial_costs.hpp"
#include "pvb/slam/optim/inertial_ba.hpp"
#include "residuals.hpp"

namespace pvb::slam {
namespace {

using optim_detail::is_stereo;
using optim_detail::PoseNormalEquations;
using optim_detail::pose_normal_equations;

/// A camera pose as one Ceres parameter block (see residuals.hpp):
/// [q_c_w (x, y, z, w), t_c_w] on SE3LeftManifold.
struct PoseBlock {
  double pose[optim_detail::kPoseSize] = {0, 0, 0, 1, 0, 0, 0};

  static PoseBlock from_se3(const geom::SE3d& T_c_w) {
    PoseBlock b;
    optim_detail::pose_to_block(T_c_w, b.pose);
    return b;
  }
  geom::SE3d to_se3() const { return optim_detail::block_to_pose(pose); }
};

double chi2_threshold(const Observation& obs, double chi2_mono, double chi2_stereo) {
  return is_stereo(obs) ? chi2_stereo : chi2_mono;
}

/// Problem options shared by all solves: the cost functions, losses and the
/// manifold are owned by the caller so that they survive across rounds.
ceres::Problem::Options borrowed_problem_options() {
  ceres::Problem::Options o;
  o.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  o.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  o.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return o;
}

bool aborted(const std::atomic<bool>* flag) { return flag != nullptr && flag->load(); }

/// Stops a bundle-adjustment pass once *flag becomes true (ORB-SLAM2's
/// pbStopFlag).  Returns SOLVER_TERMINATE_SUCCESSFULLY rather than
/// SOLVER_ABORT: g2o's force-stop keeps the estimate reached so far, and
/// SOLVER_ABORT would make Ceres discard the whole pass.
class AbortCallback : public ceres::IterationCallback {
 public:
  AbortCallback(const std::atomic<bool>* flag, const std::function<void()>& on_iteration)
      : flag_(flag), on_iteration_(on_iteration) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& /*summary*/) override {
    if (on_iteration_) on_iteration_();
    if (!aborted(flag_)) return ceres::SOLVER_CONTINUE;
    fired_ = true;
    return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }
  bool fired() const { return fired_; }

 private:
  const std::atomic<bool>* flag_;
  const std::function<void()>& on_iteration_;
  bool fired_ = false;
};

/// Levenberg-Marquardt on one pose against fixed points, the way g2o's
/// OptimizationAlgorithmLevenberg runs it for ORB-SLAM2's PoseOptimization:
/// lambda starts at 1e-5 max(diag H), a rejected step multiplies it by
/// nu (2, 4, 8, ...; at most 10 tries per iteration), an accepted one scales
/// it by max(1/3, 1 - (2 rho - 1)^3).  The step solves (H + lambda I) dx = -g
/// in the tangent space and is applied with SE3LeftManifold::Plus.  Stops
/// after options.iterations_per_round iterations, when no step lowers the
/// cost, or when a step changes the cost by less than 1e-10 relative (as
/// Ceres' function tolerance, tighter) or the pose by less than 1e-12.
/// Updates pose in place; returns the final robust cost 0.5 sum rho.
/// This replaced a Ceres solve per round: with a single 6-DoF block, Ceres'
/// problem construction, preprocessing and virtual residual calls cost
/// several times the arithmetic itself (docs/slam.md, "Speed").
double pose_only_levenberg_marquardt(const StereoIntrinsics& K, const std::vector<Eigen::Vector3d>& points_w,
                                     const std::vector<Observation>& obs, const std::vector<std::size_t>& active,
                                     bool robust, const PoseOptimizerOptions& options, double* pose) {
  PoseNormalEquations ne;
  if (!pose_normal_equations<true>(K, points_w, obs, active, robust, options, pose, &ne)) return 0.0;
  double lambda = 1e-5 * ne.H.diagonal().maxCoeff();
  double nu = 2.0;
  double trial[optim_detail::kPoseSize];
  optim_detail::SE3LeftManifold manifold;
  PoseNormalEquations trial_ne;
  for (int it = 0; it < options.iterations_per_round; ++it) {
    bool accepted = false;
    bool converged = false;
    for (int attempt = 0; attempt < 10 && !accepted; ++attempt) {
      Eigen::Matrix<double, 6, 6> A = ne.H;
      A.diagonal().array() += lambda;
      const Eigen::Matrix<double, 6, 1> dx = A.ldlt().solve(-ne.g);
      if (!dx.allFinite()) return ne.cost;
      manifold.Plus(pose, dx.data(), trial);
      const bool valid = pose_normal_equations<false>(K, points_w, obs, active, robust, options, trial, &trial_ne);
      // Predicted decrease of the quadratic model: -dx^T g - 0.5 dx^T H dx = 0.5 dx^T (lambda dx - g).
      const double predicted = 0.5 * dx.dot(lambda * dx - ne.g);
      const double gain = valid ? (ne.cost - trial_ne.cost) / std::max(predicted, 1e-300) : -1.0;
      if (valid && gain > 0.0 && std::isfinite(trial_ne.cost)) {
        converged = (ne.cost - trial_ne.cost) <= 1e-10 * ne.cost || dx.norm() <= 1e-12;
        std::copy(trial, trial + optim_detail::kPoseSize, pose);
        lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * gain - 1.0, 3));
        nu = 2.0;
        accepted = true;
      } else {
        lambda *= nu;
        nu *= 2.0;
      }
    }
    if (!accepted) break;  // no step lowers the cost: at a minimum (numerically)
    if (!pose_normal_equations<true>(K, points_w, obs, active, robust, options, pose, &ne)) break;
    if (converged) break;
  }
  return ne.cost;
}

}  // namespace

Eigen::Vector2d project(const StereoIntrinsics& K, const Eigen::Vector3d& p_c) {
  const double inv_z = 1.0 / p_c.z();
  return {K.fx * p_c.x() * inv_z + K.cx, K.fy * p_c.y() * inv_z + K.cy};
}

double observation_chi2(const StereoIntrinsics& K, const geom::SE3d& T_c_w, const Eigen::Vector3d& p_w,
                        const Observation& obs) {
  const Eigen::Vector3d p_c = T_c_w * p_w;
  if (!(p_c.z() > 0.0)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d uv = project(K, p_c);
  double e2 = (obs.uv - uv).squaredNorm();
  if (is_stereo(obs)) {
    const double e_r = obs.u_right - (uv.x() - K.bf / p_c.z());
    e2 += e_r * e_r;
  }
  return obs.inv_sigma2 * e2;
}

// ---------------------------------------------------------------------------
// Pose-only optimisation
// ---------------------------------------------------------------------------
PoseOptimizerResult optimize_pose(const geom::SE3d& T_c_w_init, const std::vector<Eigen::Vector3d>& points_w,
                                  const std::vector<Observation>& obs, const StereoIntrinsics& K,
                                  const PoseOptimizerOptions& options) {
  if (points_w.size() != obs.size()) {
    throw std::invalid_argument("optimize_pose: " + std::to_string(points_w.size()) + " points but " +
                                std::to_string(obs.size()) + " observations");
  }
  const std::size_t n = obs.size();
  PoseOptimizerResult result;
  result.T_c_w = T_c_w_init;
  result.inlier.assign(n, 0);

  const auto classify = [&](const geom::SE3d& T_c_w) {
    int count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double chi2 = observation_chi2(K, T_c_w, points_w[i], obs[i]);
      result.inlier[i] = chi2 <= chi2_threshold(obs[i], options.chi2_mono, options.chi2_stereo) ? 1 : 0;
      count += result.inlier[i];
    }
    result.num_inliers = count;
  };

  // ORB-SLAM2 does not optimise on fewer than 3 correspondences; we still
  // report which observations agree with the initial pose.
  if (n < 3 || options.rounds <= 0) {
    classify(T_c_w_init);
    return result;
  }

  // Round 0 uses every observation in front of the initial camera.
  std::vector<std::uint8_t> use(n, 0);
  for (std::size_t i = 0; i < n; ++i) use[i] = (T_c_w_init * points_w[i]).z() > 0.0 ? 1 : 0;

  PoseBlock pose = PoseBlock::from_se3(T_c_w_init);
  const PoseBlock pose_init = pose;
  std::vector<std::size_t> active;
  active.reserve(n);
  for (int round = 0; round < options.rounds; ++round) {
    if (options.restart_from_initial) pose = pose_init;
    const geom::SE3d T_start = pose.to_se3();
    const bool robust = options.robust && round < options.robust_rounds;
    active.clear();
    for (std::size_t i = 0; i < n; ++i) {
      // A residual must be defined at the starting pose (point in front).
      if (use[i] && (T_start * points_w[i]).z() > 0.0) active.push_back(i);
    }
    if (active.empty()) break;  // nothing left to optimise against; keep the pose

    result.final_cost = pose_only_levenberg_marquardt(K, points_w, obs, active, robust, options, pose.pose);

    // Classify every observation (outliers too: they may come back).
    classify(pose.to_se3());
    use = result.inlier;
    if (n < 10) break;  // ORB-SLAM2: too few edges for re-classification rounds
  }
  result.T_c_w = pose.to_se3();
  return result;
}

// ---------------------------------------------------------------------------
// Local bundle adjustment
// ---------------------------------------------------------------------------
namespace {

/// One local bundle adjustment: the blocks it moves (copies of the
/// problem's poses and points), an owned cost per edge, and which edges,
/// keyframes and points take part.
class LocalBa {
 public:
  LocalBa(BaProblem& ba, const StereoIntrinsics& K, const BaOptions& options)
      : ba_(ba),
        K_(K),
        options_(options),
        huber_mono_(std::sqrt(options.chi2_mono)),
        huber_stereo_(std::sqrt(options.chi2_stereo)),
        abort_callback_(options.abort_flag, options.on_iteration) {
    poses_.resize(ba.keyframes.size());
    for (std::size_t k = 0; k < ba.keyframes.size(); ++k) poses_[k] = PoseBlock::from_se3(ba.keyframes[k].T_c_w);
    points_.resize(ba.points.size());
    for (std::size_t p = 0; p < ba.points.size(); ++p) points_[p] = ba.points[p].p_w;
    costs_.resize(ba.edges.size());
    for (std::size_t e = 0; e < ba.edges.size(); ++e) costs_[e].reset(optim_detail::make_ba_cost(K, ba.edges[e].obs));
    // Edges whose point is behind the camera have no defined residual; they
    // never enter the problem and are reported as outliers.
    active_.assign(ba.edges.size(), 0);
    for (std::size_t e = 0; e < ba.edges.size(); ++e) active_[e] = std::isfinite(edge_chi2(e)) ? 1 : 0;
    keyframe_used_.assign(ba.keyframes.size(), 0);
    point_used_.assign(ba.points.size(), 0);
    if (ba.inertial) init_inertial(*ba.inertial);
  }

  /// Two passes as ORB-SLAM2 runs them: all edges with the Huber loss, then
  /// without that pass's outliers and without a robust kernel.
  void run(BaResult* result) {
    solve_pass(options_.iterations_first, true, result);
    const bool skip_second = aborted(options_.abort_flag);
    if (!skip_second) {
      for (std::size_t e = 0; e < active_.size(); ++e)
        if (active_[e] && edge_bad(e)) active_[e] = 0;
      solve_pass(options_.iterations_second, false, result);
    }
    result->stopped = abort_callback_.fired() || skip_second;
    // Outliers: excluded from the last pass, or chi2 too big / behind the
    // camera at the final estimate.
    for (std::size_t e = 0; e < active_.size(); ++e)
      if (!active_[e] || edge_bad(e)) result->outlier_edges.push_back(e);
  }

  /// Writes back only what was optimised, so untouched keyframes keep their
  /// exact input pose (no quaternion round trip).
  void write_back() const {
    for (std::size_t k = 0; k < ba_.keyframes.size(); ++k)
      if (keyframe_used_[k] && !ba_.keyframes[k].fixed) ba_.keyframes[k].T_c_w = poses_[k].to_se3();
    for (std::size_t p = 0; p < ba_.points.size(); ++p)
      if (point_used_[p]) ba_.points[p].p_w = points_[p];
    if (!ba_.inertial) return;
    if (free_gravity_) ba_.inertial->g_w = gravity_;
    for (std::size_t k = 0; k < ba_.keyframes.size(); ++k) {
      if (!has_imu_state_[k] || !keyframe_used_[k] || ba_.keyframes[k].fixed) continue;
      BaInertialState& st = ba_.inertial->states[k];
      st.v_w_mps = velocities_[k];
      st.bias.gyro_radps = biases_[k].head<3>();
      st.bias.accel_mps2 = biases_[k].tail<3>();
    }
  }

 private:
  double edge_chi2(std::size_t e) const {
    const BaEdge& edge = ba_.edges[e];
    return observation_chi2(K_, poses_[edge.keyframe].to_se3(), points_[edge.point], edge.obs);
  }
  bool edge_bad(std::size_t e) const {
    // chi2 is +inf for a point behind the camera (ORB-SLAM2's isDepthPositive).
    return !(edge_chi2(e) <= chi2_threshold(ba_.edges[e].obs, options_.chi2_mono, options_.chi2_stereo));
  }

  /// The active edges as residual blocks; kf_in / pt_in mark the blocks added.
  void add_residuals(ceres::Problem* prob, bool robust, std::vector<std::uint8_t>* kf_in,
                     std::vector<std::uint8_t>* pt_in) {
    for (std::size_t e = 0; e < active_.size(); ++e) {
      if (!active_[e]) continue;
      const BaEdge& edge = ba_.edges[e];
      PoseBlock& pose = poses_[edge.keyframe];
      if (!(*kf_in)[edge.keyframe]) {
        prob->AddParameterBlock(pose.pose, optim_detail::kPoseSize, &se3_manifold_);
        // Fixed keyframes (ORB-SLAM2: covisible keyframes outside the local
        // window) anchor the gauge and the scale of the local map; they
        // constrain the local points but must not move.
        if (ba_.keyframes[edge.keyframe].fixed) prob->SetParameterBlockConstant(pose.pose);
        (*kf_in)[edge.keyframe] = 1;
      }
      (*pt_in)[edge.point] = 1;
      ceres::LossFunction* loss = nullptr;
      if (robust) loss = is_stereo(edge.obs) ? &huber_stereo_ : &huber_mono_;
      prob->AddResidualBlock(costs_[e].get(), loss, pose.pose, points_[edge.point].data());
    }
  }

  void solve_pass(int iterations, bool robust, BaResult* result) {
    ceres::Problem prob(borrowed_problem_options());
    std::vector<std::uint8_t> kf_in(ba_.keyframes.size(), 0), pt_in(ba_.points.size(), 0);
    add_residuals(&prob, robust, &kf_in, &pt_in);
    std::vector<std::uint8_t> state_in;  // velocity and bias blocks added (inertial only)
    if (ba_.inertial) add_inertial_residuals(&prob, &kf_in, &state_in);
    if (prob.NumResidualBlocks() == 0) return;
    // Schur ordering: points (group 0) are eliminated first, then poses.
    // Every block must be listed, the constant ones included.  Ceres
    // orders the blocks of one group by address, so each kind has a group
    // of its own and lies in one array: blocks in separate allocations
    // would be ordered by where the heap put them, which another thread's
    // allocations change from run to run.
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (std::size_t p = 0; p < points_.size(); ++p)
      if (pt_in[p]) ordering->AddElementToGroup(points_[p].data(), 0);
    for (std::size_t k = 0; k < poses_.size(); ++k)
      if (kf_in[k]) ordering->AddElementToGroup(poses_[k].pose, 1);
    for (std::size_t k = 0; k < state_in.size(); ++k) {
      if (!state_in[k]) continue;
      ordering->AddElementToGroup(velocities_[k].data(), 2);
      ordering->AddElementToGroup(biases_[k].data(), 3);
    }
    if (ba_.inertial && free_gravity_) ordering->AddElementToGroup(gravity_.data(), 4);

    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = options_.sparse_schur ? ceres::SPARSE_SCHUR : ceres::DENSE_SCHUR;
    solver_options.linear_solver_ordering = ordering;
    solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    solver_options.max_num_iterations = iterations;
    solver_options.num_threads = 1;  // deterministic
    solver_options.logging_type = ceres::SILENT;
    if (options_.abort_flag != nullptr || options_.on_iteration) solver_options.callbacks.push_back(&abort_callback_);

    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &prob, &summary);
    // summary.iterations[0] (also counted in num_successful_steps) is the
    // initial state, not a step.
    result->iterations += static_cast<int>(summary.iterations.size()) - 1;
    result->converged = summary.termination_type == ceres::CONVERGENCE;
    for (std::size_t k = 0; k < kf_in.size(); ++k) keyframe_used_[k] |= kf_in[k];
    for (std::size_t p = 0; p < pt_in.size(); ++p) point_used_[p] |= pt_in[p];
  }

  /// The inertial terms' costs and the velocity and bias blocks of every
  /// keyframe that an IMU edge names.
  void init_inertial(const BaInertial& in) {
    const std::size_t n = ba_.keyframes.size();
    velocities_.resize(n);
    biases_.resize(n);
    has_imu_state_.assign(n, 0);
    for (std::size_t k = 0; k < n; ++k) {
      velocities_[k] = in.states[k].v_w_mps;
      biases_[k] << in.states[k].bias.gyro_radps, in.states[k].bias.accel_mps2;
    }
    gravity_ = in.g_w;
    free_gravity_ = in.gravity_sigma_rad > 0 && !in.imu_edges.empty();
    if (free_gravity_) gravity_prior_ = std::make_unique<optim_detail::GravityPriorCost>(in.g_w, in.gravity_sigma_rad);
    for (const BaImuEdge& e : in.imu_edges) {
      has_imu_state_[e.i] = has_imu_state_[e.j] = 1;
      if (free_gravity_) imu_costs_.push_back(optim_detail::make_imu_cost_free_gravity(*e.pre, in.T_b_c));
      else imu_costs_.push_back(optim_detail::make_imu_cost(*e.pre, in.T_b_c, in.g_w));
      walk_costs_.push_back(optim_detail::make_bias_walk_cost(*e.pre));
    }
    for (const BaWheelEdge& e : in.wheel_edges) {
      wheel_costs_.push_back(optim_detail::make_wheel_planar_cost(*e.pre, in.T_base_c));
      wheel_costs_.push_back(optim_detail::make_wheel_tilt_cost(*e.pre, in.T_base_c));
    }
    for (const BaGravityEdge& e : in.gravity_edges)
      gravity_costs_.push_back(optim_detail::make_gravity_cost(e.f_c, in.g_w, e.sigma_rad));
    if (in.wheel_huber > 0) wheel_loss_ = std::make_unique<ceres::HuberLoss>(in.wheel_huber);
  }

  bool free_fixed_states() const { return ba_.inertial->fixed_states_free; }
  /// A keyframe's pose block, once; constant for a fixed keyframe.
  void add_pose_block(ceres::Problem* prob, std::size_t k, std::vector<std::uint8_t>* kf_in) {
    if ((*kf_in)[k]) return;
    prob->AddParameterBlock(poses_[k].pose, optim_detail::kPoseSize, &se3_manifold_);
    if (ba_.keyframes[k].fixed) prob->SetParameterBlockConstant(poses_[k].pose);
    (*kf_in)[k] = 1;
  }

  /// A keyframe's pose, velocity and bias blocks, once; constant for a fixed keyframe.
  void add_state_blocks(ceres::Problem* prob, std::size_t k, std::vector<std::uint8_t>* kf_in,
                        std::vector<std::uint8_t>* state_in) {
    add_pose_block(prob, k, kf_in);
    if ((*state_in)[k]) return;
    prob->AddParameterBlock(velocities_[k].data(), 3);
    prob->AddParameterBlock(biases_[k].data(), 6);
    if (ba_.keyframes[k].fixed && !free_fixed_states()) {
      prob->SetParameterBlockConstant(velocities_[k].data());
      prob->SetParameterBlockConstant(biases_[k].data());
    }
    (*state_in)[k] = 1;
  }

  /// IMU edges with their bias walks, wheel edges (Huber), gravity edges.
  void add_inertial_residuals(ceres::Problem* prob, std::vector<std::uint8_t>* kf_in,
                              std::vector<std::uint8_t>* state_in) {
    const BaInertial& in = *ba_.inertial;
    state_in->assign(ba_.keyframes.size(), 0);
    for (std::size_t e = 0; e < in.imu_edges.size(); ++e) {
      const std::size_t i = in.imu_edges[e].i, j = in.imu_edges[e].j;
      add_state_blocks(prob, i, kf_in, state_in);
      add_state_blocks(prob, j, kf_in, state_in);
      std::vector<double*> blocks{poses_[i].pose, velocities_[i].data(), biases_[i].data(), poses_[j].pose,
                                  velocities_[j].data()};
      if (free_gravity_) blocks.push_back(gravity_.data());
      prob->AddResidualBlock(imu_costs_[e].get(), nullptr, blocks);
      prob->AddResidualBlock(walk_costs_[e].get(), nullptr, biases_[i].data(), biases_[j].data());
    }
    if (free_gravity_) {
      prob->SetManifold(gravity_.data(), &sphere_manifold_);
      prob->AddResidualBlock(gravity_prior_.get(), nullptr, gravity_.data());
    }
    for (std::size_t e = 0; e < in.wheel_edges.size(); ++e) {
      const std::size_t i = in.wheel_edges[e].i, j = in.wheel_edges[e].j;
      add_pose_block(prob, i, kf_in);
      add_pose_block(prob, j, kf_in);
      for (int part = 0; part < 2; ++part)
        prob->AddResidualBlock(wheel_costs_[2 * e + part].get(), wheel_loss_.get(), poses_[i].pose, poses_[j].pose);
    }
    for (std::size_t e = 0; e < in.gravity_edges.size(); ++e) {
      const std::size_t k = in.gravity_edges[e].keyframe;
      add_pose_block(prob, k, kf_in);
      prob->AddResidualBlock(gravity_costs_[e].get(), nullptr, poses_[k].pose);
    }
  }

  BaProblem& ba_;
  const StereoIntrinsics& K_;
  const BaOptions& options_;
  std::vector<PoseBlock> poses_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs_;
  ceres::HuberLoss huber_mono_, huber_stereo_;
  optim_detail::SE3LeftManifold se3_manifold_;
  std::vector<std::uint8_t> active_, keyframe_used_, point_used_;
  AbortCallback abort_callback_;
  // Inertial terms (BaProblem::inertial set), indexed like the keyframes / the edges.
  std::vector<Eigen::Vector3d> velocities_;               ///< velocity blocks
  std::vector<Eigen::Matrix<double, 6, 1>> biases_;       ///< bias blocks [b_g, b_a]
  std::vector<std::uint8_t> has_imu_state_;               ///< keyframe named by an IMU edge
  std::vector<std::unique_ptr<ceres::CostFunction>> imu_costs_, walk_costs_;  ///< per IMU edge
  std::vector<std::unique_ptr<ceres::CostFunction>> wheel_costs_;   ///< planar and tilt per wheel edge
  std::vector<std::unique_ptr<ceres::CostFunction>> gravity_costs_; ///< per gravity edge
  std::unique_ptr<ceres::HuberLoss> wheel_loss_;          ///< Huber of the wheel edges (null: none)
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();     ///< g_w's block (BaInertial::gravity_sigma_rad > 0)
  bool free_gravity_ = false;
  std::unique_ptr<ceres::CostFunction> gravity_prior_;
  ceres::SphereManifold<3> sphere_manifold_;
};

/// Checks the inertial part of a problem: one state per keyframe, edges
/// naming two different existing keyframes, non-empty increments.
void check_inertial(const BaProblem& ba) {
  const BaInertial& in = *ba.inertial;
  const std::size_t n = ba.keyframes.size();
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("local_bundle_adjustment: " + what);
  };
  if (in.states.size() != n) fail("inertial states must be one per keyframe");
  for (const BaImuEdge& e : in.imu_edges)
    if (e.i >= n || e.j >= n || e.i == e.j || !e.pre || !(e.pre->dt_s() > 0)) fail("bad IMU edge");
  for (const BaWheelEdge& e : in.wheel_edges)
    if (e.i >= n || e.j >= n || e.i == e.j || !e.pre) fail("bad wheel edge");
  for (const BaGravityEdge& e : in.gravity_edges)
    if (e.keyframe >= n || !(e.sigma_rad > 0) || !(e.f_c.norm() > 0)) fail("bad gravity edge");
}

}  // namespace

BaResult local_bundle_adjustment(BaProblem* problem, const StereoIntrinsics& K, const BaOptions& options) {
  if (problem == nullptr) throw std::invalid_argument("local_bundle_adjustment: null problem");
  BaProblem& ba = *problem;
  const std::size_t num_edges = ba.edges.size();
  for (std::size_t e = 0; e < num_edges; ++e) {
    if (ba.edges[e].keyframe >= ba.keyframes.size() || ba.edges[e].point >= ba.points.size()) {
      throw std::invalid_argument("local_bundle_adjustment: edge " + std::to_string(e) +
                                  " refers to a missing keyframe or point");
    }
  }
  if (ba.inertial) check_inertial(ba);
  const bool inertial_terms = ba.inertial && (!ba.inertial->imu_edges.empty() || !ba.inertial->wheel_edges.empty() ||
                                              !ba.inertial->gravity_edges.empty());
  BaResult result;
  if (num_edges == 0 && !inertial_terms) {
    result.converged = true;  // nothing to optimise
    return result;
  }
  // Stopped before it began (ORB-SLAM2 returns here too): nothing is
  // changed and no outlier is reported.
  if (aborted(options.abort_flag)) {
    result.stopped = true;
    return result;
  }
  LocalBa local_ba(ba, K, options);
  local_ba.run(&result);
  local_ba.write_back();
  return result;
}

// ---------------------------------------------------------------------------
// SE(3) pose graph
// ---------------------------------------------------------------------------
PoseGraphResult optimize_pose_graph(PoseGraphProblem* problem, const PoseGraphOptions& options) {
  if (problem == nullptr) throw std::invalid_argument("optimize_pose_graph: null problem");
  PoseGraphProblem& g = *problem;
  for (std::size_t e = 0; e < g.edges.size(); ++e)
    if (g.edges[e].i >= g.nodes.size() || g.edges[e].j >= g.nodes.size() || g.edges[e].i == g.edges[e].j)
      throw std::invalid_argument("optimize_pose_graph: edge " + std::to_string(e) + " refers to a missing node");
  PoseGraphResult result;
  if (g.edges.empty()) return result;

  std::vector<PoseBlock> poses(g.nodes.size());
  for (std::size_t k = 0; k < g.nodes.size(); ++k) poses[k] = PoseBlock::from_se3(g.nodes[k].T_c_w);
  optim_detail::SE3LeftManifold se3_manifold;
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem cp(po);
  for (std::size_t k = 0; k < g.nodes.size(); ++k) cp.AddParameterBlock(poses[k].pose, optim_detail::kPoseSize, &se3_manifold);
  for (const PoseGraphEdge& e : g.edges)
    cp.AddResidualBlock(new optim_detail::RelativePoseError(e.T_i_j, e.weight, e.rotation_weight), nullptr, poses[e.i].pose,
                        poses[e.j].pose);
  for (std::size_t k = 0; k < g.nodes.size(); ++k)
    if (g.nodes[k].fixed) cp.SetParameterBlockConstant(poses[k].pose);  // the gauge (and what the caller pins)

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;  // a sparse graph of 6-DoF blocks
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.max_num_iterations = options.iterations;
  so.num_threads = 1;  // deterministic
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &cp, &summary);
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size());
  for (std::size_t k = 0; k < g.nodes.size(); ++k)
    if (!g.nodes[k].fixed) g.nodes[k].T_c_w = poses[k].to_se3();
  return result;
}

}  // namespace pvb::slam
