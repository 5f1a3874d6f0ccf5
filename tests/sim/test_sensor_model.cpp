#include <gtest/gtest.h>

#include <cmath>

#include "pvb/sensor/depth_encoding.hpp"
#include "pvb/sim/sensor_model.hpp"

using namespace pvb;

namespace {
scenes::Camera kinect() {
  scenes::Camera c;
  c.depth_noise.model = scenes::DepthNoiseModel::kKinect;
  return c;
}
geom::PinholeIntrinsics K() { return {525, 525, 319.5, 239.5, 640, 480}; }
}  // namespace

TEST(SensorModel, AxialSigmaFollowsNguyen) {
  EXPECT_DOUBLE_EQ(sim::kinect_axial_sigma_m(0.4), 0.0012);
  EXPECT_NEAR(sim::kinect_axial_sigma_m(2.4), 0.0012 + 0.0019 * 4.0, 1e-15);
}

TEST(SensorModel, KinectNoiseOnAPlaneHasTheModelledSpreadAndQuantisation) {
  const double z = 3.0;
  const cv::Mat gt(480, 640, CV_32FC1, cv::Scalar(z));
  const scenes::Camera cam = kinect();
  const cv::Mat out = sim::apply_depth_model(gt, K(), cam, 1, 0);
  double sum = 0, sum2 = 0;
  int n = 0;
  const double bf = cam.depth_noise.baseline_m * 525.0;
  for (int r = 10; r < 470; ++r)
    for (int c = 10; c < 630; ++c) {
      const double v = out.at<float>(r, c);
      ASSERT_GT(v, 0);
      // every value sits on the 1/8-pixel disparity grid, up to the output
      // grid: half a 0.2 mm depth step moves the disparity by bf dz / z^2
      const double disparity_steps = bf / v / 0.125;
      const double output_step_tol = bf * (0.5 / sensor::kTumDepthFactor) / (v * v) / 0.125;
      ASSERT_NEAR(disparity_steps, std::round(disparity_steps), output_step_tol + 1e-6);
      sum += v;
      sum2 += v * v;
      ++n;
    }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  // axial sigma 0.0012 + 0.0019 * 2.6^2 = 0.0140 m; quantisation at 3 m adds
  // a uniform error of step z^2 / bf = 0.0343 m width (sd 0.0099 m)
  const double expected = std::hypot(sim::kinect_axial_sigma_m(z), 0.125 * z * z / bf / std::sqrt(12.0));
  EXPECT_NEAR(sd, expected, 0.15 * expected);
  EXPECT_NEAR(mean, z, 0.003);
}

TEST(SensorModel, InvalidOutsideRangeAndAtGrazingAngles) {
  scenes::Camera cam = kinect();
  cv::Mat gt(480, 640, CV_32FC1, cv::Scalar(6.0));  // beyond 4.5 m
  EXPECT_EQ(cv::countNonZero(sim::apply_depth_model(gt, K(), cam, 1, 0)), 0);
  gt.setTo(0.3);  // closer than 0.5 m
  EXPECT_EQ(cv::countNonZero(sim::apply_depth_model(gt, K(), cam, 1, 0)), 0);
  // a floor seen at a grazing angle: depth grows quickly with row
  for (int r = 0; r < 480; ++r) gt.row(r).setTo(1.0 + r * 0.5);
  const cv::Mat out = sim::apply_depth_model(gt, K(), cam, 1, 0);
  EXPECT_EQ(cv::countNonZero(out.rowRange(2, 8)), 0);
}

TEST(SensorModel, NoiseIsSeededPerFrame) {
  const cv::Mat gt(60, 80, CV_32FC1, cv::Scalar(2.0));
  const scenes::Camera cam = kinect();
  const geom::PinholeIntrinsics k{525, 525, 39.5, 29.5, 80, 60};
  const cv::Mat a = sim::apply_depth_model(gt, k, cam, 5, 10);
  const cv::Mat b = sim::apply_depth_model(gt, k, cam, 5, 10);
  const cv::Mat c = sim::apply_depth_model(gt, k, cam, 5, 11);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0.0);
}

TEST(SensorModel, NoneModelKeepsGroundTruthInRange) {
  scenes::Camera cam;
  cam.depth_noise.model = scenes::DepthNoiseModel::kNone;
  cv::Mat gt(4, 4, CV_32FC1, cv::Scalar(2.345f));
  gt.at<float>(0, 0) = 9.0f;
  const cv::Mat out = sim::apply_depth_model(gt, K(), cam, 1, 0);
  EXPECT_NEAR(out.at<float>(1, 1), 2.345f, 1e-6);  // 11725 steps of 0.2 mm
  EXPECT_EQ(out.at<float>(0, 0), 0.0f);
}

// The sensor emits depth on the 16-bit grid of TUM PNGs, so a recorded
// sequence gives back exactly the depth a live run passed to SLAM.
TEST(SensorModel, DepthLiesOnTheTumPngGrid) {
  cv::Mat gt(120, 160, CV_32FC1);
  for (int r = 0; r < gt.rows; ++r)
    for (int c = 0; c < gt.cols; ++c) gt.at<float>(r, c) = 1.0f + 0.0137f * static_cast<float>(r) + 1e-4f * c;
  const geom::PinholeIntrinsics k{525, 525, 79.5, 59.5, 160, 120};
  for (const auto model : {scenes::DepthNoiseModel::kKinect, scenes::DepthNoiseModel::kNone}) {
    scenes::Camera cam;
    cam.depth_noise.model = model;
    const cv::Mat out = sim::apply_depth_model(gt, k, cam, 2, 0);
    ASSERT_GT(cv::countNonZero(out), 1000);
    const cv::Mat snapped = sensor::snap_depth_to_u16_grid(out, sensor::kTumDepthFactor);
    EXPECT_EQ(cv::norm(out, snapped, cv::NORM_INF), 0.0);
  }
}

