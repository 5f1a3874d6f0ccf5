// Image files checked before decoding: a truncated or corrupt PNG or PNM is
// one IoError naming it, and nothing reaches stderr from the decoders.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/image_file.hpp"

using namespace pvb;

namespace {

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "pvb_img_" + std::to_string(::getpid()) + "_" + name;
}

cv::Mat texture(int rows, int cols, int type) {
  cv::Mat m(rows, cols, type);
  cv::RNG rng(7);
  rng.fill(m, cv::RNG::UNIFORM, 0, type == CV_16UC1 ? 60000 : 255);
  return m;
}

std::string encoded(const cv::Mat& m, const std::string& ext) {
  std::vector<uchar> buf;
  EXPECT_TRUE(cv::imencode(ext, m, buf));
  return std::string(buf.begin(), buf.end());
}

/// What read_image writes to stderr and its IoError message for `bytes`
/// stored as `name`.
struct Outcome {
  std::string error;  ///< IoError::what(), "" when it read the image
  std::string stderr_text;
};
Outcome read_bytes(const std::string& name, const std::string& bytes, int flags) {
  const std::string path = temp_path(name);
  write_file(path, bytes);
  Outcome out;
  ::testing::internal::CaptureStderr();
  try {
    dataset::read_image(path, flags, "colour image");
  } catch (const IoError& e) {
    out.error = e.what();
  }
  out.stderr_text = ::testing::internal::GetCapturedStderr();
  return out;
}

}  // namespace

TEST(ImageFile, WholeFilesReadAsImreadReadsThem) {
  const cv::Mat bgr = texture(48, 64, CV_8UC3), depth = texture(48, 64, CV_16UC1);
  for (const std::string ext : {".png", ".ppm"}) {
    const std::string path = temp_path("whole" + ext);
    write_file(path, encoded(bgr, ext));
    EXPECT_FALSE(dataset::image_damage(read_file(path)).has_value()) << ext;
    EXPECT_EQ(cv::norm(dataset::read_image(path, cv::IMREAD_COLOR), cv::imread(path, cv::IMREAD_COLOR),
                       cv::NORM_INF),
              0);
  }
  for (const std::string ext : {".png", ".pgm"}) {
    const std::string path = temp_path("depth" + ext);
    write_file(path, encoded(depth, ext));
    const cv::Mat d = dataset::read_image(path, cv::IMREAD_ANYDEPTH);
    ASSERT_EQ(d.type(), CV_16UC1) << ext;
    EXPECT_EQ(cv::norm(d, depth, cv::NORM_INF), 0) << ext;
  }
}

// Cut short anywhere, or with a flipped byte, a PNG is one error naming the
// file and no libpng line on stderr.
TEST(ImageFile, TruncatedOrCorruptPngIsOneErrorAndSilent) {
  const std::string png = encoded(texture(48, 64, CV_8UC3), ".png");
  for (const std::size_t keep :
       {png.size() - 1, png.size() - 12, png.size() / 2, std::size_t{40}, std::size_t{9}}) {
    const Outcome o = read_bytes("cut.png", png.substr(0, keep), cv::IMREAD_COLOR);
    EXPECT_NE(o.error.find("pvb_img_"), std::string::npos) << keep;
    EXPECT_NE(o.error.find("damaged colour image: truncated PNG"), std::string::npos)
        << keep << ": " << o.error;
    EXPECT_EQ(o.stderr_text, "") << keep;
  }
  std::string flipped = png;
  flipped[png.size() / 2] = static_cast<char>(flipped[png.size() / 2] ^ 0x10);
  const Outcome o = read_bytes("flip.png", flipped, cv::IMREAD_COLOR);
  EXPECT_NE(o.error.find("damaged colour image: corrupt PNG: chunk IDAT fails its CRC check"),
            std::string::npos)
      << o.error;
  EXPECT_EQ(o.stderr_text, "");
}

TEST(ImageFile, TruncatedPnmIsOneErrorAndSilent) {
  const std::string ppm = encoded(texture(48, 64, CV_8UC3), ".ppm");
  const std::string pgm16 = encoded(texture(48, 64, CV_16UC1), ".pgm");
  for (const auto& [name, bytes] :
       {std::pair{"cut.ppm", ppm.substr(0, ppm.size() - 1)},
        std::pair{"half.ppm", ppm.substr(0, ppm.size() / 2)}, std::pair{"head.ppm", ppm.substr(0, 6)},
        std::pair{"cut.pgm", pgm16.substr(0, pgm16.size() - 2)}}) {
    const Outcome o = read_bytes(name, bytes, cv::IMREAD_ANYDEPTH);
    EXPECT_NE(o.error.find("damaged colour image: truncated"), std::string::npos) << name << ": " << o.error;
    EXPECT_EQ(o.stderr_text, "") << name;
  }
  EXPECT_FALSE(dataset::image_damage("P3\n2 1\n255\n1 2 3 4 5 6\n").has_value());
  EXPECT_TRUE(dataset::image_damage("P3\n2 1\n255\n1 2 3 4 5\n").has_value());
}

TEST(ImageFile, MissingOrUndecodableFileIsOneError) {
  EXPECT_NE(
      read_bytes("text.png", "not a PNG", cv::IMREAD_COLOR).error.find("missing or unreadable colour image"),
      std::string::npos);
  try {
    dataset::read_image(temp_path("absent.png"), cv::IMREAD_COLOR, "depth image");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("absent.png: missing or unreadable depth image"), std::string::npos);
  }
}
