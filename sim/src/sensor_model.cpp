#include "pvb/sim/sensor_model.hpp"

#include <algorithm>
#include <array>
#include <vector>
#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/core/utility.hpp>

#include "pvb/sensor/depth_encoding.hpp"
#include "normal_table.hpp"
#include "splitmix.hpp"

namespace pvb::sim {

const std::array<float, 4096>& normal_table() {
  static const std::array<float, 4096> table = [] {
    std::array<float, 4096> t{};
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double p = (static_cast<double>(i) + 0.5) / t.size();
      // inverse error function by Newton iterations on erf
      double x = 0;
      for (int it = 0; it < 60; ++it) {
        const double cdf = 0.5 * std::erfc(-x / std::sqrt(2.0));
        const double pdf = std::exp(-0.5 * x * x) / std::sqrt(2.0 * M_PI);
        x -= (cdf - p) / std::max(pdf, 1e-300);
      }
      t[i] = static_cast<float>(x);
    }
    return t;
  }();
  return table;
}

namespace {

/// Whether the projected pattern stands out against the sun and sky at a
/// surface point at depth z, with normal n (unnormalised, either side)
/// seen along ray (x, y, 1); dot = n . ray.
bool pattern_survives(const SunlightFrame& sun, const Eigen::Vector3f& n, const Eigen::Vector3f& ray, float dot,
                      float z, bool lit, float mirror_w_m2 = 0) {
  const float n_norm = n.norm(), ray2 = ray.squaredNorm();
  const float cos_projector = std::abs(dot) / (n_norm * std::sqrt(ray2));
  const float pattern = sun.pattern_w_sr * cos_projector / (z * z * ray2);
  const float cos_sun = (dot > 0 ? -n : n).dot(sun.to_sun_c) / n_norm;  // the normal turned to the camera
  const float ambient = sun.beam_w_m2 * (lit ? std::max(cos_sun, 0.0f) : 0.0f) + sun.sky_w_m2 + mirror_w_m2;
  return pattern >= sun.min_contrast * ambient;
}

/// A Kinect's depth at a glass pixel: the mirror's image (its path length
/// along the ray), the cells' own (z) or none (0).
float glass_depth(const GlassView& glass, const SunlightFrame* sun, const Eigen::Vector3f& n,
                  const Eigen::Vector3f& ray, float dot, float z, int r, int c, bool lit) {
  const float mirror = glass.mirror_m.ptr<float>(r)[c];
  if (mirror > 0) return z + mirror / ray.norm();
  const float cos_i = std::abs(dot) / (n.norm() * ray.norm());
  if (z > glass_pattern_range_m(cos_i)) return 0;
  if (!sun) return z;
  const float R = fresnel_glass(cos_i);
  const Eigen::Vector3f v = ray.normalized(), nf = n.normalized();
  const Eigen::Vector3f refl = v - 2 * v.dot(nf) * nf;
  static const float cos_glint = static_cast<float>(std::cos(3 * kGlintSigmaDeg * M_PI / 180.0));
  if (sun->beam_w_m2 > 0 && refl.dot(sun->to_sun_c) > cos_glint) return 0;  // within 3 sigma of the sun's glint
  // The mirrored sky over the cells' diffuse share of the pattern.
  const float cells = static_cast<float>(kCellNirReflectance) * (1 - R) * (1 - R);
  return pattern_survives(*sun, n, ray, dot, z, lit, R / cells * sun->sky_w_m2) ? z : 0.0f;
}

}  // namespace

SunlightFrame sunlight_frame(const scenes::Sunlight& params, double sun_elevation_deg,
                             const Eigen::Vector3f& to_sun_c, cv::Mat lit) {
  const double beam = params.filter_width_nm * params.sun_w_m2_nm * scenes::beam_relative_to_air_mass_15(sun_elevation_deg);
  SunlightFrame f;
  f.to_sun_c = to_sun_c.normalized();
  f.beam_w_m2 = static_cast<float>(beam);
  f.sky_w_m2 = static_cast<float>(params.sky_share * beam);
  f.pattern_w_sr = static_cast<float>(params.projector_power_w / params.projector_solid_angle_sr);
  f.min_contrast = static_cast<float>(params.min_contrast);
  f.lit = std::move(lit);
  return f;
}

