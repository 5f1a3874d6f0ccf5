// pvbench slam on bad input, end to end: small synthetic sequences (a
// textured plane sliding past a camera, 320x240), each broken in one way.
// Every case is one clear error line (or one warning line per skipped
// frame), never an internal error, and what was tracked is kept.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/time.hpp"
#include "run_pvbench.hpp"

using namespace pvb;

namespace {

using Result = test::RunResult;

constexpr int kFrames = 20;
constexpr int kWidth = 320, kHeight = 240;
constexpr double kFocalPx = 300, kDepthM = 2.0, kShiftPx = 2.0;

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_slam_in_" + name + "_" + std::to_string(::getpid());
  std::filesystem::remove_all(d);
  return d;
}

/// A sequence of kFrames frames: a blurred random texture moving kShiftPx
/// to the left per frame, seen at kDepthM (depth_m everywhere; 0 = none),
/// with its ground truth and camera.yaml.
std::string make_sequence(const std::string& name, float depth_m = static_cast<float>(kDepthM)) {
  const std::string dir = fresh(name);
  cv::Mat texture(kHeight + 20, kWidth + 2 * kFrames * static_cast<int>(kShiftPx), CV_8UC3);
  cv::RNG(11).fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.5);
  dataset::TumSequenceWriter writer(dir);
  for (int i = 0; i < kFrames; ++i) {
    sensor::RgbdFrame f;
    f.t_ns = geom::frame_time_ns(0, i, 30.0);
    f.index = static_cast<std::size_t>(i);
    texture(cv::Rect(static_cast<int>(i * kShiftPx), 10, kWidth, kHeight)).copyTo(f.rgb);
    f.depth_m = cv::Mat(kHeight, kWidth, CV_32FC1, cv::Scalar(depth_m));
    const double x_m = i * kShiftPx * kDepthM / kFocalPx;
    writer.write(f, geom::make_se3(geom::Mat3d::Identity(), geom::Vec3d(x_m, 0, 0)));
  }
  dataset::OrbSlamSettings s;
  s.K = {kFocalPx, kFocalPx, 159.5, 119.5, kWidth, kHeight};
  s.bf = 0.075 * kFocalPx;
  dataset::write_orbslam_settings(dir + "/camera.yaml", s);
  return dir;
}

Result slam(const std::string& seq, const std::string& out, const std::string& extra = "") {
  return test::run_pvbench("slam --sequence " + seq + " --settings " + seq + "/camera.yaml --out " + out +
                           " --sync --no-dense " + extra);
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

/// A number from stats.json ("key": value); -1 when absent.
double stat(const std::string& out, const std::string& key) {
  const std::string json = read_file(out + "/stats.json");
  const std::size_t p = json.find("\"" + key + "\": ");
  return p == std::string::npos ? -1 : std::atof(json.c_str() + p + key.size() + 4);
}

/// Replaces line `n` (1-based) of a text file.
void replace_line(const std::string& path, int n, const std::string& line) {
  std::istringstream in(read_file(path));
  std::string text;
  int k = 1;
  for (std::string l; std::getline(in, l); ++k) text += (k == n ? line : l) + "\n";
  write_file(path, text);
}

TEST(SlamInput, CleanSequenceTracksEveryFrame) {
  const std::string seq = make_sequence("clean"), out = fresh("clean_out");
  const Result r = slam(seq, out);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stat(out, "frames"), kFrames);
  EXPECT_EQ(stat(out, "not_initialized_frames"), 0);
}

// Without the image codecs module (moved away, or PVB_MODULE_DIR naming a
// folder without it) the first image read is one error line naming the
// module, and nothing is tracked.
TEST(SlamInput, AMissingImageCodecsModuleIsOneErrorLine) {
  const std::string seq = make_sequence("no_codecs"), out = fresh("no_codecs_out");
  const std::string empty = fresh("no_codecs_modules");
  std::filesystem::create_directories(empty);
  const Result r = test::run_pvbench_from_source("PVB_MODULE_DIR=" + empty, "slam --sequence " + seq + " --settings " +
                                                 seq + "/camera.yaml --out " + out + " --sync --no-dense");
  EXPECT_NE(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("cannot load the image codecs module " + empty + "/libpvb_imgcodecs.so"), std::string::npos)
      << r.output;
  EXPECT_EQ(count(r.output, "\n"), 1u) << r.output;
}

