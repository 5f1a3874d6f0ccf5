// Patch alignment of map-point observations against the reference
// keyframe (slam/core/patch_refine): a textured wall, seen fronto-parallel
// from 2 m and again after a 12 cm step forward.
#include "pvb/slam/core/patch_refine.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "../features/texture.hpp"
#include "pvb/slam/features/orb_extractor.hpp"

namespace pvb::slam {
namespace patch_refine_test {

constexpr int kW = 640, kH = 480, kM = 4;
constexpr double kWallM = 2.0, kStepM = 0.12;

std::shared_ptr<const CameraModel> camera() {
  StereoIntrinsics K;
  K.fx = K.fy = 525.0;
  K.cx = 319.5;
  K.cy = 239.5;
  K.bf = 40.0;
  return std::make_shared<const CameraModel>(CameraModel::make(K, kW, kH, {}, 3.0, 1.2, 8));
}

/// The wall seen from `distance_m`: the 2 m view zoomed about the
/// principal point by 2 / distance_m (4x master, box-filtered).
cv::Mat wall_view(const cv::Mat& master, double distance_m, const CameraModel& cam) {
  const double s = kWallM / distance_m;
  // image px: x_b = c + s (x_a - c); master px X = 4 x + 1.5.
  const double ox = kM * (cam.K.cx * (1 - s)) + 1.5 * (1 - s), oy = kM * (cam.K.cy * (1 - s)) + 1.5 * (1 - s);
  const cv::Mat M = (cv::Mat_<double>(2, 3) << s, 0, ox, 0, s, oy);
  cv::Mat warped, out;
  cv::warpAffine(master, warped, M, master.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  cv::resize(warped, out, cv::Size(kW, kH), 0, 0, cv::INTER_AREA);
  return out;
}

Frame make_frame(std::uint64_t id, const cv::Mat& img, double depth_m, const std::shared_ptr<const CameraModel>& cam,
                 OrbExtractor& ex) {
  OrbFeatures features = ex.extract(img);
  Frame f(id, static_cast<std::int64_t>(id), std::move(features), cv::Mat(kH, kW, CV_32F, cv::Scalar(depth_m)), cam);
  f.pyramid = std::make_shared<const ImagePyramid>(copy_pyramid(ex.pyramid()));
  f.has_pose = true;
  return f;
}

TEST(PatchRefine, MovesObservationsToTheReferencePatch) {
  const auto cam = camera();
  const cv::Mat master = random_rectangles(kW * kM, kH * kM, 9);
  OrbExtractor ex;
  Frame fa = make_frame(0, wall_view(master, kWallM, *cam), kWallM, cam, ex);
  Frame fb = make_frame(1, wall_view(master, kWallM - kStepM, *cam), kWallM - kStepM, cam, ex);
  fb.T_c_w.translation() = Eigen::Vector3d(0, 0, -kStepM);  // p_c = p_w - step

  Map map;
  const auto kf = map.create_keyframe(fa);
  // Every keypoint of the keyframe becomes a point; each is matched to
  // the nearest keypoint of frame b (same level, within 1.5 level px of
  // the true projection) as the tracker would.
  double sum2_before = 0, sum2_after = 0;
  int matched = 0, aligned = 0;
  std::vector<std::uint8_t> used(fb.size(), 0);
  for (std::size_t j = 0; j < fa.size(); ++j) {
    const auto mp = map.create_point(fa.unproject_world(j), kf);
    mp->add_observation(kf, j);
    kf->set_map_point(j, mp);
    const Eigen::Vector2d truth = cam->project(fb.T_c_w * mp->p_w());
    const int level = fa.keys_un[j].octave;
    const double scale = cam->scale[static_cast<std::size_t>(level)];
    long best = -1;
    double best_d = 1.5 * scale;
    for (std::size_t i : fb.features_in_area(truth.x(), truth.y(), 1.5 * scale, level, level)) {
      const double d = std::hypot(fb.keys_un[i].pt.x - truth.x(), fb.keys_un[i].pt.y - truth.y());
      if (!used[i] && d < best_d) best_d = d, best = static_cast<long>(i);
    }
    if (best < 0) continue;
    const auto i = static_cast<std::size_t>(best);
    used[i] = 1;
    fb.map_points[i] = mp;
    ++matched;
    const Eigen::Vector2d before(fb.keys_un[i].pt.x, fb.keys_un[i].pt.y);
    if (!align_to_reference(fb, i, *mp, PatchAlignParams{})) continue;
    ++aligned;
    const Eigen::Vector2d after(fb.keys_un[i].pt.x, fb.keys_un[i].pt.y);
    sum2_before += (before - truth).squaredNorm() / (scale * scale);
    sum2_after += (after - truth).squaredNorm() / (scale * scale);
    EXPECT_EQ(fb.aligned_for[i], mp->id());
    EXPECT_FLOAT_EQ(fb.keys[i].x, fb.keys_un[i].pt.x);  // no distortion
    EXPECT_NEAR(fb.u_right[i], fb.keys_un[i].pt.x - cam->K.bf / (kWallM - kStepM), 1e-3);
  }
  ASSERT_GT(matched, 300);
  const double rms_before = std::sqrt(sum2_before / std::max(aligned, 1));
  const double rms_after = std::sqrt(sum2_after / std::max(aligned, 1));
  std::printf("%d of %d matches aligned; error %.3f -> %.3f level px RMS\n", aligned, matched, rms_before,
              rms_after);
  EXPECT_GT(aligned, 0.8 * matched);
  EXPECT_LT(rms_after, 0.5 * rms_before);

  // The keyframe's own observations are the anchors: nothing to align.
  auto& kf_frame = kf->frame_for_alignment();
  const cv::Point2f p = kf_frame.keys[0];
  EXPECT_FALSE(align_to_reference(kf_frame, 0, *kf->map_points()[0], PatchAlignParams{}));
  EXPECT_EQ(kf_frame.keys[0], p);
  // Already tried for its point: align_keyframe_observations skips it.
  const auto [tried, moved] = align_keyframe_observations(*kf, PatchAlignParams{});
  EXPECT_EQ(tried, static_cast<int>(fa.size()) - 1);
  EXPECT_EQ(moved, 0);
}

}  // namespace patch_refine_test
}  // namespace pvb::slam
