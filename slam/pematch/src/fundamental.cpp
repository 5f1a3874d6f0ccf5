#include "pvb/slam/pematch/fundamental.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <limits>

namespace pvb::slam {
namespace {

/// Relative size below which a pivot of the 8x9 system counts as zero
/// (null space of dimension >= 2: degenerate sample).
constexpr double kDegenerateRelPivot = 1e-9;

/// Zeroes the smallest singular value of F (rank-2 constraint, sec. 4.1).
/// With F = U S V^T and v3 the right singular vector of the smallest
/// singular value s3, F v3 = s3 u3, so F (I - v3 v3^T) = F - s3 u3 v3^T is
/// the nearest rank-2 matrix (Frobenius).  v3 is the eigenvector of F^T F
/// with the smallest eigenvalue, from the closed-form 3x3 solver.
Eigen::Matrix3d enforce_rank2(const Eigen::Matrix3d& F) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(F.transpose() * F);
  const Eigen::Vector3d v3 = es.eigenvectors().col(0);
  return F - (F * v3) * v3.transpose();
}

/// One row of eq. 5 for normalised (x1, y1) <-> (x2, y2).
template <typename Row>
void fill_row(Row&& r, double x1, double y1, double x2, double y2) {
  r << x2 * x1, x2 * y1, x2, y2 * x1, y2 * y1, y2, x1, y1, 1.0;
}

}  // namespace

Normalization hartley_normalization(const Eigen::Vector2d* pts, std::size_t n, std::size_t stride) {
  Normalization out;
  if (n == 0) return out;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < n; ++i) mean += pts[i * stride];
  mean /= static_cast<double>(n);
  double dist = 0.0;
  for (std::size_t i = 0; i < n; ++i) dist += (pts[i * stride] - mean).norm();
  dist /= static_cast<double>(n);
  const double s = dist > 1e-12 ? std::sqrt(2.0) / dist : 1.0;
  out.T << s, 0, -s * mean.x(), 0, s, -s * mean.y(), 0, 0, 1;
  return out;
}

bool solve_fundamental_8_normalized(const Eigen::Matrix<double, 8, 2>& x1, const Eigen::Matrix<double, 8, 2>& x2,
                                    Eigen::Matrix3d& F) {
  // Null vector of the 8x9 system of eq. 5 by Gaussian elimination with full
  // pivoting (rank-revealing, fixed size, ~200 flops), on a row-major array.
  double A[8][9];
  for (int i = 0; i < 8; ++i) {
    const double u1 = x1(i, 0), v1 = x1(i, 1), u2 = x2(i, 0), v2 = x2(i, 1);
    double* r = A[i];
    r[0] = u2 * u1; r[1] = u2 * v1; r[2] = u2;
    r[3] = v2 * u1; r[4] = v2 * v1; r[5] = v2;
    r[6] = u1;      r[7] = v1;      r[8] = 1.0;
    for (int c = 0; c < 9; ++c)
      if (!std::isfinite(r[c])) return false;
  }
  int col[9] = {0, 1, 2, 3, 4, 5, 6, 7, 8};  // column permutation
  double first_pivot = 0.0;
  for (int k = 0; k < 8; ++k) {
    // Partial (row) pivoting on column k; only when that column has no
    // usable pivot left, search the whole remaining block (column pivoting).
    int pr = k, pc = k;
    double best = -1.0;
    for (int r = k; r < 8; ++r) {
      const double v = std::abs(A[r][k]);
      if (v > best) {
        best = v;
        pr = r;
      }
    }
    if (k == 0) {
      // Scale reference for the degeneracy test: the largest entry of A.
      for (int r = 0; r < 8; ++r)
        for (int c = 0; c < 9; ++c) first_pivot = std::max(first_pivot, std::abs(A[r][c]));
    }
    if (!(best > kDegenerateRelPivot * first_pivot)) {
      for (int r = k; r < 8; ++r)
        for (int c = k; c < 9; ++c) {
          const double v = std::abs(A[r][c]);
          if (v > best) {
            best = v;
            pr = r;
            pc = c;
          }
        }
    }
    // Null space of dimension >= 2: degenerate sample (e.g. collinear points).
    if (!(first_pivot > 0.0) || !(best > kDegenerateRelPivot * first_pivot)) return false;
    if (pr != k)
      for (int c = 0; c < 9; ++c) std::swap(A[pr][c], A[k][c]);
    if (pc != k) {
      for (int r = 0; r < 8; ++r) std::swap(A[r][pc], A[r][k]);
      std::swap(col[pc], col[k]);
    }
    const double inv = 1.0 / A[k][k];
    for (int r = k + 1; r < 8; ++r) {
      const double f = A[r][k] * inv;
      for (int c = k + 1; c < 9; ++c) A[r][c] -= f * A[k][c];
      A[r][k] = 0.0;
    }
  }
  // Back-substitution with the free (9th permuted) unknown set to 1.
  double y[9];
  y[8] = 1.0;
  for (int k = 7; k >= 0; --k) {
    double s = A[k][8];
    for (int c = k + 1; c < 8; ++c) s += A[k][c] * y[c];
    y[k] = -s / A[k][k];
  }
  double f[9];
  for (int c = 0; c < 9; ++c) f[col[c]] = y[c];
  Eigen::Matrix3d Fn;
  Fn << f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8];
  Fn /= Fn.norm();
  F = enforce_rank2(Fn);
  return F.allFinite();
}