// A NaN or huge time stamp in associations.txt (or rgb.txt) is an error
// naming the file and line, before anything is written.
TEST(SlamInput, NanOrHugeTimeStampIsAnErrorNamingFileAndLine) {
  const std::string seq = make_sequence("nan");
  for (const std::string bad : {"nan", "9.3e9", "1e300"}) {
    replace_line(seq + "/associations.txt", 3, bad + " rgb/0.066667.png 0.066667 depth/0.066667.png");
    const std::string out = fresh("nan_out");
    const Result r = slam(seq, out);
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_NE(r.output.find("pvbench: error: " + seq + "/associations.txt:3: time stamp '" + bad + "'"),
              std::string::npos)
        << r.output;
    EXPECT_EQ(count(r.output, "\n"), 1u) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out + "/CameraTrajectory.txt"));
  }
  std::filesystem::remove(seq + "/associations.txt");
  replace_line(seq + "/rgb.txt", 6, "-9.3e9 rgb/0.066667.png");
  const Result r = slam(seq, fresh("nan_rgb_out"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find(seq + "/rgb.txt:6: time stamp '-9.3e9'"), std::string::npos) << r.output;
}

// associations.txt out of order would be tracked backwards in time: an
// error naming the line.  rgb.txt and depth.txt in any order are sorted:
// no frame is lost to the nearest-time search.
TEST(SlamInput, OutOfOrderStampsAreRejectedOrSorted) {
  const std::string seq = make_sequence("order");
  const std::string assoc = read_file(seq + "/associations.txt");
  replace_line(seq + "/associations.txt", 5, "0.033333 rgb/0.033333.png 0.033333 depth/0.033333.png");
  Result r = slam(seq, fresh("order_out"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find(seq + "/associations.txt:5: time stamps must increase"), std::string::npos)
      << r.output;
  EXPECT_EQ(count(r.output, "\n"), 1u) << r.output;

  std::filesystem::remove(seq + "/associations.txt");
  std::vector<std::string> lines;
  std::istringstream in(read_file(seq + "/depth.txt"));
  for (std::string l; std::getline(in, l);)
    if (!l.empty() && l[0] != '#') lines.push_back(l);
  std::reverse(lines.begin(), lines.end());
  std::string depth_txt = "# depth maps, newest first\n";
  for (const std::string& l : lines) depth_txt += l + "\n";
  write_file(seq + "/depth.txt", depth_txt);
  const std::string out = fresh("order_sorted_out");
  r = slam(seq, out);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stat(out, "frames"), kFrames) << r.output;
}

// --max-missing is the one rule: the reader no longer stops on its own cap
// before it, and a run it stops still writes stats.json and says where the
// trajectory is.  Values outside [0, 1] are an error.
TEST(SlamInput, MaxMissingIsTheOneRule) {
  const std::string seq = make_sequence("missing");
  for (int i = 4; i < 16; ++i)  // 12 of 20 colour images
    std::filesystem::remove(seq + "/rgb/" + geom::format_tum_time(geom::frame_time_ns(0, i, 30.0)) + ".png");
  std::string out = fresh("missing_loose");
  Result r = slam(seq, out, "--max-missing 0.9");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stat(out, "frames"), 8) << r.output;
  EXPECT_EQ(stat(out, "skipped_frames"), 12) << r.output;
  EXPECT_EQ(count(r.output, "pvbench: warning: skipping frame"), 12u) << r.output;

  out = fresh("missing_default");
  r = slam(seq, out);  // 10 %, at least 5: the 6th missing frame stops the run
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count(r.output, "pvbench: error: "), 1u) << r.output;
  EXPECT_NE(r.output.find("6 frames missing or corrupt (more than 5"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("what was tracked is in " + out), std::string::npos) << r.output;
  EXPECT_EQ(stat(out, "frames"), 4) << r.output;
  EXPECT_NE(read_file(out + "/stats.json").find("\"stop\": \"missing_frames\""), std::string::npos);

  for (const std::string bad : {"nan", "inf", "-1", "1e30"}) {
    r = slam(seq, fresh("missing_bad"), "--max-missing " + bad);
    EXPECT_EQ(r.code, 1) << bad << ": " << r.output;
    EXPECT_NE(r.output.find(
                  "pvbench: error: command line: --max-missing: expected a share of the frames in [0, 1]"),
              std::string::npos)
        << r.output;
    EXPECT_EQ(count(r.output, "\n"), 1u) << r.output;
  }
}

