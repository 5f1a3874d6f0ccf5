// Inertial initialisation from keyframe poses that vision fixed (the
// inertial-only optimisation of ORB-SLAM3, Campos et al., T-RO 2021,
// section V-B, with the poses' scale known as for RGB-D): the gyro bias
// from the rotations, then the velocities, the direction of gravity and the
// biases together under zero-mean bias priors.
#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pvb/slam/inertial/inertial_residuals.hpp"
#include "pvb/slam/optim/inertial_ba.hpp"

namespace pvb::slam {
namespace {

using PoseArray = std::array<double, 7>;

PoseArray to_block(const geom::SE3d& T_c_w) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(T_c_w.linear()).normalized();
  const Eigen::Vector3d t = T_c_w.translation();
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

void check(const InertialInitProblem& p) {
  const auto fail = [](const std::string& what) { throw std::invalid_argument("initialize_inertial: " + what); };
  if (p.T_c_w.size() < 2) fail("needs at least two keyframes");
  if (p.pre.size() + 1 != p.T_c_w.size()) fail("needs one preintegration per pair of consecutive keyframes");
  for (const auto& pre : p.pre)
    if (!pre || !(pre->dt_s() > 0)) fail("empty or missing preintegration");
  if (!(p.g_w_guess.norm() > 0)) fail("g_w_guess must not be zero");
  if (!(p.gyro_bias_prior_radps > 0) || !(p.accel_bias_prior_mps2 > 0)) fail("bias priors must be positive");
}

/// An interval's covariance with the noise of its two fixed poses added:
/// rotation 2 s_R^2; velocity 2 (|g| dt s_R)^2 (gravity turned by a rotation
/// error); position 2 s_p^2 + 2 (|g| dt^2 s_R / 2)^2.
Eigen::Matrix<double, 9, 9> interval_covariance(const ImuPreintegration& pre, const InertialInitProblem& p) {
  Eigen::Matrix<double, 9, 9> cov = pre.covariance();
  const double dt = pre.dt_s(), g = p.g_w_guess.norm(), s_R = p.pose_sigma_rad, s_p = p.pose_sigma_m;
  const double var_R = 2 * s_R * s_R, var_v = 2 * std::pow(g * dt * s_R, 2);
  const double var_p = 2 * s_p * s_p + 2 * std::pow(0.5 * g * dt * dt * s_R, 2);
  for (int k = 0; k < 3; ++k) {
    cov(k, k) += var_R;
    cov(3 + k, 3 + k) += var_v;
    cov(6 + k, 6 + k) += var_p;
  }
  return cov;
}

/// Whitened rotation residual of one interval as a function of the gyro
/// bias alone: W_R Log(dR(b_g)^T R_i^T R_j) (3).
struct GyroBiasResidual {
  const ImuFactor* f;         ///< the interval's factor (its rotation parts)
  Eigen::Quaterniond q_ij;    ///< R_i^T R_j of the IMU, from the fixed poses
  Eigen::Matrix3d W;          ///< whitening of the rotation rows

  template <typename T>
  bool operator()(const T* bg, T* r) const {
    const Eigen::Map<const Vec3T<T>> b(bg);
    const QuatT<T> q_corr = f->q_dR.cast<T>() * quaternion_exp_t<T>(f->J_R_bg.cast<T>() * (b - f->bg0.cast<T>()));
    const Vec3T<T> e = quaternion_log_t<T>(q_corr.conjugate() * q_ij.cast<T>());
    Eigen::Map<Vec3T<T>> out(r);
    out = W.cast<T>() * e;
    return true;
  }
};

/// The full 9-D residual with fixed poses; variables v_i, v_j, the 2-D
/// rotation theta of gravity (g = Exp(theta_0 e1 + theta_1 e2) g0) and one bias.
struct InitImuResidual {
  const ImuFactor* f;              ///< the interval's factor
  const PoseArray* pose_i;         ///< camera pose of keyframe i
  const PoseArray* pose_j;         ///< camera pose of keyframe j
  Eigen::Vector3d g0, e1, e2;      ///< initial gravity and the axes theta turns it about