bool fundamental_8point(const std::array<PointMatch, 8>& m, Eigen::Matrix3d& F) {
  const Normalization n1 = hartley_normalization(&m[0].p1, 8, sizeof(PointMatch) / sizeof(Eigen::Vector2d));
  const Normalization n2 = hartley_normalization(&m[0].p2, 8, sizeof(PointMatch) / sizeof(Eigen::Vector2d));
  Eigen::Matrix<double, 8, 2> x1, x2;
  for (int i = 0; i < 8; ++i) {
    x1.row(i) = n1.apply(m[i].p1).transpose();
    x2.row(i) = n2.apply(m[i].p2).transpose();
  }
  Eigen::Matrix3d Fn;
  if (!solve_fundamental_8_normalized(x1, x2, Fn)) return false;
  F = n2.T.transpose() * Fn * n1.T;
  const double norm = F.norm();
  if (!(norm > 0.0)) return false;
  F /= norm;
  return true;
}

double epipolar_distance_px(const Eigen::Matrix3d& F, const Eigen::Vector2d& p1, const Eigen::Vector2d& p2) {
  const Eigen::Vector3d l = F * p1.homogeneous();
  const double den = std::hypot(l(0), l(1));
  if (!(den > 0.0)) return std::numeric_limits<double>::infinity();
  return std::abs(l(0) * p2.x() + l(1) * p2.y() + l(2)) / den;
}

double sampson_distance_sq(const Eigen::Matrix3d& F, const Eigen::Vector2d& p1, const Eigen::Vector2d& p2) {
  const Eigen::Vector3d x1 = p1.homogeneous(), x2 = p2.homogeneous();
  const Eigen::Vector3d Fx1 = F * x1;
  const Eigen::Vector3d Ftx2 = F.transpose() * x2;
  const double e = x2.dot(Fx1);
  const double den = Fx1(0) * Fx1(0) + Fx1(1) * Fx1(1) + Ftx2(0) * Ftx2(0) + Ftx2(1) * Ftx2(1);
  if (!(den > 0.0)) return std::numeric_limits<double>::infinity();
  return e * e / den;
}

bool refine_fundamental_irls(const PointMatch* m, std::size_t n, double threshold_px, int iterations,
                             Eigen::Matrix3d& F) {
  if (n < 8) return false;
  const std::size_t stride = sizeof(PointMatch) / sizeof(Eigen::Vector2d);
  const Normalization n1 = hartley_normalization(&m[0].p1, n, stride);
  const Normalization n2 = hartley_normalization(&m[0].p2, n, stride);
  const double thr_sq = threshold_px * threshold_px;
  Eigen::Matrix3d Fcur = F;
  for (int it = 0; it < iterations; ++it) {
    // F in normalised coordinates, used for the Sampson weights.
    const Eigen::Matrix3d Fn_prev = n2.T.transpose().inverse() * Fcur * n1.T.inverse();
    Eigen::Matrix<double, 9, 9> M = Eigen::Matrix<double, 9, 9>::Zero();
    int used = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (sampson_distance_sq(Fcur, m[i].p1, m[i].p2) > thr_sq) continue;
      const Eigen::Vector2d a = n1.apply(m[i].p1), b = n2.apply(m[i].p2);
      const Eigen::Vector3d x1(a.x(), a.y(), 1.0), x2(b.x(), b.y(), 1.0);
      const Eigen::Vector3d Fx1 = Fn_prev * x1, Ftx2 = Fn_prev.transpose() * x2;
      const double den = Fx1(0) * Fx1(0) + Fx1(1) * Fx1(1) + Ftx2(0) * Ftx2(0) + Ftx2(1) * Ftx2(1);
      if (!(den > 1e-300)) continue;
      Eigen::Matrix<double, 9, 1> row;
      fill_row(row.transpose(), a.x(), a.y(), b.x(), b.y());
      M.noalias() += (1.0 / den) * row * row.transpose();
      ++used;
    }
    if (used < 8) return false;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> es(M);
    if (es.info() != Eigen::Success) return false;
    const Eigen::Matrix<double, 9, 1> f = es.eigenvectors().col(0);
    Eigen::Matrix3d Fn;
    Fn << f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7), f(8);
    Eigen::Matrix3d Fnew = n2.T.transpose() * enforce_rank2(Fn) * n1.T;
    const double norm = Fnew.norm();
    if (!(norm > 0.0) || !Fnew.allFinite()) return false;
    Fcur = Fnew / norm;
  }
  F = Fcur;
  return true;
}

}  // namespace pvb::slam
