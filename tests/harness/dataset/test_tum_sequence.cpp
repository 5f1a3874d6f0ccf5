#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/time.hpp"

using namespace pvb;

namespace {
std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_ds_" + name;
  std::system(("rm -rf " + d).c_str());
  return d;
}
sensor::RgbdFrame synthetic(int i) {
  sensor::RgbdFrame f;
  f.t_ns = geom::frame_time_ns(0, i, 30.0);
  f.rgb = cv::Mat(48, 64, CV_8UC3);
  cv::RNG rng(static_cast<std::uint64_t>(i) + 1);  // local: the same frame every call
  rng.fill(f.rgb, cv::RNG::UNIFORM, 0, 255);
  f.depth_m = cv::Mat(48, 64, CV_32FC1);
  rng.fill(f.depth_m, cv::RNG::UNIFORM, 0.5, 4.5);
  f.depth_m.at<float>(0, 0) = 0.0f;   // invalid stays invalid
  f.depth_m.at<float>(0, 1) = 20.0f;  // beyond 16-bit range: invalid
  return f;
}
}  // namespace

TEST(TumSequence, WrittenSequenceReadsBackExactly) {
  const std::string dir = temp_dir("roundtrip") + "/nested/seq";
  {
    dataset::TumSequenceWriter w(dir);
    for (int i = 0; i < 3; ++i) w.write(synthetic(i), geom::SE3d::Identity());
  }
  dataset::TumSequenceReader r(dir);
  ASSERT_EQ(r.size_hint(), 3u);
  for (int i = 0; i < 3; ++i) {
    const auto f = r.next();
    ASSERT_TRUE(f.has_value());
    const sensor::RgbdFrame ref = synthetic(i);
    EXPECT_EQ(f->t_ns, geom::seconds_to_ns(std::stod(geom::format_tum_time(ref.t_ns))));
    EXPECT_EQ(cv::norm(f->rgb, ref.rgb, cv::NORM_INF), 0.0);
    // depth quantised to 1/5000 m: at most half a step off (plus float rounding)
    for (int rr = 0; rr < 48; ++rr)
      for (int c = 2; c < 64; ++c) ASSERT_NEAR(f->depth_m.at<float>(rr, c), ref.depth_m.at<float>(rr, c), 0.5 / 5000 + 1e-6);
    EXPECT_EQ(f->depth_m.at<float>(0, 0), 0.0f);
    EXPECT_EQ(f->depth_m.at<float>(0, 1), 0.0f);
  }
  EXPECT_FALSE(r.next().has_value());
}

TEST(TumSequence, ReaderAssociatesWithoutAnAssociationFile) {
  const std::string dir = temp_dir("assoc");
  {
    dataset::TumSequenceWriter w(dir);
    for (int i = 0; i < 4; ++i) w.write(synthetic(i), geom::SE3d::Identity());
  }
  std::remove((dir + "/associations.txt").c_str());
  // shift the depth stamps by 7 ms, as a real Kinect's are, and drop one
  const auto depth = dataset::read_tum_list(dir + "/depth.txt");
  std::string text = "# depth\n";
  for (std::size_t i = 0; i < depth.size(); ++i) {
    if (i == 1) continue;
    text += geom::format_tum_time(depth[i].first + 7'000'000) + " " + depth[i].second + "\n";
  }
  write_file(dir + "/depth.txt", text);
  dataset::TumSequenceReader r(dir);
  ASSERT_EQ(r.entries().size(), 3u);  // the rgb frame without depth is left out
  for (const auto& e : r.entries()) EXPECT_EQ(e.depth_t_ns - e.t_ns, 7'000'000);
  EXPECT_TRUE(r.next().has_value());
}

TEST(TumSequence, MissingImagesAreSkippedWithAWarning) {
  const std::string dir = temp_dir("missing");
  {
    dataset::TumSequenceWriter w(dir);
    for (int i = 0; i < 3; ++i) w.write(synthetic(i), geom::SE3d::Identity());
  }
  std::remove((dir + "/rgb/0.033333.png").c_str());
  dataset::TumSequenceReader r(dir);
  int n = 0;
  while (r.next()) ++n;
  EXPECT_EQ(n, 2);
  EXPECT_EQ(r.skipped(), 1u);
  EXPECT_THROW(r.load(1), IoError);
}

TEST(TumSequence, MalformedListNamesFileAndLine) {
  const std::string dir = temp_dir("bad");
  dataset::make_dirs(dir);
  write_file(dir + "/rgb.txt", "# header\n0.1 rgb/a.png\nbanana\n");
  try {
    dataset::read_tum_list(dir + "/rgb.txt");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("rgb.txt:3"), std::string::npos) << e.what();
  }
}

