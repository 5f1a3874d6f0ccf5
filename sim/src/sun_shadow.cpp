#include "pvb/sim/sun_shadow.hpp"

#include <algorithm>
#include <cmath>

namespace pvb::sim {

SunShadowCaster::SunShadowCaster(const mjModel* m, const mjData* d, const Eigen::Vector3d& to_sun_w,
                                 const std::optional<ShadeRegion>& region)
    : m_(m), d_(d), s_(to_sun_w.normalized()) {
  // Two axes across the sun's direction.
  const Eigen::Vector3d other = std::abs(s_.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  e1_ = s_.cross(other).normalized();
  e2_ = s_.cross(e1_);
  for (int g = 0; g < m->ngeom; ++g) {
    const int type = m->geom_type[g];
    if (type == mjGEOM_PLANE || type == mjGEOM_HFIELD || m->geom_group[g] > 2 || !(m->geom_rbound[g] > 0))
      continue;
    const Eigen::Map<const Eigen::Vector3d> c(d->geom_xpos + 3 * g);
    const double a = e1_.dot(c), b = e2_.dot(c), r = m->geom_rbound[g];
    if (region) {
      // Every ray starts within the region's ball and runs along s_: the
      // geom's sphere behind the ball, or wider of the ball's axis than
      // both radii, is met by none.
      const Eigen::Vector3d to_c = c - region->centre_w;
      const double along = to_c.dot(s_), reach = region->radius_m + r;
      if (along < -reach || (to_c - along * s_).squaredNorm() > reach * reach) continue;
    }
    const long a0 = std::lround(std::floor((a - r) / cell_m_)),
               a1 = std::lround(std::floor((a + r) / cell_m_));
    const long b0 = std::lround(std::floor((b - r) / cell_m_)),
               b1 = std::lround(std::floor((b + r) / cell_m_));
    for (long i = a0; i <= a1; ++i)
      for (long j = b0; j <= b1; ++j)
        cells_[cell_key(i, j)].push_back(g);
  }
}

std::uint64_t SunShadowCaster::cell_key(long i, long j) {
  // Two's complement halves, without shifting a negative value.
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) | static_cast<std::uint32_t>(j);
}

bool SunShadowCaster::shadowed(const Eigen::Vector3d& p_w, double start_m) const {
  const auto it = cells_.find(
      cell_key(std::lround(std::floor(e1_.dot(p_w) / cell_m_)), std::lround(std::floor(e2_.dot(p_w) / cell_m_))));
  if (it == cells_.end()) return false;
  const Eigen::Vector3d start = p_w + start_m * s_;
  for (const int g : it->second) {
    const Eigen::Map<const Eigen::Vector3d> c(d_->geom_xpos + 3 * g);
    const Eigen::Vector3d to_c = c - start;
    const double along = to_c.dot(s_), r = m_->geom_rbound[g];
    if (along < -r || to_c.squaredNorm() - along * along > r * r) continue;  // the ray misses its sphere
    const double x = m_->geom_type[g] == mjGEOM_MESH
                         ? mj_rayMesh(m_, d_, g, start.data(), s_.data())
                         : mju_rayGeom(d_->geom_xpos + 3 * g, d_->geom_xmat + 9 * g, m_->geom_size + 3 * g,
                                       start.data(), s_.data(), m_->geom_type[g]);
    if (x >= 0) return true;
  }
  return false;
}

namespace {

constexpr std::uint8_t kUnknown = 0, kNoDepth = 1, kShadowed = 2, kLit = 3;

/// One block of the image, its corners included, refined by quarters where
/// its corners differ; each block keeps its own cache of tested pixels, so
/// blocks run in parallel without sharing one.
class BlockFill {
 public:
  BlockFill(const SunShadowCaster& caster, const cv::Mat& depth_m, const geom::PinholeIntrinsics& K,
            const geom::SE3d& T_w_c, float max_depth_m, int r0, int c0, int rows, int cols)
      : caster_(caster),
        depth_(depth_m),
        K_(K),
        T_w_c_(T_w_c),
        max_depth_m_(max_depth_m),
        r0_(r0),
        c0_(c0),
        cols_(cols),
        cache_(static_cast<std::size_t>(rows) * cols, kUnknown) {}

