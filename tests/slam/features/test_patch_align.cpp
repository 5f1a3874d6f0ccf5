#include "pvb/slam/features/patch_align.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "pvb/slam/features/orb_extractor.hpp"
#include "texture.hpp"

namespace pvb::slam {
namespace {

constexpr int kW = 640, kH = 480, kM = 4;  // image size, oversampling of the master texture

/// A view of the master texture under the image-space affine map
/// x_b = S x_a + t (pixel centres), rendered at 4x and box-filtered.
cv::Mat view(const cv::Mat& master, const Eigen::Matrix2d& S, const Eigen::Vector2d& t) {
  // Image pixel x covers master pixels 4x..4x+3, centre X = 4x + 1.5:
  // X_b = S (X_a - 1.5) + 4 t + 1.5.
  const Eigen::Vector2d off = -S * Eigen::Vector2d(1.5, 1.5) + kM * t + Eigen::Vector2d(1.5, 1.5);
  const cv::Mat M = (cv::Mat_<double>(2, 3) << S(0, 0), S(0, 1), off.x(), S(1, 0), S(1, 1), off.y());
  cv::Mat warped, out;
  cv::warpAffine(master, warped, M, master.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  cv::resize(warped, out, cv::Size(kW, kH), 0, 0, cv::INTER_AREA);
  return out;
}

struct Fixture {
  Fixture() : master(random_rectangles(kW * kM, kH * kM, 5)) {
    a = view(master, Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero());
    OrbExtractor ex;
    keys = ex.extract(a).keypoints;
    pyr_a = copy_pyramid(ex.pyramid());
  }
  ImagePyramid pyramid_of(const cv::Mat& img) const {
    OrbExtractor ex;
    ex.extract(img);
    return copy_pyramid(ex.pyramid());
  }
  cv::Mat master, a;
  std::vector<cv::KeyPoint> keys;
  ImagePyramid pyr_a;
};

/// For every keypoint of the reference view: start half a level pixel or
/// more off the true position in a zoomed, rotated and shifted view, align,
/// and return the RMS error (level px) of the aligned positions and the
/// share that aligned.
struct AlignFigures {
  double rms_start = 0, rms_aligned = 0, share_aligned = 0;
};
AlignFigures align_all(const Fixture& fx, const Eigen::Matrix2d& S, const Eigen::Vector2d& t, double brightness) {
  cv::Mat b = view(fx.master, S, t);
  b.convertTo(b, CV_8U, 1.0, brightness);
  const ImagePyramid pyr_b = fx.pyramid_of(b);
  PatchAlignParams params;
  cv::RNG rng(3);
  double sum2_start = 0, sum2 = 0;
  int tried = 0, ok = 0;
  for (const cv::KeyPoint& k : fx.keys) {
    const Eigen::Vector2d pa(k.pt.x, k.pt.y);
    const Eigen::Vector2d truth = S * pa + t;
    if (truth.x() < 40 || truth.y() < 40 || truth.x() > kW - 40 || truth.y() > kH - 40) continue;
    const double scale = std::pow(1.2, k.octave);
    const double angle = rng.uniform(0.0, 2 * M_PI);
    const Eigen::Vector2d start = truth + 0.7 * scale * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    ++tried;
    sum2_start += (start - truth).squaredNorm() / (scale * scale);
    Eigen::Vector2d p;
    if (!align_patch(fx.pyr_a, pa, S, pyr_b, k.octave, start, params, &p)) continue;
    ++ok;
    sum2 += (p - truth).squaredNorm() / (scale * scale);
  }
  EXPECT_GT(tried, 500);
  AlignFigures out;
  out.rms_start = std::sqrt(sum2_start / std::max(tried, 1));
  out.rms_aligned = std::sqrt(sum2 / std::max(ok, 1));
  out.share_aligned = static_cast<double>(ok) / std::max(tried, 1);
  return out;
}

TEST(PatchAlign, RecoversTheTruePositionUnderAZoomAndRotation) {
  const Fixture fx;
  const double zoom = 1.15, angle = 0.1;
  Eigen::Matrix2d S;
  S << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  S *= zoom;
  const Eigen::Vector2d t(-30.3, -17.6);
  const AlignFigures r = align_all(fx, S, t, 0.0);
  std::printf("start %.3f level px RMS; aligned %.3f level px RMS, %.0f %% aligned\n", r.rms_start, r.rms_aligned,
              100 * r.share_aligned);
  EXPECT_LT(r.rms_aligned, 0.1);
  EXPECT_GT(r.share_aligned, 0.8);
}

TEST(PatchAlign, IgnoresABrightnessOffset) {
  const Fixture fx;
  const Eigen::Matrix2d S = 0.9 * Eigen::Matrix2d::Identity();
  const Eigen::Vector2d t(31.7, 24.2);
  const AlignFigures r = align_all(fx, S, t, 25.0);
  EXPECT_LT(r.rms_aligned, 0.1);
  EXPECT_GT(r.share_aligned, 0.8);
}

TEST(PatchAlign, RejectsEdgesFlatPatchesAndImageBorders) {
  // A vertical step edge: the patch pins x only.
  cv::Mat edge(kH, kW, CV_8U, cv::Scalar(40));
  edge(cv::Rect(kW / 2, 0, kW / 2, kH)).setTo(200);
  cv::GaussianBlur(edge, edge, cv::Size(5, 5), 1.0);
  const cv::Mat flat(kH, kW, CV_8U, cv::Scalar(100));
  const ImagePyramid pyr_edge = copy_pyramid({edge}), pyr_flat = copy_pyramid({flat});
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  const PatchAlignParams params;
  Eigen::Vector2d p;
  const Eigen::Vector2d on_edge(kW / 2 - 0.5, kH / 2);
  EXPECT_FALSE(align_patch(pyr_edge, on_edge, I, pyr_edge, 0, on_edge + Eigen::Vector2d(0.3, 0.3), params, &p));
  EXPECT_FALSE(align_patch(pyr_flat, on_edge, I, pyr_flat, 0, on_edge, params, &p));

  const Fixture fx;
  const Eigen::Vector2d corner(2.0, 2.0);
  EXPECT_FALSE(align_patch(fx.pyr_a, corner, I, fx.pyr_a, 0, corner, params, &p));
  // Well-placed corners of the same image align to themselves.
  int ok = 0;
  for (const cv::KeyPoint& k : fx.keys) {
    const Eigen::Vector2d mid(k.pt.x, k.pt.y);
    if (!align_patch(fx.pyr_a, mid, I, fx.pyr_a, k.octave, mid, params, &p)) continue;
    ++ok;
    EXPECT_LT((p - mid).norm(), 1e-6);
  }
  EXPECT_GT(ok, 500);
}

}  // namespace
}  // namespace pvb::slam
