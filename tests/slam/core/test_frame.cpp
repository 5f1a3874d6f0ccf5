// Frame and CameraModel (slam/core/frame): undistortion of keypoints that
// are moved after detection, with the Kinect distortion of TUM1.yaml.
#include "pvb/slam/core/frame.hpp"

#include <gtest/gtest.h>
#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <opencv2/calib3d.hpp>
#include <optional>
#include <random>
#include <string>

#include "pvb/common/memory.hpp"
#include "sanitizers.hpp"

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
  EXPECT_FLOAT_EQ(f.keys[0].x, 24.8f);
  EXPECT_FLOAT_EQ(f.keys[0].y, 29.4f);
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
  for (int i = 0; i < n; ++i) {  // drawn last to first, as the pinned features were
    const int o = octave(rng);
    const float a = angle(rng), y = v(rng), x = u(rng);
    f.keypoints.emplace_back(cv::Point2f(x, y), 31.0f, a, 20.0f, o);
  }
  f.descriptors.create(n, 32, CV_8U);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < 32; ++c) f.descriptors.at<uchar>(r, c) = static_cast<uchar>(byte(rng));
  return f;
}

/// The area search as ORB-SLAM2 lays out its index (a vector of keypoint
/// indices per cell, built from the keypoints as detected), for comparison.
class VectorPerCellGrid {
 public:
  explicit VectorPerCellGrid(const Frame& f) : cells_(CameraModel::kGridCols * CameraModel::kGridRows) {
    const CameraModel& cam = *f.cam;
    for (std::size_t i = 0; i < f.size(); ++i) {
      const int cx = static_cast<int>(std::floor((f.keys_un[i].pt.x - cam.min_x) * cam.grid_inv_w));
      const int cy = static_cast<int>(std::floor((f.keys_un[i].pt.y - cam.min_y) * cam.grid_inv_h));
      if (cx < 0 || cy < 0 || cx >= CameraModel::kGridCols || cy >= CameraModel::kGridRows) continue;
      cells_[static_cast<std::size_t>(cy * CameraModel::kGridCols + cx)].push_back(i);
    }
  }
  std::vector<std::size_t> features_in_area(const Frame& f, double u, double v, double r, int min_level,
                                            int max_level) const {
    const CameraModel& cam = *f.cam;
    const int c0 = std::max(0, static_cast<int>(std::floor((u - cam.min_x - r) * cam.grid_inv_w)));
    const int c1 = std::min(CameraModel::kGridCols - 1, static_cast<int>(std::ceil((u - cam.min_x + r) * cam.grid_inv_w)));
    const int r0 = std::max(0, static_cast<int>(std::floor((v - cam.min_y - r) * cam.grid_inv_h)));
    const int r1 = std::min(CameraModel::kGridRows - 1, static_cast<int>(std::ceil((v - cam.min_y + r) * cam.grid_inv_h)));
    std::vector<std::size_t> out;
    for (int gy = r0; gy <= r1; ++gy)
      for (int gx = c0; gx <= c1; ++gx)
        for (std::size_t i : cells_[static_cast<std::size_t>(gy * CameraModel::kGridCols + gx)]) {
          const Keypoint& k = f.keys_un[i];
          if (min_level >= 0 && k.octave < min_level) continue;
          if (max_level >= 0 && k.octave > max_level) continue;
          if (std::abs(k.pt.x - u) < r && std::abs(k.pt.y - v) < r) out.push_back(i);
        }
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  std::vector<std::vector<std::size_t>> cells_;
};

TEST(Frame, AreaSearchFindsWhatAVectorPerCellFinds) {
  // 16-bit (1500) and 32-bit (70000) entries; keypoints moved after
  // detection stay in the cell they were detected in, as before.
  const auto cam = camera(false);
  const cv::Mat depth(kH, kW, CV_32F, cv::Scalar(2.0f));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-20.0, kW + 20.0), v(-20.0, kH + 20.0), shift(-1.5, 1.5), radius(0.5, 60.0);
  std::uniform_int_distribution<int> level(-1, 7);
  for (int n : {1500, 70000}) {
    Frame f(0, 0, random_features(n, 3), depth, cam);
    const VectorPerCellGrid reference(f);
    for (std::size_t i = 0; i < f.size(); i += 3) {
      const double dy = shift(rng), dx = shift(rng);
      f.move_keypoint(i, Eigen::Vector2d(f.keys[i].x + dx, f.keys[i].y + dy));
    }
    std::size_t found = 0;
    for (int q = 0; q < 2000; ++q) {
      const double qu = u(rng), qv = v(rng), r = radius(rng);
      const int lo = level(rng), hi = lo < 0 ? -1 : std::max(lo, level(rng));
      const std::vector<std::size_t> got = f.features_in_area(qu, qv, r, lo, hi);
      ASSERT_EQ(got, reference.features_in_area(f, qu, qv, r, lo, hi)) << n << " keypoints, query " << q;
      found += got.size();
    }
    EXPECT_GT(found, 2000u);  // the queries do find keypoints
  }
}

/// Heap bytes in use (malloc's own count, main arena and mapped blocks).
std::size_t heap_in_use() {
  const struct mallinfo2 mi = mallinfo2();
  return mi.uordblks + mi.hblkhd;
}

/// malloc's count of the bytes in use follows every block only without its
/// per-thread cache (which keeps freed blocks counted as in use).
bool malloc_counts_every_block() {
#if PVB_ADDRESS_SANITIZER
  return false;  // ASan's allocator keeps no such count
#else
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  return tunables != nullptr && std::string(tunables).find("glibc.malloc.tcache_count=0") != std::string::npos;
#endif
}

TEST(Frame, MemoryCountsEveryHeapBlockItHolds) {
  // What the frame allocates, as malloc counts it, against what memory()
  // says, so that the per-structure figures of docs/slam.md add up.  malloc
  // may hand out 16 bytes more than asked for where the free block it
  // splits would leave less than a minimum block (fragmentation, not a
  // structure left out), so each of the frame's heap blocks may be 16 bytes
  // over; the smallest structure, the outlier flags at a byte per keypoint,
  // is more than that allowance at these sizes.
  if (!malloc_counts_every_block()) GTEST_SKIP() << "needs GLIBC_TUNABLES=glibc.malloc.tcache_count=0 (ctest sets it)";
  constexpr std::size_t kHeapBlocks = 11;  // 9 arrays, the descriptors' data and their reference count
  const std::size_t allowance = 16 * kHeapBlocks;
  const auto cam = camera(false);
  const cv::Mat depth(kH, kW, CV_32F, cv::Scalar(2.0f));
  for (int n : {300, 1500}) {
    ASSERT_GT(heap_block_bytes(static_cast<std::size_t>(n)), allowance);
    const std::size_t before = heap_in_use();
    std::optional<Frame> f;
    {
      OrbFeatures features = random_features(n, 7);
      f.emplace(0, 0, std::move(features), depth, cam);
    }
    const std::size_t held = heap_in_use() - before;
    const FrameMemory m = f->memory();
    EXPECT_GE(held, m.total() - m.object) << n << " keypoints";
    EXPECT_LE(held, m.total() - m.object + allowance) << n << " keypoints";
    EXPECT_EQ(m.pyramid, 0u);
    EXPECT_GE(m.descriptors, 32u * n);
  }
}

}  // namespace
}  // namespace pvb::slam