  template <typename T>
  bool operator()(const T* v_i, const T* v_j, const T* theta, const T* bias, T* r) const {
    T pi[7], pj[7];
    for (int k = 0; k < 7; ++k) {
      pi[k] = T((*pose_i)[k]);
      pj[k] = T((*pose_j)[k]);
    }
    const Vec3T<T> axis = e1.cast<T>() * theta[0] + e2.cast<T>() * theta[1];
    const Vec3T<T> g = quaternion_exp_t<T>(axis) * g0.cast<T>();
    f->residual(pi, v_i, bias, pj, v_j, g.data(), r);
    return true;
  }
};

/// Zero-mean prior on the bias: [b_g / sigma_g, b_a / sigma_a] (6).
struct BiasPrior {
  double inv_sigma_g, inv_sigma_a;  ///< 1 / prior sigmas
  template <typename T>
  bool operator()(const T* b, T* r) const {
    for (int k = 0; k < 3; ++k) {
      r[k] = b[k] * T(inv_sigma_g);
      r[3 + k] = b[3 + k] * T(inv_sigma_a);
    }
    return true;
  }
};

/// Zero-mean prior on the gyro bias alone (3).
struct GyroPrior {
  double inv_sigma;  ///< 1 / prior sigma
  template <typename T>
  bool operator()(const T* bg, T* r) const {
    for (int k = 0; k < 3; ++k) r[k] = bg[k] * T(inv_sigma);
    return true;
  }
};

ceres::Solver::Options solver_options() {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::DENSE_QR;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.max_num_iterations = 50;
  o.num_threads = 1;  // deterministic
  o.logging_type = ceres::SILENT;
  return o;
}

/// Step 1: the gyro bias that best explains the fixed rotations.
Eigen::Vector3d solve_gyro_bias(const InertialInitProblem& p, const std::vector<ImuFactor>& factors,
                                const std::vector<PoseArray>& poses) {
  Eigen::Vector3d bg = p.bias_guess.gyro_radps;
  ceres::Problem prob;
  for (std::size_t k = 0; k < factors.size(); ++k) {
    const ImuFactor& f = factors[k];
    QuatT<double> q_i, q_j;
    Vec3T<double> unused;
    CameraPoseT<double>(poses[k].data()).attached(f.q_c_b, f.p_c_b, &q_i, &unused);
    CameraPoseT<double>(poses[k + 1].data()).attached(f.q_c_b, f.p_c_b, &q_j, &unused);
    const Eigen::Matrix3d W = sqrt_information<3>(interval_covariance(*p.pre[k], p).topLeftCorner<3, 3>());
    prob.AddResidualBlock(new ceres::AutoDiffCostFunction<GyroBiasResidual, 3, 3>(
                              new GyroBiasResidual{&f, q_i.conjugate() * q_j, W}),
                          nullptr, bg.data());
  }
  prob.AddResidualBlock(new ceres::AutoDiffCostFunction<GyroPrior, 3, 3>(new GyroPrior{1.0 / p.gyro_bias_prior_radps}),
                        nullptr, bg.data());
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options(), &prob, &summary);
  return bg;
}

/// Gravity from the velocity changes: g T = (v_N - v_0) - sum R_i dv_k
/// (ORB-SLAM3 takes the sum alone), scaled to |g_w_guess|; the guess
/// itself when that sum says nothing.
Eigen::Vector3d initial_gravity(const InertialInitProblem& p, const std::vector<ImuFactor>& factors,
                                const std::vector<PoseArray>& poses, const std::vector<Eigen::Vector3d>& v) {
  Eigen::Vector3d sum = v.back() - v.front();
  double T = 0;
  for (std::size_t k = 0; k < factors.size(); ++k) {
    QuatT<double> q_i;
    Vec3T<double> unused;
    CameraPoseT<double>(poses[k].data()).attached(factors[k].q_c_b, factors[k].p_c_b, &q_i, &unused);
    sum -= q_i * factors[k].dv;
    T += factors[k].dt_s;
  }
  const Eigen::Vector3d g = sum / T;
  if (!(g.norm() > 0.1 * p.g_w_guess.norm())) return p.g_w_guess;
  return g.normalized() * p.g_w_guess.norm();
}

/// Velocities of the IMU by finite differences of its positions.
std::vector<Eigen::Vector3d> initial_velocities(const std::vector<ImuFactor>& factors,
                                                const std::vector<PoseArray>& poses) {
  const std::size_t n = poses.size();
  std::vector<Eigen::Vector3d> p(n), v(n);
  std::vector<double> t(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    QuatT<double> q;
    CameraPoseT<double>(poses[k].data()).attached(factors[0].q_c_b, factors[0].p_c_b, &q, &p[k]);
    if (k > 0) t[k] = t[k - 1] + factors[k - 1].dt_s;
  }
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 == n ? k : k + 1;
    v[k] = (p[b] - p[a]) / (t[b] - t[a]);
  }
  return v;
}