TEST(TumSequence, SettingsFileIsReadableByOpenCv) {
  const std::string dir = temp_dir("settings");
  dataset::make_dirs(dir);
  dataset::OrbSlamSettings s;
  s.K = {525, 525, 319.5, 239.5, 640, 480};
  s.bf = 39.375;
  dataset::write_orbslam_settings(dir + "/camera.yaml", s);
  cv::FileStorage fs(dir + "/camera.yaml", cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  EXPECT_DOUBLE_EQ(static_cast<double>(fs["Camera.fx"]), 525.0);
  EXPECT_DOUBLE_EQ(static_cast<double>(fs["Camera.cx"]), 319.5);
  EXPECT_DOUBLE_EQ(static_cast<double>(fs["Camera.bf"]), 39.375);
  EXPECT_DOUBLE_EQ(static_cast<double>(fs["DepthMapFactor"]), 5000.0);
  EXPECT_EQ(static_cast<int>(fs["ORBextractor.nFeatures"]), 1000);
  EXPECT_EQ(static_cast<int>(fs["Camera.RGB"]), 1);
  EXPECT_TRUE(fs["KeyFrame.minTrackedClose"].empty());  // written only when set
  EXPECT_TRUE(fs["KeyFrame.refOverlap"].empty());

  s.n_features = 2000;
  s.kf_min_tracked_close = 400;
  s.kf_ref_overlap = 0.4375;  // written as given, not rounded
  dataset::write_orbslam_settings(dir + "/tuned.yaml", s);
  cv::FileStorage tuned(dir + "/tuned.yaml", cv::FileStorage::READ);
  ASSERT_TRUE(tuned.isOpened());
  EXPECT_EQ(static_cast<int>(tuned["ORBextractor.nFeatures"]), 2000);
  EXPECT_EQ(static_cast<int>(tuned["KeyFrame.minTrackedClose"]), 400);
  EXPECT_DOUBLE_EQ(static_cast<double>(tuned["KeyFrame.refOverlap"]), 0.4375);
  EXPECT_DOUBLE_EQ(static_cast<double>(tuned["Camera.fx"]), 525.0);
}

TEST(TumSequence, UnwritableFolderIsAClearError) {
  if (geteuid() == 0) {
    // root may write anywhere: use a path below a regular file instead
    const std::string f = temp_dir("file");
    write_file(f, "x");
    EXPECT_THROW(dataset::TumSequenceWriter w(f + "/seq"), IoError);
  } else {
    EXPECT_THROW(dataset::TumSequenceWriter w("/proc/pvb_no"), IoError);
  }
}

namespace {
/// The IoError message of f(), or "" when it does not throw one.
template <class F>
std::string io_error_of(F f) {
  try {
    f();
  } catch (const IoError& e) {
    return e.what();
  }
  return {};
}

/// A three-frame sequence whose associations.txt is replaced by `assoc`.
std::string with_associations(const std::string& name, const std::string& assoc) {
  const std::string dir = temp_dir(name);
  {
    dataset::TumSequenceWriter w(dir);
    for (int i = 0; i < 3; ++i) w.write(synthetic(i), geom::SE3d::Identity());
  }
  write_file(dir + "/associations.txt", assoc);
  return dir;
}
}  // namespace

// A time stamp that is not finite or beyond +-9e9 s (t_ns would leave
// int64) names the file and line, in every list the reader takes.
TEST(TumSequence, NonFiniteOrHugeTimeStampsNameFileAndLine) {
  const std::string a = "0.000000 rgb/0.000000.png 0.000000 depth/0.000000.png\n";
  for (const std::string bad : {"nan", "inf", "-inf", "9.3e9", "1e300", "-9.3e9"}) {
    const std::string dir =
        with_associations("assoc_t", "# c\n" + a + bad + " rgb/0.033333.png 0.033333 depth/0.033333.png\n");
    const std::string what = io_error_of([&] { dataset::TumSequenceReader r(dir); });
    EXPECT_NE(what.find("associations.txt:3: time stamp '" + bad + "'"), std::string::npos)
        << bad << ": " << what;
    const std::string depth_bad =
        with_associations("assoc_d", a + "0.033333 rgb/0.033333.png " + bad + " depth/x.png\n");
    EXPECT_NE(io_error_of([&] { dataset::TumSequenceReader r(depth_bad); }).find("associations.txt:2:"),
              std::string::npos)
        << bad;
    write_file(dir + "/rgb.txt", "0.1 rgb/a.png\n" + bad + " rgb/b.png\n");
    EXPECT_NE(io_error_of([&] { dataset::read_tum_list(dir + "/rgb.txt"); }).find("rgb.txt:2: time stamp"),
              std::string::npos)
        << bad;
  }
}

// associations.txt is tracked in its order: a stamp that does not increase
// is an error naming its line (it would be tracked backwards in time).
TEST(TumSequence, OutOfOrderAssociationsAreAnError) {
  const std::string dir = with_associations("assoc_order",
                                            "0.000000 rgb/0.000000.png 0.000000 depth/0.000000.png\n"
                                            "0.066667 rgb/0.066667.png 0.066667 depth/0.066667.png\n"
                                            "0.033333 rgb/0.033333.png 0.033333 depth/0.033333.png\n");
  const std::string what = io_error_of([&] { dataset::TumSequenceReader r(dir); });
  EXPECT_NE(what.find("associations.txt:3: time stamps must increase"), std::string::npos) << what;
  write_file(dir + "/associations.txt",
             "0.000000 rgb/0.000000.png 0.000000 depth/0.000000.png\n"
             "0.000000 rgb/0.033333.png 0.033333 depth/0.033333.png\n");
  EXPECT_NE(io_error_of([&] { dataset::TumSequenceReader r(dir); }).find("associations.txt:2:"),
            std::string::npos);
}

// Without associations.txt, rgb.txt and depth.txt may come in any order:
// they are sorted before the nearest-time association (which searches the
// depth list by bisection), so no frame is lost; a repeated stamp is an error.
TEST(TumSequence, UnsortedListsAreSortedAndRepeatedStampsRejected) {
  const std::string dir = temp_dir("unsorted");
  {
    dataset::TumSequenceWriter w(dir);
    for (int i = 0; i < 8; ++i) w.write(synthetic(i), geom::SE3d::Identity());
  }
  std::remove((dir + "/associations.txt").c_str());
  const auto depth = dataset::read_tum_list(dir + "/depth.txt");
  const auto rgb = dataset::read_tum_list(dir + "/rgb.txt");
  std::string depth_text = "# depth, newest first\n", rgb_text;
  for (std::size_t i = depth.size(); i-- > 0;)
    depth_text += geom::format_tum_time(depth[i].first) + " " + depth[i].second + "\n";
  for (std::size_t i : {3, 0, 7, 1, 6, 2, 5, 4})
    rgb_text += geom::format_tum_time(rgb[i].first) + " " + rgb[i].second + "\n";
  write_file(dir + "/depth.txt", depth_text);
  write_file(dir + "/rgb.txt", rgb_text);
  const auto sorted = dataset::read_tum_list(dir + "/rgb.txt");
  for (std::size_t i = 0; i < sorted.size(); ++i) EXPECT_EQ(sorted[i], rgb[i]);
  dataset::TumSequenceReader r(dir);
  ASSERT_EQ(r.entries().size(), 8u);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(r.entries()[i].t_ns, rgb[i].first);
    EXPECT_EQ(r.entries()[i].depth_t_ns, depth[i].first);
  }
  write_file(dir + "/rgb.txt", rgb_text + geom::format_tum_time(rgb[5].first) + " rgb/again.png\n");
  EXPECT_NE(
      io_error_of([&] { dataset::read_tum_list(dir + "/rgb.txt"); }).find("rgb.txt:9: duplicate time stamp"),
      std::string::npos);
}

// The caller decides how many frames may be skipped; past that next() stops
// (nullopt) and says why, instead of throwing.
TEST(TumSequence, SkipLimitIsTheCallersAndStopsTheStream) {
  const std::string dir = temp_dir("skiplimit");
  {
    dataset::TumSequenceWriter w(dir);
    for (int i = 0; i < 6; ++i) w.write(synthetic(i), geom::SE3d::Identity());
  }
  for (const char* f : {"/rgb/0.033333.png", "/rgb/0.066667.png", "/depth/0.100000.png"})
    std::remove((dir + f).c_str());
  dataset::TumSequenceReader loose(dir);
  loose.set_max_skipped(3);
  int n = 0;
  while (loose.next()) ++n;
  EXPECT_EQ(n, 3);
  EXPECT_FALSE(loose.skip_limit_reached());
  dataset::TumSequenceReader strict(dir);
  strict.set_max_skipped(1);
  n = 0;
  while (strict.next()) ++n;
  EXPECT_EQ(n, 1);  // frame 0; frames 1 and 2 are skipped, and 2 is one too many
  EXPECT_TRUE(strict.skip_limit_reached());
  EXPECT_EQ(strict.skipped(), 2u);
}