// All-zero depth never initialises: one error line after the outputs are
// written, not "lost 0" and exit 0.
TEST(SlamInput, NeverInitialisedIsAnErrorAfterTheOutputs) {
  const std::string seq = make_sequence("nodepth", 0.0f);
  const std::string out = fresh("nodepth_out");
  const Result r = slam(seq, out);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count(r.output, "pvbench: error: "), 1u) << r.output;
  EXPECT_NE(r.output.find("tracking never initialised in 20 frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("keypoints with depth"), std::string::npos) << r.output;  // tracking's own reason
  EXPECT_EQ(stat(out, "not_initialized_frames"), kFrames);
  EXPECT_TRUE(std::filesystem::exists(out + "/CameraTrajectory.txt"));
  EXPECT_EQ(r.output.find("warning"), std::string::npos)
      << r.output;  // nothing to evaluate: no warning either
}

TEST(SlamInput, NegativeMaxFramesIsAnError) {
  const std::string seq = make_sequence("neg");
  const std::string out = fresh("neg_out");
  const Result r = slam(seq, out, "--max-frames -3");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("pvbench: error: command line: --max-frames: expected a number of frames >= 0"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(out + "/stats.json"));
}

// Camera.width/height against the images, as `pvbench camera` checks it.
TEST(SlamInput, ImageSizeMustMatchTheSettings) {
  const std::string seq = make_sequence("size");
  std::string yaml = read_file(seq + "/camera.yaml");
  yaml = std::regex_replace(yaml, std::regex("Camera.width: 320"), "Camera.width: 640");
  yaml = std::regex_replace(yaml, std::regex("Camera.height: 240"), "Camera.height: 480");
  write_file(seq + "/camera.yaml", yaml);
  const Result r = slam(seq, fresh("size_out"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(
      r.output.find("camera.yaml: Camera.width/height: expected 320x240 (the images, rgb/0.000000.png), got "
                    "640x480"),
      std::string::npos)
      << r.output;
  EXPECT_EQ(count(r.output, "\n"), 1u) << r.output;
}

// A settings value that used to reach an OpenCV assertion is a ConfigError
// (exit 1) naming the key, and a YAML syntax error gives line and reason.
TEST(SlamInput, BadSettingsAreOneErrorNamingKeyOrLine) {
  const std::string seq = make_sequence("settings");
  const std::string yaml = read_file(seq + "/camera.yaml");
  write_file(seq + "/camera.yaml", std::regex_replace(yaml, std::regex("nLevels: 8"), "nLevels: 100"));
  Result r = slam(seq, fresh("settings_out"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("camera.yaml: ORBextractor.nLevels: expected a number of pyramid levels"),
            std::string::npos)
      << r.output;
  write_file(seq + "/camera.yaml", std::regex_replace(yaml, std::regex("Camera.fy: "), "Camera.fy "));
  r = slam(seq, fresh("settings_out"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("camera.yaml:6: cannot parse settings file: "), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("parseKey"), std::string::npos) << r.output;
}

// A truncated PNG is one warning line naming it; libpng's own message does
// not reach the terminal.
TEST(SlamInput, TruncatedPngIsOneWarningLine) {
  const std::string seq = make_sequence("cut");
  const std::string png = seq + "/rgb/" + geom::format_tum_time(geom::frame_time_ns(0, 5, 30.0)) + ".png";
  const std::string bytes = read_file(png);
  write_file(png, bytes.substr(0, bytes.size() * 2 / 3));
  const std::string out = fresh("cut_out");
  const Result r = slam(seq, out);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(
      count(r.output, "pvbench: warning: skipping frame 5: " + png + ": damaged colour image: truncated PNG"),
      1u)
      << r.output;
  EXPECT_EQ(count(r.output, "warning"), 1u) << r.output;
  EXPECT_EQ(r.output.find("libpng"), std::string::npos) << r.output;
  EXPECT_EQ(stat(out, "frames"), kFrames - 1);
}

}  // namespace

// A disk that fills up mid-run (every file capped at 1 KiB): the first
// failed write stops the run with one error naming that file, and every
// output holds whole lines only: the trajectory so far stays valid TUM.
TEST(SlamInput, FullDiskIsOneErrorNamingTheFileAndKeepsWholeLines) {
  const std::string seq = make_sequence("full");
  const std::string out = fresh("full_out");
  std::filesystem::create_directories(out);
  const Result r = test::run_pvbench_with_file_limit(
      "slam --sequence " + seq + " --settings " + seq + "/camera.yaml --out " + out + " --sync --no-dense",
      1);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count(r.output, "pvbench: error: "), 1u) << r.output;
  EXPECT_EQ(count(r.output, "\n"), 1u) << r.output;
  const std::regex failed("pvbench: error: " + out +
                          "/([A-Za-z]+\\.(txt|csv|json)): write failed: File too large\n");
  EXPECT_TRUE(std::regex_match(r.output, failed)) << r.output;
  std::size_t poses = 0;
  for (const auto& entry : std::filesystem::directory_iterator(out)) {
    const std::string text = read_file(entry.path().string());
    EXPECT_TRUE(text.empty() || text.back() == '\n') << entry.path();
    EXPECT_NE(entry.path().extension(), ".tmp") << entry.path();
    if (entry.path().filename() != "CameraTrajectory.txt") continue;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') continue;
      EXPECT_EQ(split_ws(line, " ").size(), 8u) << line;
      ++poses;
    }
  }
  EXPECT_GE(poses, 1u);  // what was tracked before the disk filled is kept
}

// A seed is a whole number in range: CLI11 wrapped "-1" to 4294967295 and
// ran.  Now every bad seed is one error line before anything is written.
TEST(SlamInput, SeedMustBeAWholeNumberInRange) {
  const std::string seq = make_sequence("seed");
  for (const std::string bad : {"-1", "abc", "1e3", "4294967296"}) {
    const std::string out = fresh("seed_out");
    const Result r = slam(seq, out, "--seed " + bad);
    EXPECT_EQ(r.code, 1) << bad << ": " << r.output;
    EXPECT_EQ(r.output,
              "pvbench: error: pvbench slam: --seed: expected a whole number in [0, 4294967295], got " + bad +
                  "\n");
    EXPECT_FALSE(std::filesystem::exists(out + "/CameraTrajectory.txt"));
  }
  EXPECT_EQ(slam(seq, fresh("seed_ok"), "--seed 4294967295").code, 0);
}

// A run that fails after it made its output folder says so in the folder:
// the list of what it wrote ends with the error.
TEST(SlamInput, AFailedRunMarksItsOutputFolder) {
  const std::string seq = make_sequence("failed_mark", 0.0f);
  const std::string out = fresh("failed_mark_out");
  const Result r = slam(seq, out);
  ASSERT_EQ(r.code, 1) << r.output;
  const std::string list = read_file(out + "/.pvbench");
  EXPECT_NE(list.find("\nfile CameraTrajectory.txt\n"), std::string::npos) << list;
  EXPECT_NE(list.find("\nfailed: "), std::string::npos) << list;
  EXPECT_NE(list.find("tracking never initialised in 20 frames"), std::string::npos) << list;
}

// Extending a map with another recording of the same place: both clocks
// start at 0, and the keyframe trajectory of both sessions could hold one
// stamp twice ("no evaluation: KeyFrameTrajectory.txt:28: duplicate time
// stamp").  The later session's stamps are put whole seconds past the
// map's last one, and the evaluation takes this session's keyframes back
// to its own clock.
TEST(SlamInput, ExtendingAMapGivesEverySessionItsOwnStamps) {
  const std::string seq = make_sequence("session_1");
  const std::string first = fresh("session_1_out"), second = fresh("session_2_out");
  const std::string map = fresh("session_maps");
  std::filesystem::create_directories(map);
  ASSERT_EQ(slam(seq, first, "--save-map " + map + "/one.pvbmap").code, 0);
  const Result r = slam(seq, second, "--map " + map + "/one.pvbmap --map-mode extend");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("no evaluation"), std::string::npos) << r.output;
  const auto stamps = [](const std::string& path) {
    std::vector<double> t;
    std::istringstream in(read_file(path));
    for (std::string line; std::getline(in, line);)
      if (!line.empty() && line[0] != '#') t.push_back(std::stod(split_ws(line, " ").at(0)));
    return t;
  };
  const std::vector<double> one = stamps(first + "/KeyFrameTrajectory.txt");
  const std::vector<double> both = stamps(second + "/KeyFrameTrajectory.txt");
  ASSERT_FALSE(one.empty());
  ASSERT_GT(both.size(), one.size()) << "the second session made no keyframe";
  EXPECT_TRUE(std::is_sorted(both.begin(), both.end()));
  EXPECT_EQ(std::adjacent_find(both.begin(), both.end()), both.end()) << "a stamp twice";
  EXPECT_EQ(std::vector<double>(both.begin(), both.begin() + static_cast<long>(one.size())), one);
  for (std::size_t i = one.size(); i < both.size(); ++i) EXPECT_GE(both[i], one.back() + 1.0) << i;
  // The tilt is scored on this session's keyframes alone, in its clock.
  std::smatch m;
  const std::string stats = read_file(second + "/stats.json");
  ASSERT_TRUE(std::regex_search(stats, m, std::regex("\"tilt\": \\{\"keyframes\": ([0-9]+)"))) << stats;
  EXPECT_EQ(std::stoul(m[1]), both.size() - one.size());
}

// The disk under the keyframe feature file fills mid-run (every file the
// run writes capped at 32 MiB, below the file's first 64 MB chunk): the
// core stops, and the run still writes what it tracked and its stats.json,
// says "system_error" there, saves no map, and ends on one error line.
TEST(SlamInput, AFeatureFileThatCannotGrowEndsTheRunWithItsStats) {
  const std::string station = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  const std::string seq = fresh("fullspill_seq"), out = fresh("fullspill_out");
  const std::string map = out + "_map.pvbmap";
  std::remove(map.c_str());
  const Result rec = test::run_pvbench("record --scenario " + station + " --out " + seq + " --frames 200");
  ASSERT_EQ(rec.code, 0) << rec.output;
  const Result r = test::run_pvbench_with_file_limit("slam --sequence " + seq + " --settings " + seq +
                                                         "/camera.yaml --out " + out + " --sync --no-dense --save-map " +
                                                         map,
                                                     32768);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(count(r.output, "pvbench: error: "), 1u) << r.output;
  EXPECT_NE(r.output.find("pvbench: error: " + seq + ": the SLAM core stopped after "), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("cannot grow the keyframe feature file by 64 MB"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the map is not saved"), std::string::npos) << r.output;
  const std::string stats = read_file(out + "/stats.json");
  EXPECT_NE(stats.find("\"stop\": \"system_error\""), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"failure\": \""), std::string::npos) << stats;
  EXPECT_LT(stat(out, "frames"), 200);
  EXPECT_GE(stat(out, "frames"), 20);  // what was tracked before the disk filled is kept
  EXPECT_FALSE(std::filesystem::exists(map));
}
