#include "pvb/eval/align.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pvb/common/error.hpp"
#include "pvb/eval/trajectory.hpp"

namespace pvb::eval {
namespace {
// A point set whose second principal variance is below this fraction of the
// first is collinear to double precision (a spread ratio of 1e-6: 6 um of
// wobble on a 20 m row), as evo's rank test decides.  A nearly straight drive
// (a robot along a PV row) still aligns: the rotation about the line is
// poorly determined, but it barely moves points that lie near the line, so
// ATE stays meaningful, as with the TUM script's Horn alignment.
constexpr double kCollinearRatio = 1e-12;

enum class Spread { kPoint, kLine, kFull };

/// How a finite point set spreads about its mean (kFull when a coordinate is
/// not finite, so that the caller's checks name it).
Spread spread_of(const std::vector<geom::Vec3d>& pts) {
  geom::Vec3d mean = geom::Vec3d::Zero();
  for (const geom::Vec3d& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  geom::Mat3d cov = geom::Mat3d::Zero();
  for (const geom::Vec3d& p : pts) cov += (p - mean) * (p - mean).transpose();
  if (!cov.allFinite()) return Spread::kFull;
  const Eigen::JacobiSVD<geom::Mat3d> svd(cov);
  const geom::Vec3d sv = svd.singularValues();  // variances along principal axes, descending
  if (sv(0) <= 1e-18) return Spread::kPoint;
  return sv(1) <= kCollinearRatio * sv(0) ? Spread::kLine : Spread::kFull;
}

void check_not_collinear(const std::vector<geom::Vec3d>& pts, const char* which) {
  const Spread spread = spread_of(pts);
  if (spread == Spread::kPoint)
    throw EvalError(std::string("cannot align: all ") + which + " positions are the same point");
  if (spread == Spread::kLine)
    throw EvalError(std::string("cannot align: the ") + which +
                    " positions are collinear (degenerate), so the rotation about that line is "
                    "undetermined; use --align origin or --align none");
}

/// se3/sim3 when one position set lies on a line (a simulated robot driving
/// exactly straight on flat ground).  The cross-covariance then has rank one,
/// Sigma = sigma0 x y^T: every rotation taking y onto x is a least-squares
/// optimum, and the positions' errors do not depend on the turn about x.
/// That turn is taken from the orientations instead: the angle about x that
/// maximises sum trace(R_gt_i^T R R_est_i).
Sim3Transform line_alignment(const std::vector<geom::SE3d>& est, const std::vector<geom::SE3d>& gt,
                             bool with_scale) {
  const std::size_t n = est.size();
  geom::Vec3d mu_est = geom::Vec3d::Zero(), mu_gt = geom::Vec3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mu_est += est[i].translation();
    mu_gt += gt[i].translation();
  }
  mu_est /= static_cast<double>(n);
  mu_gt /= static_cast<double>(n);
  geom::Mat3d sigma = geom::Mat3d::Zero(), M = geom::Mat3d::Zero();
  double var_est = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const geom::Vec3d de = est[i].translation() - mu_est;
    sigma += (gt[i].translation() - mu_gt) * de.transpose();
    var_est += de.squaredNorm();
    M += est[i].linear() * gt[i].linear().transpose();
  }
  sigma /= static_cast<double>(n);
  var_est /= static_cast<double>(n);
  const Eigen::JacobiSVD<geom::Mat3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  if (!(svd.singularValues()(0) > 1e-18))
    throw EvalError("cannot align: the estimated and ground-truth positions do not vary together");
  const geom::Vec3d x = svd.matrixU().col(0), y = svd.matrixV().col(0);
  const geom::Mat3d R0 = Eigen::Quaterniond::FromTwoVectors(y, x).toRotationMatrix();
  // trace(Rot(x, theta) A) = cos(theta) (tr A - x^T A x) + sin(theta) tr([x]_x A) + x^T A x.
  const geom::Mat3d A = R0 * M;
  geom::Mat3d x_cross;
  x_cross << 0, -x.z(), x.y(), x.z(), 0, -x.x(), -x.y(), x.x(), 0;
  const double theta = std::atan2((x_cross * A).trace(), A.trace() - x.dot(A * x));
  Sim3Transform out;
  out.R = Eigen::AngleAxisd(theta, x).toRotationMatrix() * R0;
  out.s = with_scale ? svd.singularValues()(0) / var_est : 1.0;
  out.t = mu_gt - out.s * out.R * mu_est;
  return out;
}

}  // namespace

