// pvbench match: the paper's feature-matching experiment on one image pair.
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "command.hpp"
#include "count_option.hpp"
#include "io_plan.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/image_file.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/harness/matching/experiment.hpp"
#include "pvb/plot/png.hpp"

namespace pvb::cli {
namespace {

struct MatchOptions {
  std::string img1, img2, homography;
  std::string depth1, depth2, pose1, pose2, settings;
  std::string sequence, frames;
  double gt_time_offset_s = 0.0;
  std::string method = "all";
  int runs = 10;
  unsigned seed = 1;
  std::string json, draw;
};

cv::Mat read_image(const std::string& path) {
  cv::Mat m = dataset::read_image(path, cv::IMREAD_COLOR, "image");
  harness::check_image_size(m, path);
  return m;
}

/// A depth image must cover its colour image pixel for pixel.
void check_depth_size(const cv::Mat& depth_m, const std::string& depth_path, const cv::Mat& image) {
  if (depth_m.size() == image.size()) return;
  throw IoError(depth_path, "depth image is " + std::to_string(depth_m.cols) + "x" +
                                std::to_string(depth_m.rows) + "; expected the size of its colour image, " +
                                std::to_string(image.cols) + "x" + std::to_string(image.rows));
}

/// A pose argument: "tx ty tz qx qy qz qw" (T_w_c, TUM order) or
/// "GROUNDTRUTH_FILE@TIMESTAMP" (interpolated in a TUM groundtruth.txt).
geom::SE3d resolve_pose(const std::string& arg, const std::string& what) {
  const auto at = arg.rfind('@');
  if (at != std::string::npos) {
    char* end = nullptr;
    const std::string ts = arg.substr(at + 1);
    const double t = std::strtod(ts.c_str(), &end);
    if (!end || *end != '\0' || ts.empty()) throw ConfigError("<command line>", what, "FILE@TIMESTAMP", arg);
    return harness::tum_pose_at(arg.substr(0, at), t);
  }
  return harness::parse_tum_pose(arg, what);
}

/// The coarse matches of an RGB-D pair (--sequence, or --img1/--depth1/
/// --pose1 ...) labelled from depth and poses; the images go to img1, img2.
harness::CoarseSet rgbd_coarse_set(const MatchOptions& o, cv::Mat* img1, cv::Mat* img2) {
  using namespace pvb::harness;
  RgbdGroundTruth gt;
  CameraSettings cam;
  std::string d1, d2;
  if (!o.sequence.empty()) {
    const dataset::TumSequenceReader seq(o.sequence, sensor::kTumDepthFactor, 0.05, dataset::MotionNeeds{});
    const auto& frames = seq.entries();
    const std::vector<std::string> ij = split_ws(o.frames, ",");
    int i = -1, j = -1;
    if (ij.size() == 2) {
      i = std::atoi(ij[0].c_str());
      j = std::atoi(ij[1].c_str());
    }
    if (i < 0 || j < 0 || i >= int(frames.size()) || j >= int(frames.size()))
      throw ConfigError("<command line>", "--frames", "I,J with 0 <= I,J < " + std::to_string(frames.size()),
                        o.frames);
    const std::string yaml = o.settings.empty() ? o.sequence + "/camera.yaml" : o.settings;
    cam = load_camera_settings(yaml);
    *img1 = read_image(o.sequence + "/" + frames[i].rgb);
    *img2 = read_image(o.sequence + "/" + frames[j].rgb);
    d1 = o.sequence + "/" + frames[i].depth;
    d2 = o.sequence + "/" + frames[j].depth;
    const std::string gtf = o.sequence + "/groundtruth.txt";
    // Poses at the rgb stamps (+ offset), up to 0.1 s from a ground-truth sample.
    const double dt = o.gt_time_offset_s;
    const double t1_s = geom::ns_to_seconds(frames[i].t_ns), t2_s = geom::ns_to_seconds(frames[j].t_ns);
    gt.T_c2_c1 = tum_pose_at(gtf, t2_s + dt, 0.1).inverse() * tum_pose_at(gtf, t1_s + dt, 0.1);
  } else {
    if (o.img1.empty() || o.img2.empty() || o.depth1.empty() || o.depth2.empty() || o.pose1.empty() ||
        o.pose2.empty() || o.settings.empty())
      throw ConfigError("<command line>", "RGB-D ground truth",
                        "--img1 --img2 --depth1 --depth2 --pose1 --pose2 --settings all given");
    cam = load_camera_settings(o.settings);
    *img1 = read_image(o.img1);
    *img2 = read_image(o.img2);
    d1 = o.depth1;
    d2 = o.depth2;
    gt.T_c2_c1 = resolve_pose(o.pose2, "--pose2").inverse() * resolve_pose(o.pose1, "--pose1");
  }
  gt.K = cam.K;
  gt.dist_coeffs = cam.dist_coeffs;
  gt.depth1_m = load_depth_m(d1, cam.depth_map_factor);
  gt.depth2_m = load_depth_m(d2, cam.depth_map_factor);
  check_depth_size(gt.depth1_m, d1, *img1);
  check_depth_size(gt.depth2_m, d2, *img2);
  CoarseSet cs = make_coarse_set(*img1, *img2);
  // Filters see undistorted pixels (as ORB-SLAM2 undistorts keypoints).
  cs.points = undistort_matches(cs.raw, cam.K, cam.dist_coeffs);
  cs.labels = label_by_rgbd(cs.raw, cs.points, gt);
  return cs;
}

/// The file of a GROUNDTRUTH_FILE@TIMESTAMP pose ("" for a pose given inline).
std::string pose_file(const std::string& arg) {
  const auto at = arg.rfind('@');
  return at == std::string::npos ? std::string() : arg.substr(0, at);
}

/// What match reads and writes: --json and --draw never replace an input.
void check_match_paths(const MatchOptions& o) {
  IoPlan plan;
  plan.input("the --img1 image", o.img1).input("the --img2 image", o.img2);
  plan.input("the --homography file", o.homography).input("the --depth1 image", o.depth1);
  plan.input("the --depth2 image", o.depth2).input("the --settings file", o.settings);
  plan.input("the --pose1 file", pose_file(o.pose1)).input("the --pose2 file", pose_file(o.pose2));
  add_sequence_inputs(&plan, "--sequence", o.sequence);
  plan.output_file("--json", o.json).output_file("--draw", o.draw);
  plan.check();
}

int run_match(const MatchOptions& o) {
  using namespace pvb::harness;
  check_match_paths(o);
  const std::vector<MatchMethod> methods = parse_methods(o.method);
  if (o.runs < 1) throw ConfigError("<command line>", "--runs", "a positive integer", std::to_string(o.runs));

  cv::Mat img1, img2;
  CoarseSet cs;
  const bool by_h = !o.homography.empty();
  const bool by_seq = !o.sequence.empty();
  const bool by_depth = !o.depth1.empty() || !o.depth2.empty() || !o.pose1.empty() || !o.pose2.empty();
  if (int(by_h) + int(by_seq) + int(by_depth) != 1)
    throw ConfigError(
        "<command line>", "ground truth",
        "exactly one of --homography, --depth1/--depth2/--pose1/--pose2/--settings, --sequence");

  if (by_h) {
    if (o.img1.empty() || o.img2.empty())
      throw ConfigError("<command line>", "--img1/--img2", "two image paths");
    img1 = read_image(o.img1);
    img2 = read_image(o.img2);
    cs = make_coarse_set(img1, img2);
    cs.labels = label_by_homography(cs.points, load_homography(o.homography));
  } else {
    cs = rgbd_coarse_set(o, &img1, &img2);
  }

  const auto reports = run_experiment(cs, methods, o.runs, o.seed);
  std::printf("coarse matches: %zu (ORB + ratio test, %.1f ms for both images)\n", cs.raw.size(),
              cs.extract_match_ms);
  std::printf("%-11s %9s %8s %9s %8s %8s %10s %9s\n", "method", "precision", "+-std", "recall", "+-std",
              "kept", "time_ms", "+-std");
  for (const auto& r : reports)
    std::printf("%-11s %9.4f %8.4f %9.4f %8.4f %8.1f %10.3f %9.3f\n", r.name.c_str(), r.precision.mean,
                r.precision.std, r.recall.mean, r.recall.std, r.kept.mean, r.time_ms.mean, r.time_ms.std);
  if (!reports.empty())
    std::printf("correct among coarse: %d of %d checked (%d without ground truth)\n",
                reports[0].coarse_correct, reports[0].coarse, reports[0].unknown);
  if (!o.json.empty()) write_file(o.json, reports_to_json(reports, o.runs, o.seed, cs.extract_match_ms));
  if (!o.draw.empty()) {
    // Draw the last method given (e.g. --method pe), with the first seed.
    slam::PeMatcher pe;
    const auto keep = run_method(methods.back(), cs, o.seed, slam::PeMatchParams{}, pe);
    const cv::Mat canvas = draw_matches(img1, img2, cs, keep);
    plot::write_image(canvas, o.draw);
  }
  return 0;
}

}  // namespace

Command add_match_command(CLI::App& app) {
  auto opts = std::make_shared<MatchOptions>();
  CLI::App* sub = app.add_subcommand(
      "match",
      "Feature-matching experiment (paper sec. 5.1): ORB coarse matches filtered by each method, "
      "scored against ground truth");
  sub->add_option("--img1", opts->img1, "first image")->check(path_check("match", "--img1"));
  sub->add_option("--img2", opts->img2, "second image")->check(path_check("match", "--img2"));
  sub->add_option("--homography", opts->homography, "ground truth: 3x3 homography file mapping img1 to img2")
      ->check(path_check("match", "--homography"));
  sub->add_option("--depth1", opts->depth1, "ground truth: depth image of img1 (16-bit PNG)")
      ->check(path_check("match", "--depth1"));
  sub->add_option("--depth2", opts->depth2, "ground truth: depth image of img2")
      ->check(path_check("match", "--depth2"));
  sub->add_option("--pose1", opts->pose1,
                  "pose T_w_c of img1: \"tx ty tz qx qy qz qw\" or GROUNDTRUTH_FILE@TIMESTAMP");
  sub->add_option("--pose2", opts->pose2, "pose T_w_c of img2 (same forms as --pose1)");
  sub->add_option("--settings", opts->settings,
                  "ORB-SLAM2 RGB-D settings, as pvbench slam reads them (its Camera.* and DepthMapFactor are "
                  "used); with --sequence it overrides DIR/camera.yaml")
      ->check(path_check("match", "--settings"));
  sub->add_option("--sequence", opts->sequence, "TUM-layout folder (rgb.txt, depth.txt, groundtruth.txt)")
      ->check(path_check("match", "--sequence"));
  sub->add_option("--frames", opts->frames, "I,J: rgb.txt entries (0-based) to match with --sequence");
  sub->add_option("--gt-time-offset", opts->gt_time_offset_s,
                  "with --sequence: seconds added to the rgb stamps before looking up ground-truth poses "
                  "(camera/mocap clock offset; default 0)");
  sub->add_option("--method", opts->method,
                  "all|orb|hamming|ransac|magsac|pe|pe-refined (comma list allowed)");
  sub->add_option("--runs", opts->runs, "repetitions with seeds S, S+1, ... (default 10)");
  sub->add_option("--seed", opts->seed, "first seed (default 1)")->check(seed_check("match", "--seed"));
  sub->add_option("--json", opts->json, "write the results as JSON")->check(path_check("match", "--json"));
  sub->add_option("--draw", opts->draw,
                  "write an image of the kept matches of the last method (green correct, "
                  "red wrong, yellow unchecked)")
      ->check(path_check("match", "--draw"));
  return {sub, [opts] { return run_match(*opts); }};
}

}  // namespace pvb::cli