cv::Mat apply_depth_model(const cv::Mat& gt, const geom::PinholeIntrinsics& K, const scenes::Camera& cam,
                          std::uint64_t seed, std::uint64_t frame, const SunlightFrame* sun,
                          const GlassView* glass) {
  CV_Assert(gt.type() == CV_32FC1);
  if (sun && !(sun->beam_w_m2 > 0 || sun->sky_w_m2 > 0)) sun = nullptr;  // no sun, no change
  CV_Assert(!sun || (sun->lit.type() == CV_8UC1 && sun->lit.size() == gt.size()));
  CV_Assert(!glass || glass->face.size() == gt.size());
  const float zmin = static_cast<float>(cam.depth_range_m.x()), zmax = static_cast<float>(cam.depth_range_m.y());
  cv::Mat out(gt.size(), CV_32FC1, cv::Scalar(0));
  const int W = gt.cols, H = gt.rows;
  if (cam.depth_noise.model == scenes::DepthNoiseModel::kNone) {
    for (int r = 0; r < H; ++r) {
      const float* g = gt.ptr<float>(r);
      float* o = out.ptr<float>(r);
      for (int c = 0; c < W; ++c) o[c] = (g[c] >= zmin && g[c] <= zmax) ? g[c] : 0.0f;
    }
    return sensor::snap_depth_to_u16_grid(out, sensor::kTumDepthFactor);
  }
  const scenes::DepthNoise& p = cam.depth_noise;
  const auto& nt = normal_table();
  const double bf = p.baseline_m * K.fx;
  const float cos2_max = static_cast<float>(std::pow(std::cos(p.max_incidence_deg * M_PI / 180.0), 2));
  std::vector<float> xn(static_cast<std::size_t>(W)), yn(static_cast<std::size_t>(H));
  for (int c = 0; c < W; ++c) xn[static_cast<std::size_t>(c)] = static_cast<float>((c - K.cx) / K.fx);
  for (int r = 0; r < H; ++r) yn[static_cast<std::size_t>(r)] = static_cast<float>((r - K.cy) / K.fy);
  // Lateral jitter in whole pixels for each of the 4096 quantiles: the same
  // values as rounding per pixel, 4096 roundings instead of two per pixel.
  std::array<int, 4096> jitter_px{};
  for (std::size_t i = 0; i < jitter_px.size(); ++i)
    jitter_px[i] = static_cast<int>(std::lround(nt[i] * p.lateral_sigma_px));
  // Rows run in parallel; each row has its own generator seeded by (seed,
  // frame, row), so the result does not depend on the number of threads.
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
  for (int r = rows.start; r < rows.end; ++r) {
    SplitMix rng(seed, (frame << 21) + 2 * static_cast<std::uint64_t>(r) + 1);
    float* o = out.ptr<float>(r);
    for (int c = 0; c < W; ++c) {
      const std::uint64_t bits = rng.next();
      // lateral jitter: sample a neighbouring pixel (nearest, so no mixing at edges)
      const int dc = jitter_px[bits & 4095];
      const int dr = jitter_px[(bits >> 12) & 4095];
      // rr and cc stay one pixel inside the image, so their neighbours are in it
      const int rr = std::clamp(r + dr, 1, H - 2), cc = std::clamp(c + dc, 1, W - 2);
      const float* g = gt.ptr<float>(rr);
      const float z = g[cc];
      if (z <= 0.0f) continue;
      // incidence angle from the local surface normal
      const float zl = g[cc - 1], zr = g[cc + 1], zu = gt.ptr<float>(rr - 1)[cc], zd = gt.ptr<float>(rr + 1)[cc];
      if (zl <= 0 || zr <= 0 || zu <= 0 || zd <= 0) continue;  // silhouette edge: no return
      // P(u, v) = z (xn(u), yn(v), 1); n = dP/du x dP/dv by central
      // differences; compare squared cosines to avoid square roots.
      const float xl = xn[cc - 1], xc = xn[cc], xr = xn[cc + 1];
      const float yu = yn[rr - 1], yc = yn[rr], yd = yn[rr + 1];
      const Eigen::Vector3f du(xr * zr - xl * zl, yc * (zr - zl), zr - zl);
      const Eigen::Vector3f dv(xc * (zd - zu), yd * zd - yu * zu, zd - zu);
      const Eigen::Vector3f n = du.cross(dv);
      const Eigen::Vector3f ray(xc, yc, 1.0f);
      const float dot = n.dot(ray);
      if (dot * dot < cos2_max * n.squaredNorm() * ray.squaredNorm()) continue;
      const bool lit = sun && sun->lit.ptr<std::uint8_t>(rr)[cc] != 0;
      float zs = z;
      if (glass && glass->face.ptr<std::uint16_t>(rr)[cc] != 0) {
        zs = glass_depth(*glass, sun, n, ray, dot, z, rr, cc, lit);
        if (zs <= 0) continue;
      } else if (sun && !pattern_survives(*sun, n, ray, dot, z, lit)) {
        continue;
      }
      // axial noise, then disparity quantisation
      double zn = zs + nt[(bits >> 24) & 4095] * kinect_axial_sigma_m(zs) * p.axial_scale;
      if (p.disparity_step_px > 0 && zn > 0) {
        const double d = bf / zn;
        const double dq = std::round(d / p.disparity_step_px) * p.disparity_step_px;
        zn = dq > 0 ? bf / dq : 0.0;
      }
      if (zn >= zmin && zn <= zmax) o[c] = static_cast<float>(zn);
    }
  }
  });
  return sensor::snap_depth_to_u16_grid(out, sensor::kTumDepthFactor);
}

