// The Kinect v1 depth model: libfreenect's raw -> mm relation against an
// independent calibration, the quantisation step, and the IR -> colour
// registration round trip (encode as the device, decode as libfreenect).
#include "pvb/sensor/kinect_v1.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kinect = pvb::sensor::kinect;

namespace {

const kinect::Calibration kCal{};

cv::Mat plane_m(double z_m) { return cv::Mat(kinect::kHeight, kinect::kWidth, CV_32FC1, cv::Scalar(z_m)); }

}  // namespace

// Burrus' empirical fit for one Kinect v1 (ROS kinect_calibration), a source
// independent of libfreenect's zero-plane constants: z = 1 / (3.3309495161 -
// 0.0030711016 raw) m.  Devices differ by their const_shift, and one unit of
// it (4 raw steps) moves depth by 2.3 % at 2 m, so two devices' relations
// agree to a few per cent, not exactly: 6 % over 0.6-4 m (measured: 3.4-5.2 %).
// A units slip or an inverted relation is off by far more.
TEST(KinectV1, RawToDepthAgreesWithAnIndependentCalibration) {
  for (int raw = 500; raw <= 1000; raw += 50) {
    const double burrus_mm = 1000.0 / (3.3309495161 - 0.0030711016 * raw);
    if (burrus_mm < 600 || burrus_mm > 4000) continue;
    EXPECT_NEAR(kinect::raw_to_depth_mm(raw, kCal) / burrus_mm, 1.0, 0.06) << "raw " << raw;
  }
}

TEST(KinectV1, EncodingInvertsTheRelation) {
  for (double z = 500; z < 9000; z += 137)
    EXPECT_NEAR(kinect::raw_to_depth_mm(kinect::depth_mm_to_raw_exact(z, kCal), kCal), z, 1e-6 * z);
  EXPECT_EQ(kinect::depth_mm_to_raw(0.0, kCal), kinect::kNoRaw);
  EXPECT_EQ(kinect::depth_mm_to_raw(12000.0, kCal), kinect::kNoRaw);
}

TEST(KinectV1, QuantisationStepIsTheDifferenceOfNeighbouringRawValues) {
  for (double z : {800.0, 1500.0, 3000.0, 4500.0, 7000.0}) {
    const double r = kinect::depth_mm_to_raw_exact(z, kCal);
    const double step = kinect::raw_to_depth_mm(r + 0.5, kCal) - kinect::raw_to_depth_mm(r - 0.5, kCal);
    EXPECT_NEAR(kinect::quantisation_step_mm(z, kCal) / step, 1.0, 0.01) << z;
  }
  // The Kinect v1's well-known figures: about 3 mm at 1 m, 4-5 cm at 4 m.
  EXPECT_NEAR(kinect::quantisation_step_mm(1000, kCal), 2.9, 0.3);
  EXPECT_NEAR(kinect::quantisation_step_mm(4000, kCal), 46, 5);
}

TEST(KinectV1, TableTruncatesToWholeMillimetresLikeLibfreenect) {
  const auto table = kinect::raw_to_mm_table(kCal);
  EXPECT_EQ(table[kinect::kNoRaw], 0);
  for (int raw = 0; raw < kinect::kNoRaw; ++raw) {
    const double z = kinect::raw_to_depth_mm(raw, kCal);
    if (z > 0 && z < kinect::kMaxMetricMm) EXPECT_EQ(table[raw], static_cast<int>(z)) << raw;
    else EXPECT_EQ(table[raw], 0) << raw;
  }
}

// libfreenect's shift at the reference distance (1.2 m) is 0.375 px plus the
// table's offset, and tends to D = B / (2 s) = 11.04 px beyond it.
TEST(KinectV1, RegistrationShiftFollowsTheBaseline) {
  const auto shift = kinect::depth_to_rgb_shift_table(kCal);
  EXPECT_EQ(shift[1200], static_cast<int>((0.375 + 1) * kinect::kShiftScale));
  const double d_px = 2.3 / (2 * 0.1042);
  EXPECT_NEAR(shift[9999] / double(kinect::kShiftScale), d_px * (1 - 1200.0 / 9999) + 1.375, 1.0 / 16);
  EXPECT_NEAR(shift[600] / double(kinect::kShiftScale), -d_px + 1.375, 1.0 / 16);
}

// A plane at depth z comes back at every interior pixel with at most half a
// raw step plus libfreenect's truncation to whole mm.
TEST(KinectV1, PlaneRoundTripsWithinTheQuantisation) {
  const kinect::DepthRegistration reg(kCal);
  for (double z_m : {0.6, 1.0, 2.0, 3.0, 4.5}) {
    const cv::Mat raw = reg.encode_ir_raw(plane_m(z_m));
    const cv::Mat mm = reg.register_to_colour_mm(raw);
    const double bound = 0.5 * kinect::quantisation_step_mm(1000 * z_m, kCal) + 1.0;
    int checked = 0;
    for (int v = 20; v < kinect::kHeight - 20; ++v)
      for (int u = 20; u < kinect::kWidth - 20; ++u) {
        ASSERT_NE(mm.at<std::uint16_t>(v, u), 0) << u << "," << v << " at " << z_m;
        ASSERT_LE(std::abs(mm.at<std::uint16_t>(v, u) - 1000 * z_m), bound) << u << "," << v;
        ++checked;
      }
    EXPECT_GT(checked, 200000);
  }
}

// A near box in front of a far wall: the IR camera, 2.5 cm to the side,
// sees the wall hidden behind the box's edge from the colour camera's view
// hidden by it, so that strip of the colour view gets the box's depth or
// nothing (the "shadow" of registered Kinect depth); elsewhere depth is kept.
TEST(KinectV1, OcclusionLeavesAShadowBesideNearEdges) {
  const kinect::DepthRegistration reg(kCal);
  cv::Mat depth = plane_m(3.0);
  depth(cv::Rect(200, 100, 200, 200)).setTo(0.8);
  const cv::Mat mm = reg.register_to_colour_mm(reg.encode_ir_raw(depth));
  // Far from the edges both depths are right.
  EXPECT_NEAR(mm.at<std::uint16_t>(200, 300), 800, 2);
  EXPECT_NEAR(mm.at<std::uint16_t>(200, 100), 3000, 0.5 * kinect::quantisation_step_mm(3000, kCal) + 1);
  // The wall pixels next to one side of the box are lost: the shift between
  // 0.8 m and 3 m, D * 1200 * (1/0.8 - 1/3) / 1000 = 12.1 px, of them.
  const auto shift = kinect::depth_to_rgb_shift_table(kCal);
  const int width = (shift[3000] - shift[800]) / kinect::kShiftScale;
  EXPECT_NEAR(width, 12, 1);
  int wrong_left = 0, wrong_right = 0;
  for (int u = 180; u < 200; ++u) wrong_left += std::abs(mm.at<std::uint16_t>(200, u) - 3000) > 50;
  for (int u = 400; u < 420; ++u) wrong_right += std::abs(mm.at<std::uint16_t>(200, u) - 3000) > 50;
  EXPECT_GE(std::max(wrong_left, wrong_right), width - 2);
  EXPECT_LE(std::min(wrong_left, wrong_right), 1);
}
