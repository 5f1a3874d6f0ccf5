#pragma once
// Fundamental-matrix tools for PE-match (paper sec. 4.1, eqs. 1-5 and 8).
// Convention: F maps a point of image 1 to its epipolar line in image 2,
// l2 = F * x1 (eq. 1), and x2^T F x1 = 0 (eq. 3), x = (u, v, 1) in pixels.
// Everything here works on fixed-size Eigen types and never allocates.
#include <Eigen/Core>
#include <array>
#include <cstddef>

namespace pvb::slam {

/// A coarse match as a pair of pixel positions (image 1, image 2).
struct PointMatch {
  Eigen::Vector2d p1;  ///< pixel in image 1
  Eigen::Vector2d p2;  ///< pixel in image 2
};

/// Hartley normalisation: T maps pixels to coordinates with zero mean and
/// mean distance sqrt(2) from the origin.
struct Normalization {
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  /// Applies T to a pixel.
  Eigen::Vector2d apply(const Eigen::Vector2d& p) const {
    return {T(0, 0) * p.x() + T(0, 2), T(1, 1) * p.y() + T(1, 2)};
  }
};

/// Hartley normalisation of `n` points read as pts[i * stride].
Normalization hartley_normalization(const Eigen::Vector2d* pts, std::size_t n, std::size_t stride = 1);

/// Linear 8-point solution (eq. 5) from exactly eight correspondences that are
/// already normalised, with rank 2 enforced by zeroing the smallest singular
/// value.  Returns false when the eight points are degenerate (the 8x9
/// system has a null space of dimension > 1, e.g. all points collinear in
/// one image) or contain non-finite values.  F is in normalised coordinates.
bool solve_fundamental_8_normalized(const Eigen::Matrix<double, 8, 2>& x1, const Eigen::Matrix<double, 8, 2>& x2,
                                    Eigen::Matrix3d& F);

/// Normalised 8-point algorithm on eight pixel correspondences: Hartley
/// normalisation of these eight, solve, rank 2, de-normalise.  F is scaled
/// to unit Frobenius norm.  Returns false on degenerate input.
bool fundamental_8point(const std::array<PointMatch, 8>& m, Eigen::Matrix3d& F);

/// Eq. 8: distance in pixels of p2 to the epipolar line F * p1 in image 2.
/// Returns +inf when the line is undefined (a = b = 0).
double epipolar_distance_px(const Eigen::Matrix3d& F, const Eigen::Vector2d& p1, const Eigen::Vector2d& p2);

/// True when eq. 8's distance is <= threshold_px (squared form, no sqrt).
inline bool within_epipolar_threshold(const Eigen::Matrix3d& F, const Eigen::Vector2d& p1, const Eigen::Vector2d& p2,
                                      double threshold_px) {
  const double a = F(0, 0) * p1.x() + F(0, 1) * p1.y() + F(0, 2);
  const double b = F(1, 0) * p1.x() + F(1, 1) * p1.y() + F(1, 2);
  const double c = F(2, 0) * p1.x() + F(2, 1) * p1.y() + F(2, 2);
  const double r = a * p2.x() + b * p2.y() + c;
  return r * r <= threshold_px * threshold_px * (a * a + b * b);
}

/// Squared Sampson distance of a correspondence, pixels^2 (first-order
/// geometric error of x2^T F x1 = 0 over both images).
double sampson_distance_sq(const Eigen::Matrix3d& F, const Eigen::Vector2d& p1, const Eigen::Vector2d& p2);

/// Beyond the paper: refines F on the correspondences within `threshold_px`
/// (Sampson) by iteratively reweighted least squares on the Sampson
/// distance (Torr & Murray 1997): each pass solves the normalised linear
/// system with weights 1 / (Sampson denominator), then enforces rank 2.
/// Returns false if the system became
/// degenerate, in which case F is left unchanged.
bool refine_fundamental_irls(const PointMatch* m, std::size_t n, double threshold_px, int iterations,
                             Eigen::Matrix3d& F);

}  // namespace pvb::slam