/// Step 2: velocities, gravity's direction and both biases, the
/// preintegrations linearised at `bias`.  Returns false if Ceres failed.
bool solve_full(const InertialInitProblem& p, const std::vector<ImuFactor>& factors,
                const std::vector<PoseArray>& poses, InertialInitResult* out, Eigen::Matrix<double, 6, 1>* bias) {
  std::vector<Eigen::Vector3d>& v = out->v_w_mps;
  const Eigen::Vector3d g0 = out->g_w;
  Eigen::Index axis = 0;
  g0.cwiseAbs().minCoeff(&axis);
  const Eigen::Vector3d e1 = g0.cross(Eigen::Vector3d::Unit(axis)).normalized(), e2 = g0.normalized().cross(e1);
  double theta[2] = {0.0, 0.0};
  ceres::Problem prob;
  for (std::size_t k = 0; k < factors.size(); ++k) {
    auto* r = new InitImuResidual{&factors[k], &poses[k], &poses[k + 1], g0, e1, e2};
    prob.AddResidualBlock(new ceres::AutoDiffCostFunction<InitImuResidual, 9, 3, 3, 2, 6>(r), nullptr, v[k].data(),
                          v[k + 1].data(), theta, bias->data());
  }
  prob.AddResidualBlock(new ceres::AutoDiffCostFunction<BiasPrior, 6, 6>(
                            new BiasPrior{1.0 / p.gyro_bias_prior_radps, 1.0 / p.accel_bias_prior_mps2}),
                        nullptr, bias->data());
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options(), &prob, &summary);
  out->g_w = quaternion_exp_t<double>(e1 * theta[0] + e2 * theta[1]) * g0;
  out->bias.gyro_radps = bias->head<3>();
  out->bias.accel_mps2 = bias->tail<3>();
  return summary.IsSolutionUsable();
}

/// RMS of the whitened 9-D residuals at the result.
double rms_whitened(const std::vector<ImuFactor>& factors, const std::vector<PoseArray>& poses,
                    const InertialInitResult& r) {
  double sum = 0;
  Eigen::Matrix<double, 6, 1> b;
  b << r.bias.gyro_radps, r.bias.accel_mps2;
  for (std::size_t k = 0; k < factors.size(); ++k) {
    Eigen::Matrix<double, 9, 1> e;
    factors[k].residual(poses[k].data(), r.v_w_mps[k].data(), b.data(), poses[k + 1].data(), r.v_w_mps[k + 1].data(),
                        r.g_w.data(), e.data());
    sum += e.squaredNorm();
  }
  return std::sqrt(sum / (9.0 * static_cast<double>(factors.size())));
}

std::vector<ImuFactor> factors_of(const std::vector<std::shared_ptr<const ImuPreintegration>>& pre,
                                  const InertialInitProblem& problem) {
  std::vector<ImuFactor> f;
  f.reserve(pre.size());
  for (const auto& p : pre) {
    f.emplace_back(*p, problem.T_b_c);
    f.back().sqrt_info = sqrt_information<9>(interval_covariance(*p, problem));
  }
  return f;
}

}  // namespace

InertialInitResult initialize_inertial(const InertialInitProblem& problem) {
  check(problem);
  std::vector<PoseArray> poses;
  for (const geom::SE3d& T : problem.T_c_w) poses.push_back(to_block(T));
  InertialInitResult result;
  // 1. The gyro bias from the rotations alone, at the given linearisation.
  const Eigen::Vector3d bg = solve_gyro_bias(problem, factors_of(problem.pre, problem), poses);
  // 2. Velocities, gravity and both biases, the increments integrated again
  // at the current bias until it settles (at most three rounds).
  Eigen::Matrix<double, 6, 1> bias;
  bias << bg, problem.bias_guess.accel_mps2;
  std::vector<std::shared_ptr<const ImuPreintegration>> pre;
  std::vector<ImuFactor> factors;
  bool ok = true;
  for (int round = 0; round < 3; ++round) {
    const ImuBias lin{bias.head<3>(), bias.tail<3>()};
    pre.clear();
    for (const auto& p : problem.pre) {
      auto copy = std::make_shared<ImuPreintegration>(*p);
      copy->reintegrate(lin);
      pre.push_back(copy);
    }
    factors = factors_of(pre, problem);
    if (round == 0) {
      result.v_w_mps = initial_velocities(factors, poses);
      result.g_w = initial_gravity(problem, factors, poses, result.v_w_mps);
    }
    const Eigen::Matrix<double, 6, 1> before = bias;
    ok = solve_full(problem, factors, poses, &result, &bias);
    if (!ok) break;
    // Settled: the first-order correction is then far below the noise.
    if ((bias.head<3>() - before.head<3>()).norm() < 1e-4 && (bias.tail<3>() - before.tail<3>()).norm() < 1e-3) break;
  }
  result.ok = ok && result.g_w.allFinite() && bias.allFinite();
  result.rms_whitened = rms_whitened(factors, poses, result);
  return result;
}

}  // namespace pvb::slam
