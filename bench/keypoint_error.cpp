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
//   keypoint_error DIR [--gap N] [--step N] [--frames N] [--whole-pixels]
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
#include "pvb/slam/optim/optimizer.hpp"

namespace {

struct Options {
  std::string dir;
  int gap = 5, step = 10, frames = 600;
  bool whole_pixels = false;
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
    else if (o.dir.empty() && a.rfind("--", 0) != 0)
      o.dir = a;
    else
      throw pvb::ConfigError("command line", a, "DIR [--gap N] [--step N] [--frames N] [--whole-pixels]");
  }
  if (o.dir.empty()) throw pvb::ConfigError("command line", "DIR", "a recorded sequence folder");
  return o;
}

struct Accumulator {
  double sum2[8] = {0};
  int count[8] = {0};
  double rot2_deg = 0, pos2_m = 0;
  int pairs = 0;
};

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

  Accumulator acc;
  const int n = std::min<int>(o.frames, static_cast<int>(reader.size_hint()));
  for (int k = 0; k + o.gap < n; k += o.step) {
    const pvb::sensor::RgbdFrame f0 = reader.load(k), f1 = reader.load(k + o.gap);
    const pvb::slam::OrbFeatures a = extract(f0.rgb), b = extract(f1.rgb);
    const pvb::geom::SE3d T_w_c0 = T_w_c_of(f0.t_ns), T_c1_w = T_w_c_of(f1.t_ns).inverse();
    std::vector<Eigen::Vector3d> points_w;
    std::vector<pvb::slam::Observation> obs;
    for (std::size_t i = 0; i < a.keypoints.size(); ++i) {
      const cv::KeyPoint& ka = a.keypoints[i];
      const float z = depth_at(f0.depth_m, ka.pt);
      if (!(z > 0)) continue;
      const Eigen::Vector3d p_c0((ka.pt.x - K.cx) * z / K.fx, (ka.pt.y - K.cy) * z / K.fy, z);
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
      const cv::KeyPoint& kb = b.keypoints[best];
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
    const double rot_deg = Eigen::AngleAxisd(E.linear()).angle() * 180.0 / M_PI;
    acc.rot2_deg += rot_deg * rot_deg;
    acc.pos2_m += (res.T_c_w.inverse().translation() - T_c1_w.inverse().translation()).squaredNorm();
    ++acc.pairs;
  }
  if (acc.pairs == 0) throw pvb::Error(o.dir + ": no frame pair with 30 matches");
  double all2 = 0;
  int all = 0;
  for (int l = 0; l < 8; ++l) all2 += acc.sum2[l], all += acc.count[l];
  std::printf("%s, %s, gap %d: %d pairs, %d matches\n", o.dir.c_str(),
              o.whole_pixels ? "whole level pixels" : "sub-pixel", o.gap, acc.pairs, all);
  std::printf(
      "residual RMS %.3f level px; pose from exact points: rotation RMS %.4f deg, position RMS %.2f mm\n",
      std::sqrt(all2 / all), std::sqrt(acc.rot2_deg / acc.pairs), 1e3 * std::sqrt(acc.pos2_m / acc.pairs));
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
