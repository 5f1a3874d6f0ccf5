#include "pvb/sim/active_stereo.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <vector>

#include "normal_table.hpp"
#include "pvb/sensor/depth_encoding.hpp"
#include "pvb/sim/sensor_model.hpp"
#include "splitmix.hpp"

namespace pvb::sim {
namespace {

constexpr double kRadPerDeg = M_PI / 180.0;
constexpr float kSpotSigmaIrPx = 0.7f;       ///< a spot's width in the image, one sigma
constexpr float kPatternFloorShare = 0.005f;  ///< pattern_range_m's "adds less than"
/// Noise streams of the infrared images: above the colour (2 r) and Kinect
/// depth (2 r + 1) streams of the same frame, whose rows stay below 2^20.
constexpr std::uint64_t kInfraredStreams = 1ull << 20;

/// The solid angle of a rectangular field of full angles a x b.
double rectangle_solid_angle_sr(double a_rad, double b_rad) {
  return 4.0 * std::asin(std::sin(a_rad / 2) * std::sin(b_rad / 2));
}

/// The surface normal (unnormalised, either side) at pixel (r, c) of a
/// depth image from central differences of its back-projected neighbours;
/// false at a silhouette or the border.
bool surface_normal(const cv::Mat& depth, const std::vector<float>& xn, const std::vector<float>& yn, int r, int c,
                    Eigen::Vector3f* n) {
  if (r < 1 || c < 1 || r >= depth.rows - 1 || c >= depth.cols - 1) return false;
  const float zl = depth.ptr<float>(r)[c - 1], zr = depth.ptr<float>(r)[c + 1];
  const float zu = depth.ptr<float>(r - 1)[c], zd = depth.ptr<float>(r + 1)[c];
  if (zl <= 0 || zr <= 0 || zu <= 0 || zd <= 0) return false;
  const auto uc = static_cast<std::size_t>(c), ur = static_cast<std::size_t>(r);
  const Eigen::Vector3f du(xn[uc + 1] * zr - xn[uc - 1] * zl, yn[ur] * (zr - zl), zr - zl);
  const Eigen::Vector3f dv(xn[uc] * (zd - zu), yn[ur + 1] * zd - yn[ur - 1] * zu, zd - zu);
  *n = du.cross(dv);
  return n->squaredNorm() > 0;
}

std::vector<float> normalised_coordinates(int n, double c0, double f) {
  std::vector<float> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = static_cast<float>((i - c0) / f);
  return out;
}

/// The mean of the central 60 % of an image (the meter of auto_exposure_gain).
double central_mean(const cv::Mat& img) {
  const cv::Rect centre(img.cols / 5, img.rows / 5, img.cols - 2 * (img.cols / 5), img.rows - 2 * (img.rows / 5));
  return cv::mean(img(centre))[0];
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

DotPattern::DotPattern(const scenes::ActiveStereo& p) {
  if (p.dots <= 0) return;
  half_w_ = static_cast<float>(std::tan(p.projector_hfov_deg * kRadPerDeg / 2));
  half_h_ = static_cast<float>(std::tan(p.projector_vfov_deg * kRadPerDeg / 2));
  texels_per_unit_ = static_cast<float>(2.0 * p.ir_fx);  // half an infrared pixel at the centre
  const int W = static_cast<int>(std::ceil(2 * half_w_ * texels_per_unit_)) + 1;
  const int H = static_cast<int>(std::ceil(2 * half_h_ * texels_per_unit_)) + 1;
  tex_ = cv::Mat::zeros(H, W, CV_32FC1);
  const float sigma = 2 * kSpotSigmaIrPx;  // texels
  const int radius = static_cast<int>(std::ceil(3 * sigma));
  SplitMix rng(p.pattern_seed, 0);
  for (int k = 0; k < p.dots; ++k) {
    const double x = rng.uniform() * (W - 1), y = rng.uniform() * (H - 1);
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    for (int r = std::max(0, y0 - radius); r <= std::min(H - 1, y0 + radius); ++r)
      for (int c = std::max(0, x0 - radius); c <= std::min(W - 1, x0 + radius); ++c) {
        const double d2 = (c - x) * (c - x) + (r - y) * (r - y);
        tex_.ptr<float>(r)[c] += static_cast<float>(std::exp(-d2 / (2.0 * sigma * sigma)));
      }
  }
  tex_ *= static_cast<double>(W) * H / cv::sum(tex_)[0];
  double peak = 0;
  cv::minMaxLoc(tex_, nullptr, &peak);
  peak_ = static_cast<float>(peak);
}

float DotPattern::at(float tx, float ty) const {
  if (tex_.empty()) return 0.0f;
  const float x = (tx + half_w_) * texels_per_unit_, y = (ty + half_h_) * texels_per_unit_;
  if (!(x >= 0 && y >= 0 && x < tex_.cols - 1 && y < tex_.rows - 1)) return 0.0f;
  const int c = static_cast<int>(x), r = static_cast<int>(y);
  const float a = x - c, b = y - r;
  const float* p0 = tex_.ptr<float>(r) + c;
  const float* p1 = tex_.ptr<float>(r + 1) + c;
  return (1 - b) * ((1 - a) * p0[0] + a * p0[1]) + b * ((1 - a) * p1[0] + a * p1[1]);
}

ActiveStereoModel::ActiveStereoModel(const scenes::Camera& cam, double sun_elevation_deg, std::uint64_t seed)
    : cam_(cam), seed_(seed), dots_(cam.stereo) {
  const scenes::ActiveStereo& p = cam.stereo;
  K_ir_ = {p.ir_fx, p.ir_fx, p.ir_cx(), p.ir_cy(), p.ir_width, p.ir_height};
  K_colour_ = {cam.fx, cam.fy, cam.cx(), cam.cy(), cam.width, cam.height};
  const double beam = p.band_sun_w_m2 * scenes::beam_relative_to_air_mass_15(sun_elevation_deg);
  beam_w_m2_ = static_cast<float>(beam);
  sky_w_m2_ = static_cast<float>(p.sky_share * beam);
  intensity_w_sr_ = static_cast<float>(
      p.projector_power_w / rectangle_solid_angle_sr(p.projector_hfov_deg * kRadPerDeg, p.projector_vfov_deg * kRadPerDeg));
}

float ActiveStereoModel::pattern_range_m() const {
  const float shade = std::max(sky_w_m2_, static_cast<float>(cam_.stereo.min_ambient_w_m2));
  return std::sqrt(intensity_w_sr_ * dots_.peak() / (kPatternFloorShare * shade));
}

cv::Mat ActiveStereoModel::infrared_image(const InfraredView& view, bool right_imager,
                                          const Eigen::Vector3f& to_sun_c, std::uint64_t frame) const {
  CV_Assert(view.grey.type() == CV_8UC1 && view.depth_m.type() == CV_32FC1 && view.grey.size() == view.depth_m.size());
  CV_Assert(view.lit.empty() || (view.lit.type() == CV_8UC1 && view.lit.size() == view.grey.size()));
  const scenes::ActiveStereo& p = cam_.stereo;
  const int W = view.grey.cols, H = view.grey.rows;
  const std::vector<float> xn = normalised_coordinates(W, K_ir_.cx, K_ir_.fx);
  const std::vector<float> yn = normalised_coordinates(H, K_ir_.cy, K_ir_.fy);
  // The projector in this imager's frame: projector_offset_m from the left imager.
  const float proj_x = static_cast<float>(p.projector_offset_m - (right_imager ? p.baseline_m : 0.0));
  const float floor_w_m2 = static_cast<float>(p.min_ambient_w_m2);
  cv::Mat radiance(H, W, CV_32FC1);  // 8-bit levels before exposure
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r) {
      const std::uint8_t* g = view.grey.ptr<std::uint8_t>(r);
      const float* z = view.depth_m.ptr<float>(r);
      float* o = radiance.ptr<float>(r);
      for (int c = 0; c < W; ++c) {
        o[c] = g[c];
        if (z[c] <= 0) continue;
        const Eigen::Vector3f ray(xn[static_cast<std::size_t>(c)], yn[static_cast<std::size_t>(r)], 1.0f);
        const Eigen::Vector3f q = z[c] * ray - Eigen::Vector3f(proj_x, 0, 0);  // from the projector
        const float spot = dots_.at(q.x() / q.z(), q.y() / q.z());
        if (spot <= 0) continue;
        Eigen::Vector3f n;
        float cos_projector = 1, cos_sun = 1;
        if (surface_normal(view.depth_m, xn, yn, r, c, &n)) {
          if (n.dot(ray) > 0) n = -n;  // towards the camera
          n.normalize();
          cos_projector = std::abs(n.dot(q)) / q.norm();
          cos_sun = std::max(n.dot(to_sun_c), 0.0f);
        }
        const bool lit = !view.lit.empty() && view.lit.ptr<std::uint8_t>(r)[c] != 0;
        const float ambient = std::max(beam_w_m2_ * (lit ? cos_sun : 0.0f) + sky_w_m2_, floor_w_m2);
        const float projector = intensity_w_sr_ * spot * cos_projector / q.squaredNorm();
        o[c] = g[c] * (1.0f + projector / ambient);
      }
    }
  });
  if (!view.glass.face.empty()) apply_glass(&radiance, view.glass, K_ir_, to_sun_c, beam_w_m2_ > 0);
  const double gain = std::clamp(kAutoExposureTargetGrey / std::max(central_mean(radiance), 1.0), 0.25, 8.0);
  const auto& nt = normal_table();
  cv::Mat out(H, W, CV_8UC1);
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r) {
      SplitMix rng(seed_, (frame << 21) + kInfraredStreams + 2 * static_cast<std::uint64_t>(r) + (right_imager ? 1 : 0));
      const float* v = radiance.ptr<float>(r);
      std::uint8_t* o = out.ptr<std::uint8_t>(r);
      for (int c = 0; c < W; ++c)
        o[c] = cv::saturate_cast<std::uint8_t>(v[c] * gain + p.ir_noise_sigma * nt[rng.next() & 4095]);
    }
  });
  return out;
}