double auto_exposure_gain(const cv::Mat& rgb) {
  CV_Assert(rgb.type() == CV_8UC3);
  const cv::Rect centre(rgb.cols / 5, rgb.rows / 5, rgb.cols - 2 * (rgb.cols / 5), rgb.rows - 2 * (rgb.rows / 5));
  const cv::Scalar m = cv::mean(rgb(centre));  // R, G, B
  const double grey = 0.299 * m[0] + 0.587 * m[1] + 0.114 * m[2];
  return std::clamp(kAutoExposureTargetGrey / std::max(grey, 1.0), 0.25, 8.0);
}

void apply_rgb_model(cv::Mat* rgb, const scenes::RgbNoise& given, const std::optional<cv::Point2d>& sun_px,
                     std::uint64_t seed, std::uint64_t frame) {
  CV_Assert(rgb->type() == CV_8UC3);
  scenes::RgbNoise params = given;
  if (params.auto_exposure) {  // the gain amplifies the sensor's noise with the signal
    const double gain = auto_exposure_gain(*rgb);
    params.exposure *= gain;
    params.sigma *= gain;
  }
  const bool glare = params.glare > 0 && sun_px.has_value();
  if (params.sigma <= 0 && params.exposure == 1.0 && !glare) return;
  const auto& nt = normal_table();
  // The noise for each of the 4096 quantiles, the same products as per pixel.
  std::array<double, 4096> noise{};
  for (std::size_t i = 0; i < noise.size(); ++i) noise[i] = params.sigma > 0 ? nt[i] * params.sigma : 0.0;
  const double sigma_px = 0.35 * rgb->cols;
  // Without exposure and glare, v * 1.0 + 0.0 + n is exactly v + n.
  const bool plain = params.exposure == 1.0 && !glare;
  cv::parallel_for_(cv::Range(0, rgb->rows), [&](const cv::Range& rows) {
  for (int r = rows.start; r < rows.end; ++r) {
    SplitMix rng(seed, (frame << 21) + 2 * static_cast<std::uint64_t>(r));
    auto* px = rgb->ptr<cv::Vec3b>(r);
    if (plain) {
      for (int c = 0; c < rgb->cols; ++c) {
        const std::uint64_t bits = rng.next();
        for (int k = 0; k < 3; ++k)
          px[c][k] = cv::saturate_cast<uchar>(px[c][k] + noise[(bits >> (12 * k)) & 4095]);
      }
      continue;
    }
    for (int c = 0; c < rgb->cols; ++c) {
      double add = 0;
      if (glare) {
        const double dx = c - sun_px->x, dy = r - sun_px->y;
        add = 255.0 * params.glare * std::exp(-(dx * dx + dy * dy) / (2 * sigma_px * sigma_px));
      }
      const std::uint64_t bits = rng.next();
      for (int k = 0; k < 3; ++k) {
        const double n = noise[(bits >> (12 * k)) & 4095];
        px[c][k] = cv::saturate_cast<uchar>(px[c][k] * params.exposure + add + n);
      }
    }
  }
  });
}

}  // namespace pvb::sim
