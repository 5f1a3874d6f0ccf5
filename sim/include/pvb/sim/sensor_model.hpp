#pragma once
// RGB-D sensor model applied to rendered images.  Every random draw comes
// from a generator seeded by (scenario seed, frame index), so a frame's noise
// does not depend on what was rendered before it.
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>

#include "pvb/geometry/pinhole.hpp"
#include "pvb/scenes/scenario.hpp"

namespace pvb::sim {

/// Axial noise of a Kinect v1 (Nguyen et al. 2012): sigma_z(z) in metres.
inline double kinect_axial_sigma_m(double z_m) { return 0.0012 + 0.0019 * (z_m - 0.4) * (z_m - 0.4); }

/// Turns ground-truth depth into sensor depth (CV_32FC1, metres, 0 invalid).
/// Model kinect, after ICL-NUIM: lateral jitter of the sampling position,
/// axial Gaussian noise, disparity d = b f / z quantised to the step, invalid
/// pixels at grazing angles and outside the depth range.  Model none: ground
/// truth cut to the depth range.  Either way the result lies on the 16-bit
/// grid of TUM PNGs (sensor::kTumDepthFactor, 0.2 mm): a recorded sequence
/// replays bit for bit the depth a live run saw.
cv::Mat apply_depth_model(const cv::Mat& depth_gt_m, const geom::PinholeIntrinsics& K, const scenes::Camera& cam,
                          std::uint64_t seed, std::uint64_t frame);

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