cv::Mat ActiveStereoModel::disparity(const cv::Mat& left, const cv::Mat& right) const {
  const scenes::ActiveStereo& p = cam_.stereo;
  const int b2 = p.block_px * p.block_px;
  // OpenCV's recommended smoothness penalties for one channel; a left-right
  // check of one pixel and speckle removal, as a D4's post-filters do.
  auto sgbm = cv::StereoSGBM::create(0, p.disparities, p.block_px, 8 * b2, 32 * b2, 1, 31, p.uniqueness_pct, 100, 2,
                                     cv::StereoSGBM::MODE_SGBM_3WAY);
  cv::Mat fixed;  // CV_16S, 16 steps per pixel
  sgbm->compute(left, right, fixed);
  cv::Mat out;
  fixed.convertTo(out, CV_32F, 1.0 / 16);
  out.setTo(0.0f, out <= 0.0f);
  return out;
}

cv::Mat ActiveStereoModel::depth(const StereoRender& views, std::uint64_t frame, StereoTimes* times) const {
  using Clock = std::chrono::steady_clock;
  StereoTimes t;
  auto t0 = Clock::now();
  const cv::Mat left = infrared_image(views.left, false, views.to_sun_c, frame);
  const cv::Mat right = infrared_image(views.right, true, views.to_sun_c, frame);
  t.images_ms = ms_since(t0);
  t0 = Clock::now();
  const cv::Mat disp = disparity(left, right);
  t.match_ms = ms_since(t0);
  t0 = Clock::now();
  const float bf = static_cast<float>(cam_.stereo.baseline_m * K_ir_.fx);
  cv::Mat z_left(disp.size(), CV_32FC1, cv::Scalar(0));
  for (int r = 0; r < disp.rows; ++r)
    for (int c = 0; c < disp.cols; ++c) {
      const float d = disp.ptr<float>(r)[c];
      if (d > 0) z_left.ptr<float>(r)[c] = bf / d;
    }
  cv::Mat z = register_depth(z_left, K_ir_, Eigen::Vector3d(-cam_.stereo.colour_offset_m, 0, 0), K_colour_);
  const float zmin = static_cast<float>(cam_.depth_range_m.x()), zmax = static_cast<float>(cam_.depth_range_m.y());
  z.setTo(0.0f, (z < zmin) | (z > zmax));
  z = sensor::snap_depth_to_u16_grid(z, sensor::kTumDepthFactor);
  t.register_ms = ms_since(t0);
  if (times) *times = t;
  return z;
}

