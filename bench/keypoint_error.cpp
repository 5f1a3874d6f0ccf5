// Not a benchmark: how far ORB keypoints are from where they should be, on a
// recorded sequence with ground truth (a `pvbench record` folder: noise-free
// or noisy depth, groundtruth.txt, camera.yaml).  Nothing of SLAM is in it.
//
// For frame pairs (k, k + gap): the keypoints of frame k are back-projected
// with frame k's depth and ground-truth pose (map points exact up to the
// keypoint's own error), projected into frame k + gap with its ground-truth
// pose and matched there (descriptor distance <= 50, within 4 level px,
// pyramid level +-1).  Printed:
//   - the RMS residual "matched keypoint - projection" in level pixels
//     (2-D), overall and per level: the error of both keypoints;
//   - the RMS pose error that optimize_pose leaves when started at the
//     ground truth with these points: what a perfect map would leave.
// Two whole-pixel detections, each off by a uniform +-0.5 px per axis,
// predict a residual of 0.58 level px.  docs/slam.md, "Sub-pixel keypoints".
//
// --align-patches: each match in frame k + gap is moved by aligning frame
// k's 9x9 patch around the keypoint (from the level whose scale matches),
// warped by the affine map that ground truth and depth predict (fronto-
// parallel patch), to frame k + gap: Gauss-Newton on the translation,
// mean-subtracted, from the FAST keypoint, moves over 1.5 level px
// rejected.  The check behind
// docs/experiments/2026-11-21-lawnmower-pitch-bias-per-keyframe.md.
// The mean pose error (camera frame) is printed too: a bias shows there.
//
//   keypoint_error DIR [--gap N] [--step N] [--frames N] [--whole-pixels] [--align-patches]
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/features/orb_extractor.hpp"
#include "pvb/slam/features/patch_align.hpp"
#include "pvb/slam/optim/optimizer.hpp"

namespace {

struct Options {
  std::string dir;
  int gap = 5, step = 10, frames = 600;
  bool whole_pixels = false;
  bool align_patches = false;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* name) {
      if (i + 1 >= argc) throw pvb::ConfigError("command line", name, "a positive integer after it");
      const int v = std::atoi(argv[++i]);
      if (v <= 0) throw pvb::ConfigError("command line", name, "a positive integer", argv[i]);
      return v;
    };
    if (a == "--gap")
      o.gap = value("--gap");
    else if (a == "--step")
      o.step = value("--step");
    else if (a == "--frames")
      o.frames = value("--frames");
    else if (a == "--whole-pixels")
      o.whole_pixels = true;
    else if (a == "--align-patches")
      o.align_patches = true;
    else if (o.dir.empty() && a.rfind("--", 0) != 0)
      o.dir = a;
    else
      throw pvb::ConfigError("command line", a,
                             "DIR [--gap N] [--step N] [--frames N] [--whole-pixels] [--align-patches]");
  }
  if (o.dir.empty()) throw pvb::ConfigError("command line", "DIR", "a recorded sequence folder");
  return o;
}

struct Accumulator {
  double sum2[8] = {0};
  int count[8] = {0};
  double rot2_deg = 0, pos2_m = 0;
  Eigen::Vector3d rot_sum_deg = Eigen::Vector3d::Zero(), pos_sum_m = Eigen::Vector3d::Zero();
  int pairs = 0;
  // Pairs whose ground-truth rotation exceeds kTurnDeg: a bias that only
  // turns show (e.g. a camera mounted differently from its ground truth).
  Eigen::Vector3d turn_rot_sum_deg = Eigen::Vector3d::Zero(), turn_gt_sum_deg = Eigen::Vector3d::Zero();
  int turn_pairs = 0;
};
constexpr double kTurnDeg = 1.5;

