// The image codecs behind their plug-in module give OpenCV's bytes and
// pixels, and pvbench does not link OpenCV's codecs (about 140 shared
// libraries at every start): the module is loaded by the first image call.
#include "pvb/sensor/image_codec.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

using namespace pvb;

namespace {

cv::Mat test_image() {
  cv::Mat m(48, 64, CV_8UC3);
  cv::randu(m, 0, 255);
  return m;
}

/// What `ldd` lists for a program (its shared libraries, transitively).
std::string ldd(const std::string& path) {
  std::unique_ptr<FILE, int (*)(FILE*)> p(popen(("ldd " + path + " 2>&1").c_str(), "r"), &pclose);
  std::string out;
  char buf[4096];
  while (p && std::fgets(buf, sizeof buf, p.get())) out += buf;
  return out;
}

}  // namespace

TEST(ImageCodec, EncodesAndDecodesAsOpenCvDoes) {
  const cv::Mat img = test_image();
  for (const int level : {1, 6}) {
    std::vector<unsigned char> ours, theirs;
    ASSERT_TRUE(sensor::imencode(".png", img, &ours, {cv::IMWRITE_PNG_COMPRESSION, level}));
    ASSERT_TRUE(cv::imencode(".png", img, theirs, {cv::IMWRITE_PNG_COMPRESSION, level}));
    EXPECT_EQ(ours, theirs) << "level " << level;
  }
  std::vector<unsigned char> png;
  ASSERT_TRUE(cv::imencode(".png", img, png));
  const cv::Mat back = sensor::imdecode(cv::Mat(1, static_cast<int>(png.size()), CV_8U, png.data()), cv::IMREAD_COLOR);
  EXPECT_EQ(cv::norm(back, img, cv::NORM_INF), 0.0);
  // A 16-bit depth image through a file, both ways.
  cv::Mat depth(30, 40, CV_16UC1);
  cv::randu(depth, 0, 65535);
  const std::string path = ::testing::TempDir() + "pvb_image_codec_depth.png";
  ASSERT_TRUE(sensor::imwrite(path, depth));
  const cv::Mat read = sensor::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(read.type(), CV_16UC1);
  EXPECT_EQ(cv::norm(read, depth, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(cv::imread(path, cv::IMREAD_UNCHANGED), depth, cv::NORM_INF), 0.0);
  std::filesystem::remove(path);
  // OpenCV's own refusal passes through.
  std::vector<unsigned char> none;
  EXPECT_THROW(sensor::imencode(".nosuchformat", img, &none), cv::Exception);
}

TEST(ImageCodec, PvbenchDoesNotLinkOpenCvsCodecs) {
  const std::string pvbench = std::string(PVB_BINARY_DIR) + "/bin/pvbench";
  if (!std::filesystem::exists(pvbench)) GTEST_SKIP() << "no " << pvbench;
  const std::string libs = ldd(pvbench);
  ASSERT_NE(libs.find("libopencv_core"), std::string::npos) << libs;
  EXPECT_EQ(libs.find("libopencv_imgcodecs"), std::string::npos) << libs;
  EXPECT_EQ(libs.find("libgdal"), std::string::npos) << libs;
}
