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