  /// Fills the block between rows r0..r1 and columns c0..c1 (inclusive,
  /// image coordinates) into the cache.
  void fill(int r0, int r1, int c0, int c1) {
    const std::uint8_t v = at(r0, c0);
    if (r1 - r0 <= 1 && c1 - c0 <= 1) {
      at(r0, c1), at(r1, c0), at(r1, c1);
      return;
    }
    if (v != kNoDepth && v == at(r0, c1) && v == at(r1, c0) && v == at(r1, c1)) {
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) {
          std::uint8_t& st = cache_[index(r, c)];
          if (st == kUnknown) st = has_depth(r, c) ? v : kNoDepth;
        }
      return;
    }
    const int rm = (r0 + r1) / 2, cm = (c0 + c1) / 2;
    fill(r0, rm, c0, cm);
    if (c1 > cm) fill(r0, rm, cm, c1);
    if (r1 > rm) fill(rm, r1, c0, cm);
    if (r1 > rm && c1 > cm) fill(rm, r1, cm, c1);
  }
  bool lit(int r, int c) const { return cache_[index(r, c)] == kLit; }

 private:
  std::size_t index(int r, int c) const { return static_cast<std::size_t>(r - r0_) * cols_ + (c - c0_); }
  bool has_depth(int r, int c) const {
    const float z = depth_.at<float>(r, c);
    return z > 0 && z <= max_depth_m_;
  }
  std::uint8_t at(int r, int c) {
    std::uint8_t& st = cache_[index(r, c)];
    if (st != kUnknown) return st;
    if (!has_depth(r, c)) return st = kNoDepth;
    const float z = depth_.at<float>(r, c);
    const Eigen::Vector3d p_c(z * (c - K_.cx) / K_.fx, z * (r - K_.cy) / K_.fy, z);
    return st = caster_.shadowed(T_w_c_ * p_c) ? kShadowed : kLit;
  }
  const SunShadowCaster& caster_;
  const cv::Mat& depth_;
  const geom::PinholeIntrinsics& K_;
  const geom::SE3d& T_w_c_;
  float max_depth_m_;
  int r0_, c0_, cols_;
  std::vector<std::uint8_t> cache_;
};

}  // namespace

cv::Mat sun_visibility(const SunShadowCaster& caster, const cv::Mat& depth_m,
                       const geom::PinholeIntrinsics& K, const geom::SE3d& T_w_c, int step,
                       float max_depth_m) {
  CV_Assert(depth_m.type() == CV_32FC1 && step >= 1);
  const int H = depth_m.rows, W = depth_m.cols;
  const int block_rows = (H + step - 1) / step, block_cols = (W + step - 1) / step;
  cv::Mat out(H, W, CV_8UC1, cv::Scalar(0));
  // Block (i, j) writes rows [i step, (i + 1) step) and columns likewise:
  // every pixel once, whatever the thread count.
  cv::parallel_for_(cv::Range(0, block_rows * block_cols), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b) {
      const int r0 = (b / block_cols) * step, c0 = (b % block_cols) * step;
      const int r1 = std::min(r0 + step, H - 1), c1 = std::min(c0 + step, W - 1);
      BlockFill block(caster, depth_m, K, T_w_c, max_depth_m, r0, c0, r1 - r0 + 1, c1 - c0 + 1);
      block.fill(r0, r1, c0, c1);
      for (int r = r0; r < std::min(r0 + step, H); ++r)
        for (int c = c0; c < std::min(c0 + step, W); ++c)
          out.at<std::uint8_t>(r, c) = block.lit(r, c) ? 1 : 0;
    }
  });
  return out;
}

}  // namespace pvb::sim
