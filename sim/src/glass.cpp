#include "pvb/sim/glass.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/core/utility.hpp>

#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/truth_surface.hpp"

namespace pvb::sim {
namespace {

constexpr float kGlintSigmaRad = static_cast<float>(kGlintSigmaDeg * M_PI / 180.0);
constexpr float kGlintGain = 4.0f;        ///< the lobe saturates within ~1.7 sigma of its centre
constexpr double kMirrorRayMaxM = 20.0;
constexpr int kMirrorBlockPx = 4;
/// A sunlit soil's colour as the mirror shows the ground (linear RGB).
const Eigen::Vector3f kMirroredGroundRgb(0.36f, 0.30f, 0.23f);

/// Sutherland-Hodgman: the polygon's part with z >= z_min.
std::vector<Eigen::Vector3d> clip_near(const std::vector<Eigen::Vector3d>& poly, double z_min) {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector3d& a = poly[i];
    const Eigen::Vector3d& b = poly[(i + 1) % poly.size()];
    const bool ina = a.z() >= z_min, inb = b.z() >= z_min;
    if (ina) out.push_back(a);
    if (ina != inb) out.push_back(a + (b - a) * ((z_min - a.z()) / (b.z() - a.z())));
  }
  return out;
}

/// The image rectangle a face's near-clipped projection covers (empty when none).
cv::Rect face_rect(const std::vector<Eigen::Vector3d>& corners_c, const geom::PinholeIntrinsics& K) {
  const std::vector<Eigen::Vector3d> poly = clip_near(corners_c, 0.02);
  if (poly.size() < 3) return {};
  double u0 = 1e18, u1 = -1e18, v0 = 1e18, v1 = -1e18;
  for (const auto& p : poly) {
    const double u = K.fx * p.x() / p.z() + K.cx, v = K.fy * p.y() / p.z() + K.cy;
    u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
  }
  const int x0 = static_cast<int>(std::floor(std::max(u0, -1.0))), y0 = static_cast<int>(std::floor(std::max(v0, -1.0)));
  const int x1 = static_cast<int>(std::ceil(std::min(u1, static_cast<double>(K.width))));
  const int y1 = static_cast<int>(std::ceil(std::min(v1, static_cast<double>(K.height))));
  return cv::Rect(x0, y0, std::max(0, x1 - x0 + 1), std::max(0, y1 - y0 + 1)) & cv::Rect(0, 0, K.width, K.height);
}

}  // namespace

namespace {

/// fresnel_reflectance(cos, kGlassIndex) at 1025 evenly spaced cosines,
/// linearly interpolated: the per-pixel paths' Fresnel (within 2e-4).
struct FresnelTable {
  std::array<float, 1025> r{};
  double cos_mirror_wins = 0;  ///< mirror_depth_wins below this cosine
  FresnelTable();
  float at(double cos_i) const {
    const double x = std::clamp(std::abs(cos_i), 0.0, 1.0) * 1024.0;
    const auto i = std::min<std::size_t>(static_cast<std::size_t>(x), 1023);
    const float a = static_cast<float>(x - static_cast<double>(i));
    return (1 - a) * r[i] + a * r[i + 1];
  }
};

const FresnelTable& fresnel_table() {
  static const FresnelTable t;
  return t;
}

}  // namespace

double fresnel_reflectance(double cos_i, double index) {
  cos_i = std::clamp(std::abs(cos_i), 0.0, 1.0);
  const double sin_t = std::sqrt(1.0 - cos_i * cos_i) / index;
  if (sin_t >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
  const double rs = (cos_i - index * cos_t) / (cos_i + index * cos_t);
  const double rp = (cos_t - index * cos_i) / (cos_t + index * cos_i);
  return 0.5 * (rs * rs + rp * rp);
}

FresnelTable::FresnelTable() {
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = static_cast<float>(fresnel_reflectance(static_cast<double>(i) / 1024.0));
  // The mirror's image wins where R^2 rho_s > rho_c (1 - R)^2, R falling
  // with the cosine: bisect for the crossing.
  double lo = 0, hi = 1;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi), R = fresnel_reflectance(mid);
    (R * R * kMirroredSurfaceReflectance > kCellNirReflectance * (1 - R) * (1 - R) ? lo : hi) = mid;
  }
  cos_mirror_wins = lo;
}