Alignment parse_alignment(const std::string& name) {
  if (name == "se3") return Alignment::kSe3;
  if (name == "sim3") return Alignment::kSim3;
  if (name == "none") return Alignment::kNone;
  if (name == "origin") return Alignment::kOrigin;
  throw ConfigError("command line", "--align", "one of se3, sim3, none, origin", name);
}

const char* alignment_name(Alignment a) {
  switch (a) {
    case Alignment::kSe3: return "se3";
    case Alignment::kSim3: return "sim3";
    case Alignment::kNone: return "none";
    case Alignment::kOrigin: return "origin";
  }
  return "?";
}

Sim3Transform umeyama(const std::vector<geom::Vec3d>& est, const std::vector<geom::Vec3d>& gt,
                      bool with_scale) {
  if (est.size() != gt.size()) throw EvalError("cannot align: point sets differ in size");
  const std::size_t n = est.size();
  if (n < 3)
    throw EvalError("cannot align: " + std::to_string(n) +
                    " associated pose pair(s), at least 3 are needed for se3/sim3 alignment");
  for (std::size_t i = 0; i < n; ++i)
    if (!plausible_position(est[i]) || !plausible_position(gt[i]))
      throw EvalError("cannot align: a position is not finite or lies beyond 1e8 m");
  geom::Vec3d mu_est = geom::Vec3d::Zero(), mu_gt = geom::Vec3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mu_est += est[i];
    mu_gt += gt[i];
  }
  mu_est /= static_cast<double>(n);
  mu_gt /= static_cast<double>(n);
  check_not_collinear(est, "estimated");
  check_not_collinear(gt, "ground-truth");

  // Cross-covariance Sigma = 1/n sum (gt_i - mu_gt)(est_i - mu_est)^T.
  geom::Mat3d sigma = geom::Mat3d::Zero();
  double var_est = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const geom::Vec3d de = est[i] - mu_est;
    sigma += (gt[i] - mu_gt) * de.transpose();
    var_est += de.squaredNorm();
  }
  sigma /= static_cast<double>(n);
  var_est /= static_cast<double>(n);

  const Eigen::JacobiSVD<geom::Mat3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  geom::Mat3d S = geom::Mat3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  Sim3Transform out;
  out.R = svd.matrixU() * S * svd.matrixV().transpose();
  out.s = with_scale ? (svd.singularValues().asDiagonal() * S).trace() / var_est : 1.0;
  out.t = mu_gt - out.s * out.R * mu_est;
  return out;
}

Sim3Transform compute_alignment(const std::vector<geom::SE3d>& est, const std::vector<geom::SE3d>& gt,
                                Alignment kind) {
  if (est.size() != gt.size()) throw EvalError("cannot align: pose lists differ in size");
  switch (kind) {
    case Alignment::kNone: return {};
    case Alignment::kOrigin: {
      if (est.empty()) throw EvalError("cannot align: no associated pose pairs");
      // T such that T * est_0 == gt_0.
      const geom::SE3d T = gt.front() * est.front().inverse();
      Sim3Transform out;
      out.R = T.linear();
      out.t = T.translation();
      return out;
    }
    case Alignment::kSe3:
    case Alignment::kSim3: {
      std::vector<geom::Vec3d> p_est, p_gt;
      p_est.reserve(est.size());
      p_gt.reserve(gt.size());
      for (std::size_t i = 0; i < est.size(); ++i) {
        p_est.push_back(est[i].translation());
        p_gt.push_back(gt[i].translation());
      }
      const bool sim3 = kind == Alignment::kSim3;
      const auto plausible = [](const std::vector<geom::Vec3d>& pts) {
        return std::all_of(pts.begin(), pts.end(), [](const geom::Vec3d& p) { return plausible_position(p); });
      };
      if (est.size() >= 3 && plausible(p_est) && plausible(p_gt)) {
        const Spread se = spread_of(p_est), sg = spread_of(p_gt);
        if (se != Spread::kPoint && sg != Spread::kPoint && (se == Spread::kLine || sg == Spread::kLine))
          return line_alignment(est, gt, sim3);
      }
      return umeyama(p_est, p_gt, sim3);
    }
  }
  return {};
}

std::vector<geom::SE3d> apply_alignment(const Sim3Transform& transform, const std::vector<geom::SE3d>& poses) {
  std::vector<geom::SE3d> out;
  out.reserve(poses.size());
  for (const geom::SE3d& T : poses) out.push_back(transform.apply(T));
  return out;
}

}  // namespace pvb::eval