cv::Mat register_depth(const cv::Mat& depth_src, const geom::PinholeIntrinsics& K_src, const Eigen::Vector3d& p_dst_src,
                       const geom::PinholeIntrinsics& K_dst) {
  CV_Assert(depth_src.type() == CV_32FC1);
  constexpr float kNone = std::numeric_limits<float>::infinity();
  cv::Mat out(K_dst.height, K_dst.width, CV_32FC1, cv::Scalar(kNone));
  const double tx = p_dst_src.x(), ty = p_dst_src.y(), tz = p_dst_src.z();
  for (int r = 0; r < depth_src.rows; ++r) {
    const float* z = depth_src.ptr<float>(r);
    for (int c = 0; c < depth_src.cols; ++c) {
      if (z[c] <= 0) continue;
      const double zd = z[c] + tz;
      if (zd <= 0) continue;
      // The source pixel's square, its corners at +-0.5, in the destination.
      auto u = [&](double cc) { return K_dst.fx * (z[c] * (cc - K_src.cx) / K_src.fx + tx) / zd + K_dst.cx; };
      auto v = [&](double rr) { return K_dst.fy * (z[c] * (rr - K_src.cy) / K_src.fy + ty) / zd + K_dst.cy; };
      // Half a destination pixel more on each side closes the cracks that
      // neighbours of slightly different depth leave between their squares.
      const int c0 = std::max(0, static_cast<int>(std::ceil(u(c - 0.5) - 0.5)));
      const int c1 = std::min(K_dst.width - 1, static_cast<int>(std::ceil(u(c + 0.5) + 0.5)) - 1);
      const int r0 = std::max(0, static_cast<int>(std::ceil(v(r - 0.5) - 0.5)));
      const int r1 = std::min(K_dst.height - 1, static_cast<int>(std::ceil(v(r + 0.5) + 0.5)) - 1);
      for (int rr = r0; rr <= r1; ++rr) {
        float* o = out.ptr<float>(rr);
        for (int cc = c0; cc <= c1; ++cc) o[cc] = std::min(o[cc], static_cast<float>(zd));
      }
    }
  }
  out.setTo(0.0f, out == kNone);
  return out;
}

}  // namespace pvb::sim
