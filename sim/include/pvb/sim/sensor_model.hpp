#pragma once
// RGB-D sensor model applied to rendered images.  Every random draw comes
// from a generator seeded by (scenario seed, frame index), so a frame's noise
// does not depend on what was rendered before it.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>

#include "pvb/geometry/pinhole.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/glass.hpp"

namespace pvb::sim {

/// Axial noise of a Kinect v1 (Nguyen et al. 2012): sigma_z(z) in metres.
inline double kinect_axial_sigma_m(double z_m) { return 0.0012 + 0.0019 * (z_m - 0.4) * (z_m - 0.4); }

/// What sunlight does to one frame's structured-light depth
/// (scenes::Sunlight; docs/sensors.md, "Sunlight").
struct SunlightFrame {
  Eigen::Vector3f to_sun_c = Eigen::Vector3f::UnitZ();  ///< unit, camera frame
  float beam_w_m2 = 0;    ///< the sun's beam in the camera's band, on a surface facing it
  float sky_w_m2 = 0;     ///< the sky's, on any surface
  float pattern_w_sr = 0; ///< the projector's power over its solid angle
  float min_contrast = 1;
  cv::Mat lit;            ///< CV_8UC1: 1 where the sun reaches the point seen (sun_visibility)
  /// The range beyond which even a shaded surface facing the camera has
  /// no depth (infinite without sky).
  float shade_range_m() const { return std::sqrt(pattern_w_sr / (min_contrast * sky_w_m2)); }
};

/// The band's irradiances for a sun at this elevation: the beam scaled from
/// air mass 1.5 by the clear sky's beam share (none at or below the horizon).
SunlightFrame sunlight_frame(const scenes::Sunlight& params, double sun_elevation_deg,
                             const Eigen::Vector3f& to_sun_c, cv::Mat lit);

/// Turns ground-truth depth into sensor depth (CV_32FC1, metres, 0 invalid).
/// Model kinect, after ICL-NUIM: lateral jitter of the sampling position,
/// axial Gaussian noise, disparity d = b f / z quantised to the step, invalid
/// pixels at grazing angles and outside the depth range, and with `sun`
/// the pixels whose pattern the sun and sky drown.  Model none: ground
/// truth cut to the depth range.  Either way the result lies on the 16-bit
/// grid of TUM PNGs (sensor::kTumDepthFactor, 0.2 mm): a recorded sequence
/// replays bit for bit the depth a live run saw.
/// With `glass` (specular panels), a glass pixel returns the depth of what
/// the mirror shows where GlassView::mirror_m says so, nothing beyond
/// glass_pattern_range_m, and with `sun` nothing where the mirrored sky
/// drowns the cells' pattern or the sun glints.
cv::Mat apply_depth_model(const cv::Mat& depth_gt_m, const geom::PinholeIntrinsics& K, const scenes::Camera& cam,
                          std::uint64_t seed, std::uint64_t frame, const SunlightFrame* sun = nullptr,
                          const GlassView* glass = nullptr);

/// Exposure gain, sun glare (when `sun_px` is given: the sun's projection,
/// possibly outside the image) and additive Gaussian noise on an RGB image.
/// With params.auto_exposure the gain is metered on the frame itself
/// (auto_exposure_gain) and multiplies the exposure and the noise.
void apply_rgb_model(cv::Mat* rgb, const scenes::RgbNoise& params, const std::optional<cv::Point2d>& sun_px,
                     std::uint64_t seed, std::uint64_t frame);

/// Middle grey in 8-bit sRGB (18 % reflectance), the target of automatic exposure.
inline constexpr double kAutoExposureTargetGrey = 118.0;
/// The automatic-exposure gain for a rendered RGB image: middle grey over
/// the mean grey (Rec. 601 luma) of its central region (the middle 60 % of
/// its width and height, a centre-weighted meter), clamped to [1/4, 8].
double auto_exposure_gain(const cv::Mat& rgb);

}  // namespace pvb::sim
