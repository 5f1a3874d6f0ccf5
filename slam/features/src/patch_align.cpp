#include "pvb/slam/features/patch_align.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace pvb::slam {
namespace {

// The patch buffers are fixed-size arrays on the stack (per match, no
// allocation): patches up to kMaxHalfSize, the template one ring wider.
constexpr int kMaxHalfSize = 16;
constexpr int kMaxPatch = (2 * kMaxHalfSize + 1) * (2 * kMaxHalfSize + 1);
constexpr int kMaxTemplate = (2 * kMaxHalfSize + 3) * (2 * kMaxHalfSize + 3);

/// Bilinear sample of a CV_8U image; false outside [0, cols-1) x [0, rows-1).
bool bilinear(const cv::Mat& img, double x, double y, double* value) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= img.cols || y0 + 1 >= img.rows) return false;
  const double fx = x - x0, fy = y - y0;
  const uchar* r0 = img.ptr<uchar>(y0) + x0;
  const uchar* r1 = img.ptr<uchar>(y0 + 1) + x0;
  *value = (1 - fy) * ((1 - fx) * r0[0] + fx * r0[1]) + fy * ((1 - fx) * r1[0] + fx * r1[1]);
  return true;
}

/// Level-0 px per level px, per axis.
Eigen::Vector2d level_ratio(const ImagePyramid& pyr, int l) {
  return {static_cast<double>(pyr[0].cols) / pyr[static_cast<std::size_t>(l)].cols,
          static_cast<double>(pyr[0].rows) / pyr[static_cast<std::size_t>(l)].rows};
}
Eigen::Vector2d to_level(const Eigen::Vector2d& p0, const Eigen::Vector2d& ratio) {
  return (p0.array() + 0.5) / ratio.array() - 0.5;
}
Eigen::Vector2d from_level(const Eigen::Vector2d& pl, const Eigen::Vector2d& ratio) {
  return (pl.array() + 0.5) * ratio.array() - 0.5;
}

}  // namespace

ImagePyramid copy_pyramid(const std::vector<cv::Mat>& levels) {
  ImagePyramid out;
  out.reserve(levels.size());
  for (const cv::Mat& level : levels) out.push_back(level.clone());
  return out;
}

namespace {

/// The template on the current level's pixel grid: T(dx, dy) for offsets in
/// [-R-1, R+1]^2 current-level px, sampled from reference level `ref_img`
/// (level-0 px per its px: ra) around p_ref, along the current level's
/// axes mapped back by A_inv.  False where it leaves the image.
bool sample_template(const cv::Mat& ref_img, const Eigen::Vector2d& p_ref, const Eigen::Vector2d& ra,
                     const Eigen::Matrix2d& A_inv, const Eigen::Vector2d& rb, int R, double* tmpl) {
  const int WT = 2 * R + 3;
  // Reference-level position of offset (dx, dy): q0 + dx ex + dy ey.
  const Eigen::Vector2d q0 = to_level(p_ref, ra);
  const Eigen::Vector2d ex = (A_inv.col(0) * rb.x()).cwiseQuotient(ra);
  const Eigen::Vector2d ey = (A_inv.col(1) * rb.y()).cwiseQuotient(ra);
  for (int dy = -R - 1; dy <= R + 1; ++dy) {
    const Eigen::Vector2d row = q0 + dy * ey;
    for (int dx = -R - 1; dx <= R + 1; ++dx) {
      const double qx = row.x() + dx * ex.x(), qy = row.y() + dx * ex.y();
      if (!bilinear(ref_img, qx, qy, &tmpl[(dy + R + 1) * WT + (dx + R + 1)])) return false;
    }
  }
  return true;
}

/// The mean-subtracted template (t) and its mean-subtracted gradients (gx,
/// gy) on the inner W x W patch, and their Gauss-Newton matrix H.
Eigen::Matrix2d template_gradients(const double* tmpl, int W, double* t, double* gx, double* gy) {
  const int WT = W + 2, n = W * W;
  double t_mean = 0, gx_mean = 0, gy_mean = 0;
  for (int y = 0; y < W; ++y)
    for (int x = 0; x < W; ++x) {
      const int k = y * W + x, c = (y + 1) * WT + (x + 1);
      t[k] = tmpl[c];
      gx[k] = 0.5 * (tmpl[c + 1] - tmpl[c - 1]);
      gy[k] = 0.5 * (tmpl[c + WT] - tmpl[c - WT]);
      t_mean += t[k], gx_mean += gx[k], gy_mean += gy[k];
    }
  t_mean /= n, gx_mean /= n, gy_mean /= n;
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  for (int k = 0; k < n; ++k) {
    t[k] -= t_mean;
    gx[k] -= gx_mean;  // the gradient of the mean-subtracted patch
    gy[k] -= gy_mean;
    H(0, 0) += gx[k] * gx[k];
    H(0, 1) += gx[k] * gy[k];
    H(1, 1) += gy[k] * gy[k];
  }
  H(1, 0) = H(0, 1);
  return H;
}

/// Whether H's smaller eigenvalue (closed form for a symmetric 2x2) is at
/// least min_ratio of the larger: a patch textured in both directions.
bool well_conditioned(const Eigen::Matrix2d& H, double min_ratio) {
  const double half_trace = 0.5 * (H(0, 0) + H(1, 1));
  const double root = std::sqrt(0.25 * (H(0, 0) - H(1, 1)) * (H(0, 0) - H(1, 1)) + H(0, 1) * H(0, 1));
  const double ev_min = half_trace - root, ev_max = half_trace + root;
  return ev_max > 0 && ev_min > min_ratio * ev_max;
}

/// The steepest-descent vector b = sum g e of the W x W patch of `img` at
/// level position c (bilinear, one set of weights for all samples) against
/// the template t; false where the patch leaves the image.
bool patch_residual(const cv::Mat& img, const Eigen::Vector2d& c, int R, const double* t, const double* gx,
                    const double* gy, Eigen::Vector2d* b) {
  const int W = 2 * R + 1, n = W * W;
  double cur_px[kMaxPatch];
  // Integer offsets: every sample shares the same bilinear weights.
  const int x0 = static_cast<int>(std::floor(c.x())) - R, y0 = static_cast<int>(std::floor(c.y())) - R;
  if (x0 < 0 || y0 < 0 || x0 + W >= img.cols || y0 + W >= img.rows) return false;
  const double fx = c.x() - std::floor(c.x()), fy = c.y() - std::floor(c.y());
  const double w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
  double c_mean = 0;
  for (int y = 0; y < W; ++y) {
    const uchar* r0 = img.ptr<uchar>(y0 + y) + x0;
    const uchar* r1 = r0 + img.step[0];
    for (int x = 0; x < W; ++x) {
      const double v = w00 * r0[x] + w01 * r0[x + 1] + w10 * r1[x] + w11 * r1[x + 1];
      cur_px[y * W + x] = v;
      c_mean += v;
    }
  }
  c_mean /= n;
  *b = Eigen::Vector2d::Zero();
  for (int k = 0; k < n; ++k) {
    const double e = (cur_px[k] - c_mean) - t[k];
    b->x() += gx[k] * e;
    b->y() += gy[k] * e;
  }
  return true;
}

}  // namespace

