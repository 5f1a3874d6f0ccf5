#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/harness/matching/experiment.hpp"
#include "shared_data.hpp"

namespace pvb::harness {
namespace {

/// A file or folder under ../shared.
std::string shared(const std::string& relative) { return pvb::test::shared_path(relative); }

TEST(MatchGroundTruth, HomographyLabels) {
  Eigen::Matrix3d H;
  H << 2, 0, 10, 0, 2, -5, 0, 0, 1;  // (x, y) -> (2x + 10, 2y - 5)
  const std::vector<slam::PointMatch> m = {
      {{1, 1}, {12, -3}},        // exact
      {{1, 1}, {14.9, -3}},      // 2.9 px off
      {{1, 1}, {15.1, -3}},      // 3.1 px off
  };
  const auto l = label_by_homography(m, H, 3.0);
  EXPECT_EQ(l[0], MatchLabel::kCorrect);
  EXPECT_EQ(l[1], MatchLabel::kCorrect);
  EXPECT_EQ(l[2], MatchLabel::kWrong);
}

TEST(MatchGroundTruth, RgbdLabelsFromKnownMotion) {
  RgbdGroundTruth gt;
  gt.K = geom::PinholeIntrinsics{};  // fx = fy = 525, cx 319.5, cy 239.5, 640x480
  gt.depth1_m = cv::Mat(480, 640, CV_32F, cv::Scalar(2.0f));
  gt.depth2_m = cv::Mat(480, 640, CV_32F, cv::Scalar(1.9f));
  // Camera 2 is 0.1 m forward along z: p_c2 = p_c1 - (0, 0, 0.1).
  gt.T_c2_c1 = geom::make_se3(geom::Mat3d::Identity(), geom::Vec3d(0, 0, -0.1));
  // Pixel (419.5, 239.5) at 2 m -> x = 100/525*2; at z = 1.9 projects to
  // u = 319.5 + 525 * x / 1.9 = 319.5 + 100 * 2 / 1.9 = 424.763...
  const double u2 = 319.5 + 200.0 / 1.9;
  std::vector<slam::PointMatch> m = {{{419.5, 239.5}, {u2, 239.5}},
                                     {{419.5, 239.5}, {u2 + 3.5, 239.5}},
                                     {{419.5, 239.5}, {u2, 239.5}}};
  cv::Mat d2 = gt.depth2_m.clone();
  d2.at<float>(240, static_cast<int>(std::lround(u2))) = 1.0f;  // inconsistent depth at the 3rd
  auto labels = label_by_rgbd(m, m, gt);
  EXPECT_EQ(labels[0], MatchLabel::kCorrect);
  EXPECT_EQ(labels[1], MatchLabel::kWrong);
  EXPECT_EQ(labels[2], MatchLabel::kCorrect);
  gt.depth2_m = d2;
  labels = label_by_rgbd(m, m, gt);
  EXPECT_EQ(labels[2], MatchLabel::kWrong);
  gt.depth1_m.at<float>(240, 420) = 0.0f;  // no depth: cannot be checked
  labels = label_by_rgbd(m, m, gt);
  EXPECT_EQ(labels[0], MatchLabel::kUnknown);
}

TEST(MatchGroundTruth, TumPoseParsingAndInterpolation) {
  const geom::SE3d T = parse_tum_pose("1 2 3 0 0 0 1", "--pose1");
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_THROW(parse_tum_pose("1 2 3", "--pose1"), ConfigError);
  EXPECT_THROW(parse_tum_pose("1 2 3 0 0 0 x", "--pose1"), ConfigError);
  const std::string path = ::testing::TempDir() + "/gt_interp.txt";
  write_file(path, "# t tx ty tz qx qy qz qw\n10.0 0 0 0 0 0 0 1\n10.1 1 0 0 0 0 0.7071067811865476 0.7071067811865476\n");
  const geom::SE3d M = tum_pose_at(path, 10.04);
  EXPECT_NEAR(M.translation().x(), 0.4, 1e-9);
  EXPECT_NEAR(geom::rotation_angle_rad(M.linear()), 0.4 * M_PI / 2, 1e-9);  // 40 % of 90 deg (slerp)
  EXPECT_THROW(tum_pose_at(path, 10.05, 0.01), IoError);  // 0.05 s from both samples
  EXPECT_THROW(tum_pose_at(path, 11.0), IoError);
  EXPECT_THROW(tum_pose_at(path + ".missing", 10.0), IoError);
}


TEST(MatchGroundTruth, SettingsFromOrbSlamYaml) {
  const CameraSettings s = load_camera_settings(shared("data/tum/TUM1.yaml"));
  EXPECT_DOUBLE_EQ(s.K.fx, 517.306408);
  EXPECT_DOUBLE_EQ(s.K.cy, 255.313989);
  EXPECT_DOUBLE_EQ(s.depth_map_factor, 5000.0);
  ASSERT_EQ(s.dist_coeffs.cols, 5);
  EXPECT_DOUBLE_EQ(s.dist_coeffs.at<double>(0, 0), 0.262383);
  const std::string bad = ::testing::TempDir() + "/bad.yaml";
  write_file(bad, "%YAML:1.0\nCamera.fx: 500.0\n");
  EXPECT_THROW(load_camera_settings(bad), ConfigError);
}

TEST(MatchMetrics, ScoreAndSpread) {
  const std::vector<MatchLabel> l = {MatchLabel::kCorrect, MatchLabel::kCorrect, MatchLabel::kWrong,
                                     MatchLabel::kUnknown, MatchLabel::kCorrect};
  const RunScore s = score_mask({1, 0, 1, 1, 1}, l);
  EXPECT_EQ(s.kept, 3);                      // the unknown one is not counted
  EXPECT_DOUBLE_EQ(s.precision, 2.0 / 3.0);  // 2 correct of 3 kept
  EXPECT_DOUBLE_EQ(s.recall, 2.0 / 3.0);     // 2 of 3 correct kept
  const Spread sp = spread_of({1, 2, 3, 4});
  EXPECT_DOUBLE_EQ(sp.mean, 2.5);
  EXPECT_NEAR(sp.std, std::sqrt(5.0 / 3.0), 1e-12);
  EXPECT_EQ(sp.min, 1);
  EXPECT_EQ(sp.max, 4);
  EXPECT_THROW(parse_methods("pe,bogus"), ConfigError);
  EXPECT_EQ(parse_methods("all").size(), 6u);
}

TEST(MatchExperiment, OxfordWallFiltersImprovePrecision) {
  const std::string dir = shared("data/oxford/wall/");
  const cv::Mat a = cv::imread(dir + "img1.ppm"), b = cv::imread(dir + "img3.ppm");
  CoarseSet cs = make_coarse_set(a, b);
  cs.labels = label_by_homography(cs.points, load_homography(dir + "H1to3p"));
  const auto rep = run_experiment(cs, all_methods(), 3, 1);
  ASSERT_EQ(rep.size(), 6u);
  const MethodReport& orb = rep[0];
  EXPECT_DOUBLE_EQ(orb.recall.mean, 1.0);
  for (size_t i = 2; i < rep.size(); ++i) {  // the F-based filters
    EXPECT_GT(rep[i].precision.mean, orb.precision.mean + 0.05) << rep[i].name;
    EXPECT_GT(rep[i].recall.mean, 0.8) << rep[i].name;
  }
}

std::string slurp(const std::string& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(MatchCli, OxfordWallJson) {
  const std::string dir = shared("data/oxford/wall/");
  const std::string json = ::testing::TempDir() + "/match_wall.json";
  const std::string png = ::testing::TempDir() + "/match_wall.png";
  std::remove(json.c_str());
  const std::string cmd = std::string(PVB_BINARY_DIR) + "/bin/pvbench match --img1 " + dir + "img1.ppm --img2 " +
                          dir + "img2.ppm --homography " + dir + "H1to2p --runs 2 --json " + json + " --draw " + png +
                          " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const std::string j = slurp(json);
  for (const char* name : {"orb", "hamming", "ransac", "magsac", "pe", "pe-refined"})
    EXPECT_NE(j.find(std::string("\"name\":\"") + name + "\""), std::string::npos) << name;
  for (const char* key : {"\"precision\":", "\"recall\":", "\"kept\":", "\"coarse\":", "\"time_ms\":",
                          "\"precision_std\":", "\"recall_min\":"})
    EXPECT_NE(j.find(key), std::string::npos) << key;
  EXPECT_FALSE(cv::imread(png).empty());
  // A bad ground-truth file is one error line and a non-zero exit.
  const std::string bad = std::string(PVB_BINARY_DIR) + "/bin/pvbench match --img1 " + dir + "img1.ppm --img2 " +
                          dir + "img2.ppm --homography /nonexistent/H 2> /dev/null";
  EXPECT_NE(std::system(bad.c_str()), 0);
}

TEST(MatchCli, TumSequencePair) {
  const std::string seq = shared("data/tum/fr1_xyz_pair");
  const std::string json = ::testing::TempDir() + "/match_tum.json";
  const std::string cmd = std::string(PVB_BINARY_DIR) + "/bin/pvbench match --sequence " + seq +
                          " --frames 0,1 --settings " + shared("data/tum/TUM1.yaml") +
                          " --runs 1 --method orb,pe --json " + json + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const std::string j = slurp(json);
  EXPECT_NE(j.find("\"name\":\"pe\""), std::string::npos);
  EXPECT_EQ(j.find("\"name\":\"ransac\""), std::string::npos);
}

std::string temp_file(const std::string& name) {
  return ::testing::TempDir() + "pvb_match_" + std::to_string(::getpid()) + "_" + name;
}

TEST(MatchGroundTruth, SingularOrNonFiniteHomographyIsAnError) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"1 2 3\n2 4 6\n0 0 1\n", "singular"},  // rank 2
      {"0 0 0\n0 0 0\n0 0 0\n", "singular"},
      {"1e-300 0 0\n0 1e-300 0\n0 0 1\n", "singular"},
      {"1 0 nan\n0 1 0\n0 0 1\n", "nine finite numbers"},
      {"1 0 0\n0 1 0\n", "nine finite numbers"}};
  for (const auto& [text, why] : bad) {
    const std::string path = temp_file("H");
    write_file(path, text);
    try {
      load_homography(path);
      ADD_FAILURE() << text;
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  }
  const std::string scaled = temp_file("Hs");
  write_file(scaled, "1e-6 0 1e-4\n0 2e-6 0\n0 0 1e-6\n");  // a valid map at a small scale
  EXPECT_NO_THROW(load_homography(scaled));
}

TEST(MatchGroundTruth, DepthWithoutValidPixelsIsAnError) {
  const std::string zero = temp_file("zero.png");
  ASSERT_TRUE(cv::imwrite(zero, cv::Mat(48, 64, CV_16UC1, cv::Scalar(0))));
  try {
    load_depth_m(zero, 5000);
    FAIL() << "accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("zero.png: depth image holds no valid depth"), std::string::npos)
        << e.what();
  }
  cv::Mat one(48, 64, CV_16UC1, cv::Scalar(0));
  one.at<std::uint16_t>(3, 4) = 10000;
  ASSERT_TRUE(cv::imwrite(zero, one));
  EXPECT_FLOAT_EQ(load_depth_m(zero, 5000).at<float>(3, 4), 2.0f);
}

// The settings are read as pvbench slam reads them: a value it refuses is
// refused here too, naming the key.
TEST(MatchGroundTruth, CameraSettingsOutOfRangeAreErrors) {
  const std::string good = read_file(shared("data/tum/TUM1.yaml"));
  const std::string path = temp_file("cam.yaml");
  write_file(path, good);
  EXPECT_NO_THROW(load_camera_settings(path));
  for (const auto& [key, bad] : std::vector<std::pair<std::string, std::string>>{
           {"Camera.width", "1e10"}, {"Camera.k1", ".nan"}, {"DepthMapFactor", ".inf"}, {"Camera.cx", "1e9"}}) {
    write_file(path, std::regex_replace(good, std::regex(key + ": .*"), key + ": " + bad));
    try {
      load_camera_settings(path);
      ADD_FAILURE() << key << " " << bad;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  }
}

TEST(MatchExperiment, TinyImagesAreAClearError) {
  const cv::Mat dot(1, 1, CV_8UC3, cv::Scalar::all(128));
  EXPECT_THROW(check_image_size(dot, "dot.png"), IoError);
  EXPECT_THROW(make_coarse_set(dot, dot), pvb::Error);  // not an OpenCV assertion
  cv::Mat small(kMinImageSidePx, kMinImageSidePx, CV_8UC3);
  cv::RNG(3).fill(small, cv::RNG::UNIFORM, 0, 255);
  EXPECT_NO_THROW(check_image_size(small, "small.png"));
  EXPECT_NO_THROW(make_coarse_set(small, small));
}

/// Runs pvbench with `args`; stdout and stderr together in *out.
int run_pvbench(const std::string& args, std::string* out) {
  const std::string log = temp_file("log.txt");
  const int status =
      std::system((std::string(PVB_BINARY_DIR) + "/bin/pvbench " + args + " > " + log + " 2>&1").c_str());
  *out = read_file(log);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A 1x1 image, a truncated PPM, a singular homography and an all-zero
// depth image are each one error line naming the file (exit 1, not an
// internal error, and nothing from OpenCV or libpng).
TEST(MatchCli, BadInputsAreOneErrorLineEach) {
  const std::string wall = shared("data/oxford/wall/");
  const std::string dot = temp_file("dot.ppm"), cut = temp_file("cut.ppm"), H = temp_file("H"),
                    zero = temp_file("zero.png");
  ASSERT_TRUE(cv::imwrite(dot, cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(9))));
  const std::string ppm = read_file(wall + "img2.ppm");
  write_file(cut, ppm.substr(0, ppm.size() / 2));
  write_file(H, "1 2 3\n2 4 6\n0 0 1\n");
  const cv::Mat img1 = cv::imread(wall + "img1.ppm");
  ASSERT_TRUE(cv::imwrite(zero, cv::Mat(img1.size(), CV_16UC1, cv::Scalar(0))));
  const std::string pose = "\"0 0 0 0 0 0 1\"";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--img1 " + dot + " --img2 " + wall + "img2.ppm --homography " + wall + "H1to2p",
       dot + ": image is 1x1"},
      {"--img1 " + wall + "img1.ppm --img2 " + cut + " --homography " + wall + "H1to2p",
       cut + ": damaged image: truncated PNM"},
      {"--img1 " + wall + "img1.ppm --img2 " + wall + "img2.ppm --homography " + H,
       H + ": the homography is singular"},
      {"--img1 " + wall + "img1.ppm --img2 " + wall + "img1.ppm --depth1 " + zero + " --depth2 " + zero +
           " --pose1 " + pose + " --pose2 " + pose + " --settings " + shared("data/tum/TUM1.yaml") +
           " --runs 1",
       zero + ": depth image holds no valid depth"}};
  for (const auto& [args, expected] : cases) {
    std::string out;
    EXPECT_EQ(run_pvbench("match " + args, &out), 1) << args << "\n" << out;
    EXPECT_NE(out.find("pvbench: error: " + expected), std::string::npos) << out;
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  }
}

}  // namespace
}  // namespace pvb::harness
