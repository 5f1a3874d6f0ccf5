// The d435 model on synthetic views: passive stereo on a textured plane,
// the projector's dots in the dark and in the sun, depth registration.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pvb/sim/active_stereo.hpp"

namespace pvb::sim {
namespace {

/// A camera whose colour camera is the left imager itself, so the depth
/// lands where the left image has it.
scenes::Camera camera_at_left_imager() {
  scenes::Camera cam;
  cam.model = scenes::CameraKind::kD435;
  cam.width = cam.stereo.ir_width;
  cam.height = cam.stereo.ir_height;
  cam.fx = cam.fy = cam.stereo.ir_fx;
  cam.stereo.colour_offset_m = 0;
  cam.depth_range_m = {0.1, 10};
  return cam;
}

/// Value noise on the plane: a hashed grey per 1.5 cm cell, bilinear.
double plane_texture(double X, double Y) {
  auto cell = [](long i, long j) {
    std::uint64_t h = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint64_t>(j) * 0xC2B2AE3D27D4EB4Full;
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 29;
    return static_cast<double>(h % 1000) / 999.0 - 0.5;
  };
  const double x = X / 0.015, y = Y / 0.015;
  const long i = static_cast<long>(std::floor(x)), j = static_cast<long>(std::floor(y));
  const double a = x - i, b = y - j;
  return (1 - b) * ((1 - a) * cell(i, j) + a * cell(i + 1, j)) + b * ((1 - a) * cell(i, j + 1) + a * cell(i + 1, j + 1));
}

/// A fronto-parallel plane at depth z_m seen by the imager at x_m along
/// the baseline: grey from a random texture on the plane, or uniform.
InfraredView plane_view(const scenes::Camera& cam, double z_m, double x_m, bool textured) {
  const auto& p = cam.stereo;
  InfraredView v;
  v.depth_m = cv::Mat(p.ir_height, p.ir_width, CV_32FC1, cv::Scalar(z_m));
  v.grey = cv::Mat(p.ir_height, p.ir_width, CV_8UC1, cv::Scalar(110));
  if (!textured) return v;
  for (int r = 0; r < p.ir_height; ++r)
    for (int c = 0; c < p.ir_width; ++c) {
      const double X = (c - p.ir_cx()) / p.ir_fx * z_m + x_m, Y = (r - p.ir_cy()) / p.ir_fx * z_m;
      v.grey.ptr<std::uint8_t>(r)[c] = cv::saturate_cast<std::uint8_t>(110 + 120 * plane_texture(X, Y));
    }
  return v;
}

StereoRender plane(const scenes::Camera& cam, double z_m, bool textured) {
  StereoRender s;
  s.left = plane_view(cam, z_m, 0.0, textured);
  s.right = plane_view(cam, z_m, cam.stereo.baseline_m, textured);
  s.to_sun_c = Eigen::Vector3f(0, 0, -1);  // behind the camera: shining on the plane head on
  return s;
}

/// The share of pixels in the matcher's reach (right of the disparity
/// range) with depth, and their median relative error.
std::pair<double, double> valid_and_error(const cv::Mat& z, const scenes::Camera& cam, double z_true) {
  std::vector<double> err;
  long n = 0;
  for (int r = 10; r < z.rows - 10; ++r)
    for (int c = cam.stereo.disparities + 10; c < z.cols - 10; ++c) {
      ++n;
      const float v = z.ptr<float>(r)[c];
      if (v > 0) err.push_back(std::abs(v - z_true) / z_true);
    }
  if (err.empty()) return {0.0, 1.0};
  std::nth_element(err.begin(), err.begin() + static_cast<std::ptrdiff_t>(err.size() / 2), err.end());
  return {static_cast<double>(err.size()) / static_cast<double>(n), err[err.size() / 2]};
}

TEST(DotPattern, HasMeanOneAndBrightSpots) {
  scenes::ActiveStereo p;
  const DotPattern dots(p);
  double sum = 0;
  int n = 0;
  for (double ty = -0.5; ty <= 0.5; ty += 0.0037)
    for (double tx = -0.9; tx <= 0.9; tx += 0.0041, ++n) sum += dots.at(static_cast<float>(tx), static_cast<float>(ty));
  EXPECT_NEAR(sum / n, 1.0, 0.05);
  EXPECT_GT(dots.peak(), 10.0f);  // 5000 spots of 0.7 px over 848 x 480 px leave most of the field dark
  EXPECT_EQ(dots.at(2.0f, 0.0f), 0.0f) << "outside the field";
  p.dots = 0;
  EXPECT_EQ(DotPattern(p).at(0.0f, 0.0f), 0.0f);
}

TEST(ActiveStereo, PassiveStereoOnATexturedPlaneGivesItsDepth) {
  scenes::Camera cam = camera_at_left_imager();
  cam.stereo.projector_power_w = 0;  // the scene's texture only
  const double bf = cam.stereo.baseline_m * cam.stereo.ir_fx;
  for (const double z : {1.0, 2.0, 4.0}) {
    const ActiveStereoModel model(cam, 50.0, 3);
    const cv::Mat depth = model.depth(plane(cam, z, true), 0);
    const auto [valid, err] = valid_and_error(depth, cam, z);
    EXPECT_GT(valid, 0.95) << z << " m";
    // The matcher finds the whole disparity; its sub-pixel part locks
    // towards whole pixels (docs/sensors.md), so the error stays under
    // half a pixel of disparity: d err / (1 - err) with d = bf / z.
    EXPECT_LT(bf / z * err / (1 - err), 0.5) << z << " m";
  }
}

TEST(ActiveStereo, TheProjectorGivesDepthOnABlankPlaneInTheDarkButNotInTheSun) {
  const scenes::Camera cam = camera_at_left_imager();
  StereoRender blank = plane(cam, 1.0, false);
  // Night: only the ambient floor, the dots stand out.
  const auto [valid_dark, err_dark] = valid_and_error(ActiveStereoModel(cam, -10.0, 3).depth(blank, 0), cam, 1.0);
  EXPECT_GT(valid_dark, 0.8);
  EXPECT_LT(err_dark, 0.02);
  // Noon sun on the plane: the dots drown.
  blank.left.lit = cv::Mat(blank.left.grey.size(), CV_8UC1, cv::Scalar(1));
  blank.right.lit = blank.left.lit.clone();
  const auto [valid_sun, err_sun] = valid_and_error(ActiveStereoModel(cam, 60.0, 3).depth(blank, 0), cam, 1.0);
  EXPECT_LT(valid_sun, 0.2);
  (void)err_sun;
}

TEST(ActiveStereo, TheSameFrameGivesTheSameDepth) {
  const scenes::Camera cam = camera_at_left_imager();
  const ActiveStereoModel model(cam, 50.0, 3);
  const StereoRender s = plane(cam, 2.0, true);
  EXPECT_EQ(cv::norm(model.depth(s, 5), model.depth(s, 5), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(model.infrared_image(s.left, false, s.to_sun_c, 5),
                     model.infrared_image(s.left, false, s.to_sun_c, 6), cv::NORM_INF), 0.0)
      << "each frame draws its own noise";
}

TEST(RegisterDepth, APlaneMovesByTheParallax) {
  const geom::PinholeIntrinsics K_src{400, 400, 159.5, 119.5, 320, 240};
  const geom::PinholeIntrinsics K_dst{600, 600, 319.5, 239.5, 640, 480};
  const cv::Mat src(240, 320, CV_32FC1, cv::Scalar(2.0f));
  // The source 0.1 m to the left of the destination: a point at the
  // source's centre lies 600 * -0.1 / 2 = -30 px from the destination's.
  const cv::Mat dst = register_depth(src, K_src, Eigen::Vector3d(-0.1, 0, 0), K_dst);
  // The source covers x in [-0.8 - 0.1, 0.8 - 0.1] m at 2 m: destination
  // columns 319.5 + 300 * [-0.9, 0.7] = [49.5, 529.5].
  EXPECT_EQ(dst.at<float>(240, 60), 2.0f);
  EXPECT_EQ(dst.at<float>(240, 520), 2.0f);
  EXPECT_EQ(dst.at<float>(240, 40), 0.0f);
  EXPECT_EQ(dst.at<float>(240, 540), 0.0f);
  // rows: 239.5 + 300 * [-0.6, 0.6] = [59.5, 419.5]
  EXPECT_EQ(cv::countNonZero(dst(cv::Rect(60, 70, 460, 340)) == 0.0f), 0) << "no cracks inside";
  // The nearer of two surfaces wins.
  cv::Mat two = src.clone();
  two(cv::Rect(100, 100, 20, 20)).setTo(1.0f);
  const cv::Mat d2 = register_depth(two, K_src, Eigen::Vector3d(-0.1, 0, 0), K_dst);
  // The patch's centre (110, 110) at 1 m lies at x = -0.124 - 0.1 m,
  // y = -0.024 m: destination column 185.25, row 225.25.
  EXPECT_EQ(d2.at<float>(225, 185), 1.0f);
  EXPECT_EQ(d2.at<float>(300, 300), 2.0f);
}

}  // namespace
}  // namespace pvb::sim
