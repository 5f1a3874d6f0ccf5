// Frame and CameraModel (slam/core/frame): undistortion of keypoints that
// are moved after detection, with the Kinect distortion of TUM1.yaml.
#include "pvb/slam/core/frame.hpp"

#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdlib>
#include <opencv2/calib3d.hpp>
#include <optional>
#include <random>
#include <string>

#include "pvb/common/memory.hpp"

namespace pvb::slam {
namespace {

constexpr int kW = 640, kH = 480;

std::shared_ptr<const CameraModel> camera(bool distorted) {
  StereoIntrinsics K;  // TUM1.yaml (freiburg1 Kinect)
  K.fx = 517.306408;
  K.fy = 516.469215;
  K.cx = 318.643040;
  K.cy = 255.313989;
  K.bf = 40.0;
  const std::vector<double> dist = distorted ? std::vector<double>{0.262383, -0.953104, -0.005358, 0.002628, 1.163314}
                                             : std::vector<double>{};
  return std::make_shared<const CameraModel>(CameraModel::make(K, kW, kH, dist, 3.0, 1.2, 8));
}

Eigen::Vector2d undistort_cv(const CameraModel& cam, const Eigen::Vector2d& px) {
  std::vector<cv::Point2f> in = {cv::Point2f(float(px.x()), float(px.y()))}, out;
  cv::undistortPoints(in, out, cam.K_cv, cam.dist_cv, cv::noArray(), cam.K_cv);
  return {out[0].x, out[0].y};
}

/// A frame with one keypoint at `px` (level 0) and depth 2 m everywhere.
Frame one_keypoint_frame(const std::shared_ptr<const CameraModel>& cam, const Eigen::Vector2d& px) {
  OrbFeatures f;
  f.keypoints.emplace_back(cv::Point2f(float(px.x()), float(px.y())), 31.0f, 0.0f, 50.0f, 0);
  f.descriptors = cv::Mat::zeros(1, 32, CV_8U);
  return Frame(0, 0, std::move(f), cv::Mat(kH, kW, CV_32F, cv::Scalar(2.0f)), cam);
}

TEST(CameraModel, UndistortTableAgreesWithOpenCvAcrossTheImage) {
  const auto cam = camera(true);
  double worst = 0;
  for (double v = 0.3; v < kH - 1; v += 37.7)
    for (double u = 0.6; u < kW - 1; u += 41.3) {
      const Eigen::Vector2d px(u, v);
      worst = std::max(worst, (cam->undistort(px) - undistort_cv(*cam, px)).norm());
    }
  EXPECT_LT(worst, 2e-3);
}

TEST(CameraModel, UndistortIsTheIdentityWithoutDistortion) {
  const auto cam = camera(false);
  EXPECT_TRUE(cam->undistort_table.empty());
  const Eigen::Vector2d px(12.25, 470.5);
  EXPECT_EQ(cam->undistort(px), px);
}

TEST(Frame, MovedKeypointIsUndistortedWhereItNowIs) {
  // Near a corner the distortion is far from a shift: moving the raw
  // keypoint by (0.8, -0.6) px moves the undistorted one by a different amount.
  const auto cam = camera(true);
  const Eigen::Vector2d from(24.0, 30.0), to(24.8, 29.4);
  Frame f = one_keypoint_frame(cam, from);
  ASSERT_EQ(f.size(), 1u);
  const Eigen::Vector2d un_from(f.keys_un[0].pt.x, f.keys_un[0].pt.y);
  EXPECT_LT((un_from - undistort_cv(*cam, from)).norm(), 1e-3);
  const Eigen::Vector2d exact = undistort_cv(*cam, to);
  // The old rule (same shift as the raw keypoint) would miss by more than this.
  ASSERT_GT((un_from + (to - from) - exact).norm(), 0.02);
  f.move_keypoint(0, to);
  EXPECT_FLOAT_EQ(f.keys[0].pt.x, 24.8f);
  EXPECT_FLOAT_EQ(f.keys[0].pt.y, 29.4f);
  EXPECT_LT((Eigen::Vector2d(f.keys_un[0].pt.x, f.keys_un[0].pt.y) - exact).norm(), 2e-3);
  EXPECT_NEAR(f.u_right[0], f.keys_un[0].pt.x - cam->K.bf / 2.0, 1e-4);
}

TEST(Frame, MovedKeypointShiftsWithoutDistortion) {
  const auto cam = camera(false);
  Frame f = one_keypoint_frame(cam, Eigen::Vector2d(100.0, 200.0));
  f.move_keypoint(0, Eigen::Vector2d(100.25, 199.5));
  EXPECT_FLOAT_EQ(f.keys_un[0].pt.x, 100.25f);
  EXPECT_FLOAT_EQ(f.keys_un[0].pt.y, 199.5f);
  EXPECT_NEAR(f.u_right[0], 100.25 - cam->K.bf / 2.0, 1e-4);
}

/// n keypoints at seeded random positions and levels, random descriptors.
OrbFeatures random_features(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, float(kW - 1)), v(0.0f, float(kH - 1)), angle(0.0f, 360.0f);
  std::uniform_int_distribution<int> octave(0, 7), byte(0, 255);
  OrbFeatures f;
  for (int i = 0; i < n; ++i) f.keypoints.emplace_back(cv::Point2f(u(rng), v(rng)), 31.0f, angle(rng), 20.0f, octave(rng));
  f.descriptors.create(n, 32, CV_8U);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < 32; ++c) f.descriptors.at<uchar>(r, c) = static_cast<uchar>(byte(rng));
  return f;
}