TEST(SensorModel, RgbExposureAndNoise) {
  cv::Mat img(100, 100, CV_8UC3, cv::Scalar(100, 100, 100));
  scenes::RgbNoise p;
  p.sigma = 0;
  p.exposure = 1.5;
  sim::apply_rgb_model(&img, p, std::nullopt, 1, 0);
  EXPECT_EQ(img.at<cv::Vec3b>(5, 5)[0], 150);
  p.exposure = 1.0;
  p.sigma = 4.0;
  cv::Mat n(200, 200, CV_8UC3, cv::Scalar(100, 100, 100));
  sim::apply_rgb_model(&n, p, std::nullopt, 1, 0);
  cv::Scalar mean, sd;
  cv::meanStdDev(n.reshape(1), mean, sd);
  EXPECT_NEAR(sd[0], 4.0, 0.3);
  EXPECT_NEAR(mean[0], 100.0, 0.2);
}

// Automatic exposure brings a dark view to middle grey and amplifies the
// noise with it; a bright one is turned down; the meter reads the centre.
TEST(SensorModel, AutoExposureMetersTheCentreAndScalesTheNoise) {
  scenes::RgbNoise p;
  p.sigma = 2.0;
  p.auto_exposure = true;
  cv::Mat dark(200, 200, CV_8UC3, cv::Scalar(30, 30, 30));
  EXPECT_NEAR(sim::auto_exposure_gain(dark), sim::kAutoExposureTargetGrey / 30.0, 1e-9);
  sim::apply_rgb_model(&dark, p, std::nullopt, 1, 0);
  cv::Scalar mean, sd;
  cv::meanStdDev(dark.reshape(1), mean, sd);
  EXPECT_NEAR(mean[0], sim::kAutoExposureTargetGrey, 1.0);
  EXPECT_NEAR(sd[0], 2.0 * sim::kAutoExposureTargetGrey / 30.0, 0.6);  // noise x gain
  cv::Mat bright(200, 200, CV_8UC3, cv::Scalar(236, 236, 236));
  EXPECT_NEAR(sim::auto_exposure_gain(bright), 0.5, 1e-9);
  // A bright border (the sky) around a dark centre does not dim the centre.
  cv::Mat framed(200, 200, CV_8UC3, cv::Scalar(250, 250, 250));
  framed(cv::Rect(40, 40, 120, 120)).setTo(cv::Scalar(59, 59, 59));
  EXPECT_NEAR(sim::auto_exposure_gain(framed), 2.0, 1e-9);
  // The gain stays within [1/4, 8].
  EXPECT_DOUBLE_EQ(sim::auto_exposure_gain(cv::Mat(100, 100, CV_8UC3, cv::Scalar(1, 1, 1))), 8.0);
}

namespace {
// A Kinect with the sunlight model and a plane facing it at z metres, lit
// head-on by a sun `elevation_deg` up, or shaded when !lit.
sim::SunlightFrame sun_on_plane(double elevation_deg, bool lit) {
  scenes::Sunlight params;
  params.on = true;
  return sim::sunlight_frame(params, elevation_deg, Eigen::Vector3f(0, 0, -1),
                             cv::Mat(480, 640, CV_8UC1, cv::Scalar(lit ? 1 : 0)));
}
}  // namespace

TEST(SensorModel, SunlightBelowTheHorizonChangesNothing) {
  const cv::Mat gt(480, 640, CV_32FC1, cv::Scalar(3.0));
  const cv::Mat without = sim::apply_depth_model(gt, K(), kinect(), 1, 0);
  for (const double elevation : {0.0, -10.0}) {
    const sim::SunlightFrame night = sun_on_plane(elevation, true);
    const cv::Mat with = sim::apply_depth_model(gt, K(), kinect(), 1, 0, &night);
    EXPECT_EQ(cv::countNonZero(with != without), 0) << elevation;
  }
}

TEST(SensorModel, SunlightDrownsTheFarPatternAndShadeKeepsIt) {
  const cv::Rect centre(220, 140, 200, 200);  // rays within 11 degrees of the axis
  const auto valid_share = [&](double z, const sim::SunlightFrame& sun) {
    const cv::Mat gt(480, 640, CV_32FC1, cv::Scalar(z));
    return cv::countNonZero(sim::apply_depth_model(gt, K(), kinect(), 1, 0, &sun)(centre)) / 40000.0;
  };
  const sim::SunlightFrame noon = sun_on_plane(60, true), shade = sun_on_plane(60, false);
  EXPECT_EQ(valid_share(3.0, noon), 0.0);   // a sunlit far surface: no depth
  EXPECT_EQ(valid_share(1.0, noon), 1.0);   // close, the pattern still wins
  EXPECT_EQ(valid_share(3.0, shade), 1.0);  // shaded: the sky alone
  // The calibration: in shade at air mass 1.5, a surface facing the camera
  // keeps depth to the rated 4.0 m.
  const sim::SunlightFrame am15 = sun_on_plane(41.81, false);
  EXPECT_EQ(valid_share(3.6, am15), 1.0);  // 4.0 m on the axis, less 11 degrees off it
  EXPECT_EQ(valid_share(4.3, am15), 0.0);
  // A surface turned away from the sun has only the sky on it.
  sim::SunlightFrame behind = noon;
  behind.to_sun_c = Eigen::Vector3f(0, 0, 1);
  EXPECT_EQ(valid_share(3.0, behind), 1.0);
}