bool align_patch(const ImagePyramid& ref, const Eigen::Vector2d& p_ref, const Eigen::Matrix2d& A_cur_ref,
                 const ImagePyramid& cur, int level_cur, const Eigen::Vector2d& p_cur_start,
                 const PatchAlignParams& params, Eigen::Vector2d* p_cur) {
  const int num_levels = static_cast<int>(std::min(ref.size(), cur.size()));
  if (level_cur < 0 || level_cur >= num_levels) return false;
  if (params.half_size < 1 || params.half_size > kMaxHalfSize) return false;
  const double det = A_cur_ref.determinant();
  if (!(std::abs(det) > 1e-6) || !A_cur_ref.allFinite()) return false;
  const int R = params.half_size;
  const int W = 2 * R + 1;  // patch width
  const Eigen::Vector2d rb = level_ratio(cur, level_cur);
  // A current-level pixel spans |A^-1| * rb reference level-0 px: the
  // reference level whose pixels are that size.
  const double zoom = std::sqrt(std::abs(det));
  const int la = std::clamp(
      static_cast<int>(std::lround(level_cur - std::log(zoom) / std::log(params.scale_factor))), 0,
      num_levels - 1);
  double tmpl[kMaxTemplate];
  if (!sample_template(ref[static_cast<std::size_t>(la)], p_ref, level_ratio(ref, la), A_cur_ref.inverse(), rb,
                       R, tmpl))
    return false;
  double t[kMaxPatch], gx[kMaxPatch], gy[kMaxPatch];
  const Eigen::Matrix2d H = template_gradients(tmpl, W, t, gx, gy);
  if (!well_conditioned(H, params.min_eigen_ratio)) return false;
  const Eigen::Matrix2d H_inv = H.inverse();

  const cv::Mat& img = cur[static_cast<std::size_t>(level_cur)];
  const Eigen::Vector2d start = to_level(p_cur_start, rb);
  Eigen::Vector2d c = start;
  for (int it = 0; it < params.max_iterations; ++it) {
    Eigen::Vector2d b;
    if (!patch_residual(img, c, R, t, gx, gy, &b)) return false;
    // Inverse compositional: the template's step Δ = H^-1 b, composed
    // inversely with the current warp.
    const Eigen::Vector2d step = H_inv * b;
    c -= step;
    if ((c - start).norm() > params.max_shift_level_px) return false;
    if (step.norm() < params.converged_level_px) break;
  }
  *p_cur = from_level(c, rb);
  return true;
}

}  // namespace pvb::slam