float fresnel_glass(double cos_i) { return fresnel_table().at(cos_i); }

double glass_pattern_range_m(double cos_i) {
  const double R = fresnel_glass(cos_i);
  return kPatternRatedRangeM * std::sqrt(kCellNirReflectance * (1 - R) * (1 - R) / kPatternReferenceReflectance);
}

bool mirror_depth_wins(double cos_i) { return std::abs(cos_i) < fresnel_table().cos_mirror_wins; }

GlassFinder::GlassFinder(const mjModel* m, const std::vector<bool>& specular_arrays) : m_(m) {
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_type[g] != mjGEOM_BOX || classify_geom(m, g) != SurfaceClass::kPanel) continue;
    // Panel materials are "a<array>panel<variant>", slabs "a<array>slab<variant>".
    const char* name = mj_id2name(m, mjOBJ_MATERIAL, m->geom_matid[g]);
    const int array = name && name[0] == 'a' ? std::atoi(name + 1) : -1;
    if (array >= 0 && static_cast<std::size_t>(array) < specular_arrays.size() &&
        specular_arrays[static_cast<std::size_t>(array)])
      panels_.push_back(g);
  }
}

GlassView GlassFinder::find(const mjData* d, const cv::Mat& depth_m, const geom::PinholeIntrinsics& K,
                            const geom::SE3d& T_w_c, bool mirror_rays) const {
  GlassView out;
  out.face = cv::Mat::zeros(depth_m.size(), CV_16UC1);
  out.mirror_m = cv::Mat::zeros(depth_m.size(), CV_32FC1);
  out.R_w_c = T_w_c.linear().cast<float>();
  const geom::SE3d T_c_w = T_w_c.inverse();
  const Eigen::Vector3d eye_w = T_w_c.translation();
  for (const int g : panels_) {
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> R(d->geom_xmat + 9 * g);
    const Eigen::Map<const Eigen::Vector3d> x(d->geom_xpos + 3 * g);
    const Eigen::Map<const Eigen::Vector3d> size(m_->geom_size + 3 * g);
    const Eigen::Vector3d n_w = R.col(2), top_w = x + size.z() * n_w;
    if (n_w.dot(eye_w - top_w) <= 0) continue;  // the camera sees the back
    std::vector<Eigen::Vector3d> corners;
    for (const auto& [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
      corners.push_back(T_c_w * (top_w + a * size.x() * R.col(0) + b * size.y() * R.col(1)));
    const cv::Rect rect = face_rect(corners, K);
    if (rect.empty()) continue;
    const auto k = static_cast<std::uint16_t>(out.normals_c.size() + 1);
    const Eigen::Vector3d n_c = T_c_w.linear() * n_w;
    out.normals_c.push_back(n_c.cast<float>());
    const double tol_base = 0.005;
    // One mirrored ray per block of kMirrorBlockPx x kMirrorBlockPx pixels
    // of this face (its first pixel that needs one), shared by the block.
    const int bw = (rect.width + kMirrorBlockPx - 1) / kMirrorBlockPx;
    std::vector<float> block_m(static_cast<std::size_t>(bw) * ((rect.height + kMirrorBlockPx - 1) / kMirrorBlockPx),
                               -1.0f);
    for (int r = rect.y; r < rect.y + rect.height; ++r)
      for (int c = rect.x; c < rect.x + rect.width; ++c) {
        const float z = depth_m.ptr<float>(r)[c];
        if (z <= 0) continue;
        const Eigen::Vector3d p_c(z * (c - K.cx) / K.fx, z * (r - K.cy) / K.fy, z);
        const Eigen::Vector3d q = R.transpose() * (T_w_c * p_c - x);  // in the panel's frame
        if (std::abs(q.z() - size.z()) > tol_base + 0.002 * z || std::abs(q.x()) > size.x() || std::abs(q.y()) > size.y())
          continue;
        out.face.ptr<std::uint16_t>(r)[c] = k;
        if (!mirror_rays || !mirror_depth_wins(std::abs(n_c.dot(p_c)) / p_c.norm())) continue;
        float& m = block_m[static_cast<std::size_t>(((r - rect.y) / kMirrorBlockPx) * bw + (c - rect.x) / kMirrorBlockPx)];
        if (m < 0) {
          const Eigen::Vector3d v_w = T_w_c.linear() * p_c.normalized();
          const Eigen::Vector3d refl = v_w - 2 * v_w.dot(n_w) * n_w;
          const Eigen::Vector3d from = T_w_c * p_c + 0.01 * refl;
          int geom = -1;
          const mjtNum dist = mj_ray(m_, d, from.data(), refl.data(), nullptr, 1, -1, &geom);
          m = geom >= 0 && dist > 0 && dist < kMirrorRayMaxM ? static_cast<float>(dist + 0.01) : 0.0f;
        }
        out.mirror_m.ptr<float>(r)[c] = m;
      }
  }
  return out;
}

Eigen::Vector3f mirrored_colour(const Eigen::Vector3f& dir_w) {
  const float up = dir_w.normalized().z();
  if (up <= 0) return kMirroredGroundRgb;
  return kSkyHorizonRgb + (kSkyZenithRgb - kSkyHorizonRgb) * up;
}

void apply_glass(cv::Mat* image, const GlassView& glass, const geom::PinholeIntrinsics& K,
                 const Eigen::Vector3f& to_sun_c, bool sun_up) {
  CV_Assert(image->type() == CV_8UC3 || image->type() == CV_32FC1);
  CV_Assert(glass.face.size() == image->size());
  if (glass.normals_c.empty()) return;
  const bool grey = image->type() == CV_32FC1;
  const Eigen::Vector3f sun_c = to_sun_c.normalized();
  const float cos_glint_reach = std::cos(6 * kGlintSigmaRad);
  cv::parallel_for_(cv::Range(0, image->rows), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r) {
      const std::uint16_t* f = glass.face.ptr<std::uint16_t>(r);
      for (int c = 0; c < image->cols; ++c) {
        if (f[c] == 0) continue;
        const Eigen::Vector3f& n = glass.normals_c[f[c] - 1u];
        const Eigen::Vector3f v = Eigen::Vector3f(static_cast<float>((c - K.cx) / K.fx),
                                                  static_cast<float>((r - K.cy) / K.fy), 1.0f).normalized();
        const float cos_i = std::abs(v.dot(n));
        const float R = fresnel_glass(cos_i);
        const Eigen::Vector3f refl = v - 2 * v.dot(n) * n;
        Eigen::Vector3f add = 255.0f * R * mirrored_colour(glass.R_w_c * refl);
        const float cos_sun = refl.dot(sun_c);
        if (sun_up && cos_sun > cos_glint_reach) {  // within 6 sigma of the sun's mirror direction
          const float angle = std::acos(std::min(cos_sun, 1.0f));
          add += Eigen::Vector3f::Constant(255.0f * kGlintGain * R / 0.04f *
                                           std::exp(-angle * angle / (2 * kGlintSigmaRad * kGlintSigmaRad)));
        }
        if (grey) {
          float& p = image->ptr<float>(r)[c];
          p = (1 - R) * p + 0.299f * add.x() + 0.587f * add.y() + 0.114f * add.z();
        } else {
          cv::Vec3b& p = image->ptr<cv::Vec3b>(r)[c];
          for (int k = 0; k < 3; ++k) p[k] = cv::saturate_cast<std::uint8_t>((1 - R) * p[k] + add[k]);
        }
      }
    }
  });
}

}  // namespace pvb::sim
