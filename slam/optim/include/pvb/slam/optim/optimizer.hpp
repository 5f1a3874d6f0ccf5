#pragma once
// Pose-only optimisation and local bundle adjustment for RGB-D SLAM (the
// parts of ORB-SLAM2's g2o Optimizer that tracking and local mapping use),
// pose-only by a small Levenberg-Marquardt of its own, local BA on Ceres.
// Inputs in, result out: no map types here, so the
// optimiser is tested on synthetic problems and the SLAM core converts its
// map into these structs.
//
// Conventions: T_c_w maps world points into the camera (optical) frame.
// An observation with u_right >= 0 is "stereo" (RGB-D: u_right = u - bf / z),
// with a 3-D residual (u, v, u_right); else monocular (u, v).
#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "pvb/geometry/se3.hpp"

namespace pvb::slam {

/// Pinhole intrinsics plus the RGB-D virtual baseline (bf = baseline x fx).
struct StereoIntrinsics {
  double fx = 525, fy = 525, cx = 319.5, cy = 239.5;
  double bf = 40.0;
};

/// One keypoint measurement of a 3-D point.
struct Observation {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  ///< pixel (undistorted)
  double u_right = -1.0;                         ///< < 0: monocular
  double inv_sigma2 = 1.0;                       ///< 1 / sigma^2 of its pyramid level (ORB-SLAM2: 1 / 1.2^(2 level))
};

struct PoseOptimizerOptions {
  int rounds = 4;                  ///< ORB-SLAM2: 4 rounds of 10 iterations, re-classifying outliers
  int iterations_per_round = 10;
  double chi2_mono = 5.991;        ///< chi-square 95 %, 2 DoF
  double chi2_stereo = 7.815;      ///< chi-square 95 %, 3 DoF
  bool robust = true;              ///< Huber loss (delta = sqrt(chi2)) in the first rounds
  int robust_rounds = 2;           ///< rounds [0, robust_rounds) use Huber (ORB-SLAM2 drops it from round 2)
  bool restart_from_initial = true; ///< ORB-SLAM2 restarts every round from T_c_w_init
};

struct PoseOptimizerResult {
  geom::SE3d T_c_w;                 ///< optimised pose
  std::vector<std::uint8_t> inlier; ///< per observation, after the last round
  int num_inliers = 0;
  double final_cost = 0;            ///< robust cost 0.5 sum of rho(chi2) at the end of the last round
};

/// Optimises one camera pose against fixed 3-D points (ORB-SLAM2's
/// Optimizer::PoseOptimization).  points_w[i] is observed by obs[i].
/// Outliers (chi2 above the threshold) are excluded from the next round and
/// reported in `inlier`.  Each round is Levenberg-Marquardt on the 6-DoF
/// tangent of the pose (g2o's schedule, as ORB-SLAM2), Huber as IRLS
/// weights; deterministic.
PoseOptimizerResult optimize_pose(const geom::SE3d& T_c_w_init, const std::vector<Eigen::Vector3d>& points_w,
                                  const std::vector<Observation>& obs, const StereoIntrinsics& K,
                                  const PoseOptimizerOptions& options = {});

/// A local bundle-adjustment problem (ORB-SLAM2's Optimizer::LocalBundleAdjustment).
struct BaKeyframe {
  std::uint64_t id = 0;
  geom::SE3d T_c_w;
  bool fixed = false;  ///< fixed keyframes observe local points but do not move
};
struct BaPoint {
  std::uint64_t id = 0;
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
};
struct BaEdge {
  std::size_t keyframe = 0;  ///< index into BaProblem::keyframes
  std::size_t point = 0;     ///< index into BaProblem::points
  Observation obs;
};
struct BaInertial;  // inertial_ba.hpp
struct BaProblem {
  std::vector<BaKeyframe> keyframes;
  std::vector<BaPoint> points;
  std::vector<BaEdge> edges;
  /// Optional inertial and wheel terms (null: visual only, as before).
  std::shared_ptr<BaInertial> inertial;
};

struct BaOptions {
  int iterations_first = 5;   ///< with Huber loss
  int iterations_second = 10; ///< without the outliers of the first pass
  double chi2_mono = 5.991;
  double chi2_stereo = 7.815;
  /// Optional: stop early once it becomes true (ORB-SLAM2's pbStopFlag).
  /// Another thread may set it while the solve runs (local mapping sets it
  /// when a new keyframe arrives).  Set before the call: nothing changes and
  /// no outlier is reported.  Set during the first pass: the estimate so far
  /// is kept and the second pass skipped.
  const std::atomic<bool>* abort_flag = nullptr;
  /// Optional: called after every iteration of either pass (iteration 0,
  /// the start, included), before abort_flag is looked at.  Tests use it to
  /// raise the flag at a chosen iteration.
  std::function<void()> on_iteration;
  /// Sparse Schur complement (global BA over the whole map: many keyframes,
  /// each seeing a few others); false: dense (local BA, a few dozen keyframes).
  bool sparse_schur = false;
};

struct BaResult {
  std::vector<std::size_t> outlier_edges;  ///< edges to erase from the map (chi2 too big or point behind camera)
  int iterations = 0;
  bool converged = false;
  /// The abort flag cut a pass short or skipped the second pass.
  bool stopped = false;
};

/// Optimises the non-fixed keyframe poses and all points in place.
BaResult local_bundle_adjustment(BaProblem* problem, const StereoIntrinsics& K, const BaOptions& options = {});

/// An SE(3) pose graph (ORB-SLAM2's Optimizer::OptimizeEssentialGraph with
/// scale fixed, as for RGB-D): nodes are keyframe poses T_c_w, edges are
/// measured relative poses T_i_j = T_iw * T_jw^-1 (camera j in camera i).
struct PoseGraphNode {
  std::uint64_t id = 0;
  geom::SE3d T_c_w;    ///< initial value in, optimised value out
  bool fixed = false;  ///< held constant (at least one node fixes the gauge)
};
struct PoseGraphEdge {
  std::size_t i = 0, j = 0;  ///< indices into PoseGraphProblem::nodes
  geom::SE3d T_i_j;          ///< measured pose of camera j in camera i
  double weight = 1.0;       ///< information = weight^2 * diag(r^2 I3, I3)
  double rotation_weight = 1.0;  ///< r: rotation rows (radians) against translation rows (metres)
};
struct PoseGraphProblem {
  std::vector<PoseGraphNode> nodes;
  std::vector<PoseGraphEdge> edges;
};
struct PoseGraphOptions {
  int iterations = 20;  ///< Levenberg-Marquardt iterations (ORB-SLAM2: 20)
};
struct PoseGraphResult {
  double initial_cost = 0, final_cost = 0;  ///< 0.5 sum |r|^2
  int iterations = 0;
};

/// Optimises the non-fixed nodes in place.  Residual per edge:
/// r = weight [rotation_weight Log(R_E); t_E] with E = T_i_j^-1 T_iw T_jw^-1 (zero when the
/// poses agree with the measurement).  Deterministic (single thread).
/// Throws std::invalid_argument for an edge naming a missing node.
PoseGraphResult optimize_pose_graph(PoseGraphProblem* problem, const PoseGraphOptions& options = {});

/// Reprojection residual helpers (also used by tests and by map-point culling).
Eigen::Vector2d project(const StereoIntrinsics& K, const Eigen::Vector3d& p_c);
/// chi2 of one observation of p_w seen from T_c_w (weighted by inv_sigma2).
/// +infinity when p_w is not in front of the camera (z_c <= 0).
double observation_chi2(const StereoIntrinsics& K, const geom::SE3d& T_c_w, const Eigen::Vector3d& p_w,
                        const Observation& obs);

}  // namespace pvb::slam