void run(const Options& o) {
  const pvb::slam::Settings settings = pvb::slam::read_settings(o.dir + "/camera.yaml");
  const pvb::dataset::TumSequenceReader reader(o.dir, settings.depth_map_factor);
  const pvb::eval::Trajectory gt = pvb::eval::read_tum(o.dir + "/groundtruth.txt");
  std::map<std::int64_t, pvb::geom::SE3d> T_w_c_at;
  for (const auto& p : gt.poses) T_w_c_at[p.t_ns] = p.T_w_c;
  // Ground truth at a frame's time stamp: the nearest pose within 1 ms.
  const auto T_w_c_of = [&](std::int64_t t_ns) {
    auto it = T_w_c_at.lower_bound(t_ns - 1'000'000);
    if (it == T_w_c_at.end() || std::llabs(it->first - t_ns) > 1'000'000)
      throw pvb::Error(o.dir + "/groundtruth.txt: no pose within 1 ms of frame time " + std::to_string(t_ns) +
                       " ns");
    return it->second;
  };

  pvb::slam::OrbParams orb = settings.orb;
  orb.sub_pixel = !o.whole_pixels;
  pvb::slam::OrbExtractor extractor(orb);
  pvb::slam::StereoIntrinsics K;
  K.fx = settings.K.fx, K.fy = settings.K.fy, K.cx = settings.K.cx, K.cy = settings.K.cy, K.bf = settings.bf;
  const auto extract = [&](const cv::Mat& rgb) {
    cv::Mat grey;
    cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
    return extractor.extract(grey);
  };
  const auto depth_at = [](const cv::Mat& depth_m, cv::Point2f p) {
    const int u = static_cast<int>(std::lround(p.x)), v = static_cast<int>(std::lround(p.y));
    if (u < 0 || v < 0 || u >= depth_m.cols || v >= depth_m.rows) return 0.f;
    return depth_m.at<float>(v, u);
  };

  pvb::slam::PatchAlignParams align;
  align.scale_factor = orb.scale_factor;
  align.min_eigen_ratio = 0;  // edges too, as the check before SLAM had it

  Accumulator acc;
  const int n = std::min<int>(o.frames, static_cast<int>(reader.size_hint()));
  for (int k = 0; k + o.gap < n; k += o.step) {
    const pvb::sensor::RgbdFrame f0 = reader.load(k), f1 = reader.load(k + o.gap);
    pvb::slam::ImagePyramid pyr_a, pyr_b;
    const pvb::slam::OrbFeatures a = extract(f0.rgb);
    if (o.align_patches) pyr_a = pvb::slam::copy_pyramid(extractor.pyramid());
    const pvb::slam::OrbFeatures b = extract(f1.rgb);
    if (o.align_patches) pyr_b = pvb::slam::copy_pyramid(extractor.pyramid());
    const pvb::geom::SE3d T_w_c0 = T_w_c_of(f0.t_ns), T_c1_w = T_w_c_of(f1.t_ns).inverse();
    std::vector<Eigen::Vector3d> points_w;
    std::vector<pvb::slam::Observation> obs;
    for (std::size_t i = 0; i < a.keypoints.size(); ++i) {
      const cv::KeyPoint& ka = a.keypoints[i];
      const float z = depth_at(f0.depth_m, ka.pt);
      if (!(z > 0)) continue;
      const Eigen::Vector3d p_c0 = settings.K.unproject(ka.pt.x, ka.pt.y, z);
      const Eigen::Vector3d p_w = T_w_c0 * p_c0, p_c1 = T_c1_w * p_w;
      if (p_c1.z() < 0.1) continue;
      const Eigen::Vector2d uv = pvb::slam::project(K, p_c1);
      const double radius_px = 4.0 * extractor.level_scale(ka.octave);
      int best = -1, best_dist = 51;
      for (std::size_t j = 0; j < b.keypoints.size(); ++j) {
        const cv::KeyPoint& kb = b.keypoints[j];
        if (std::abs(kb.octave - ka.octave) > 1) continue;
        if (std::abs(kb.pt.x - uv.x()) > radius_px || std::abs(kb.pt.y - uv.y()) > radius_px) continue;
        const int d = static_cast<int>(cv::norm(a.descriptors.row(static_cast<int>(i)),
                                                b.descriptors.row(static_cast<int>(j)), cv::NORM_HAMMING));
        if (d < best_dist) best_dist = d, best = static_cast<int>(j);
      }
      if (best < 0) continue;
      cv::KeyPoint kb = b.keypoints[best];
      if (o.align_patches) {
        // Affine map of first-image offsets at ka to second-image offsets,
        // for a fronto-parallel patch at depth z, from ground truth.
        const auto project_b = [&](double u, double v) {
          return pvb::slam::project(K, T_c1_w * (T_w_c0 * settings.K.unproject(u, v, z)));
        };
        Eigen::Matrix2d A;
        A.col(0) = 0.5 * (project_b(ka.pt.x + 1, ka.pt.y) - project_b(ka.pt.x - 1, ka.pt.y));
        A.col(1) = 0.5 * (project_b(ka.pt.x, ka.pt.y + 1) - project_b(ka.pt.x, ka.pt.y - 1));
        Eigen::Vector2d aligned;
        if (pvb::slam::align_patch(pyr_a, {ka.pt.x, ka.pt.y}, A, pyr_b, kb.octave, {kb.pt.x, kb.pt.y}, align,
                                   &aligned))
          kb.pt = cv::Point2f(static_cast<float>(aligned.x()), static_cast<float>(aligned.y()));
      }
      const double scale = extractor.level_scale(kb.octave);
      const Eigen::Vector2d r = (Eigen::Vector2d(kb.pt.x, kb.pt.y) - uv) / scale;
      if (r.norm() > 3.0) continue;  // a wrong match, not keypoint error
      acc.sum2[kb.octave] += r.squaredNorm();
      ++acc.count[kb.octave];
      pvb::slam::Observation ob;
      ob.uv = {kb.pt.x, kb.pt.y};
      const float z1 = depth_at(f1.depth_m, kb.pt);
      ob.u_right = z1 > 0 ? kb.pt.x - K.bf / z1 : -1.0;
      ob.inv_sigma2 = 1.0 / (scale * scale);
      points_w.push_back(p_w);
      obs.push_back(ob);
    }
    if (obs.size() < 30) continue;
    const pvb::slam::PoseOptimizerResult res = pvb::slam::optimize_pose(T_c1_w, points_w, obs, K);
    const pvb::geom::SE3d E = res.T_c_w * T_c1_w.inverse();
    const Eigen::AngleAxisd aa(E.linear());
    const double rot_deg = aa.angle() * 180.0 / M_PI;
    acc.rot2_deg += rot_deg * rot_deg;
    acc.rot_sum_deg += aa.axis() * rot_deg;
    const Eigen::Vector3d dp_w = res.T_c_w.inverse().translation() - T_c1_w.inverse().translation();
    acc.pos2_m += dp_w.squaredNorm();
    acc.pos_sum_m += T_c1_w.linear() * dp_w;  // in the camera frame: x right, y down, z forward
    ++acc.pairs;
    const Eigen::AngleAxisd gt_rel((T_c1_w * T_w_c0).linear());  // frame k in frame k + gap
    if (gt_rel.angle() * 180.0 / M_PI > kTurnDeg) {
      acc.turn_rot_sum_deg += aa.axis() * rot_deg;
      acc.turn_gt_sum_deg += gt_rel.axis() * gt_rel.angle() * 180.0 / M_PI;
      ++acc.turn_pairs;
    }
  }
  if (acc.pairs == 0) throw pvb::Error(o.dir + ": no frame pair with 30 matches");
  double all2 = 0;
  int all = 0;
  for (int l = 0; l < 8; ++l) all2 += acc.sum2[l], all += acc.count[l];
  std::printf("%s, %s%s, gap %d: %d pairs, %d matches\n", o.dir.c_str(),
              o.whole_pixels ? "whole level pixels" : "sub-pixel", o.align_patches ? ", aligned patches" : "",
              o.gap, acc.pairs, all);
  std::printf(
      "residual RMS %.3f level px; pose from exact points: rotation RMS %.4f deg, position RMS %.2f mm\n",
      std::sqrt(all2 / all), std::sqrt(acc.rot2_deg / acc.pairs), 1e3 * std::sqrt(acc.pos2_m / acc.pairs));
  const Eigen::Vector3d rot_mean = acc.rot_sum_deg / acc.pairs, pos_mean = 1e3 * acc.pos_sum_m / acc.pairs;
  std::printf(
      "mean pose error (camera frame): rotation (%.4f, %.4f, %.4f) deg, position (%.2f, %.2f, %.2f) mm\n",
      rot_mean.x(), rot_mean.y(), rot_mean.z(), pos_mean.x(), pos_mean.y(), pos_mean.z());
  if (acc.turn_pairs > 0) {
    const Eigen::Vector3d e = acc.turn_rot_sum_deg / acc.turn_pairs, g = acc.turn_gt_sum_deg / acc.turn_pairs;
    std::printf("%d pairs turning over %.1f deg (mean rotation (%.2f, %.2f, %.2f) deg): mean rotation error "
                "(%.4f, %.4f, %.4f) deg\n",
                acc.turn_pairs, kTurnDeg, g.x(), g.y(), g.z(), e.x(), e.y(), e.z());
  }
  std::printf("per level:");
  for (int l = 0; l < 8; ++l)
    if (acc.count[l] > 0)
      std::printf(" %d: %.3f (%d)", l, std::sqrt(acc.sum2[l] / acc.count[l]), acc.count[l]);
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  try {
    run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::cerr << "keypoint_error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