/// Heap bytes in use (malloc's own count, main arena and mapped blocks).
std::size_t heap_in_use() {
  const struct mallinfo2 mi = mallinfo2();
  return mi.uordblks + mi.hblkhd;
}

/// malloc's count of the bytes in use follows every block only without its
/// per-thread cache (which keeps freed blocks counted as in use).
bool malloc_counts_every_block() {
#if defined(__SANITIZE_ADDRESS__)
  return false;  // ASan's allocator keeps no such count
#else
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  return tunables != nullptr && std::string(tunables).find("glibc.malloc.tcache_count=0") != std::string::npos;
#endif
}

TEST(Frame, MemoryCountsEveryHeapBlockItHolds) {
  // What the frame allocates, as malloc counts it, against what memory()
  // says, so that the per-structure figures of docs/slam.md add up.  malloc
  // may hand out up to a minimum block more than asked for where the free
  // block it splits would leave less (fragmentation, not a structure left
  // out): 0.2 % allows that and no more; from 300 keypoints on, the
  // smallest structure, the outlier flags at a byte per keypoint, is over
  // 0.2 % of the total.
  if (!malloc_counts_every_block()) GTEST_SKIP() << "needs GLIBC_TUNABLES=glibc.malloc.tcache_count=0 (ctest sets it)";
  const auto cam = camera(false);
  const cv::Mat depth(kH, kW, CV_32F, cv::Scalar(2.0f));
  for (int n : {1, 300, 1500}) {
    const std::size_t before = heap_in_use();
    std::optional<Frame> f;
    {
      OrbFeatures features = random_features(n, 7);
      f.emplace(0, 0, std::move(features), depth, cam);
    }
    const auto held = static_cast<double>(heap_in_use() - before);
    const FrameMemory m = f->memory();
    EXPECT_NEAR(held, static_cast<double>(m.total() - m.object), 0.002 * held) << n << " keypoints";
    if (n >= 300) {
      EXPECT_GT(static_cast<double>(heap_block_bytes(static_cast<std::size_t>(n))), 0.002 * held);
    }
    EXPECT_EQ(m.pyramid, 0u);
    EXPECT_GE(m.descriptors, 32u * n);
  }
}

}  // namespace
}  // namespace pvb::slam
