// PLY round trip: write, then parse header and body independently (byte
// level) and with read_ply; malformed files give an IoError naming the line.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "file_size_limit.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/slam/dense/ply.hpp"

namespace {

using pvb::slam::dense::CloudPoint;
using pvb::slam::dense::PointCloud;

std::string temp(const std::string& name) {
  return ::testing::TempDir() + "pvb_ply_" + name + "_" + std::to_string(::getpid()) + ".ply";
}

PointCloud sample() {
  return {{1.5f, -2.25f, 3.0f, 255, 0, 7}, {-0.001f, 1e6f, 0.0f, 1, 2, 3}, {0.1f, 0.2f, 0.3f, 128, 64, 32}};
}

TEST(Ply, HeaderAndBodyAreBinaryLittleEndian) {
  const std::string path = temp("layout");
  pvb::slam::dense::write_ply(path, sample());
  const std::string bytes = pvb::read_file(path);
  const std::size_t end = bytes.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  std::istringstream header(bytes.substr(0, end));
  std::vector<std::string> lines;
  for (std::string l; std::getline(header, l);)
    if (l.rfind("comment", 0) != 0) lines.push_back(l);
  const std::vector<std::string> expect = {"ply",
                                           "format binary_little_endian 1.0",
                                           "element vertex 3",
                                           "property float x",
                                           "property float y",
                                           "property float z",
                                           "property uchar red",
                                           "property uchar green",
                                           "property uchar blue"};
  EXPECT_EQ(lines, expect);
  const std::string body = bytes.substr(end + std::strlen("end_header\n"));
  ASSERT_EQ(body.size(), 3u * 15u);
  // first vertex: x = 1.5f = 0x3FC00000, little endian: 00 00 C0 3F
  EXPECT_EQ(static_cast<unsigned char>(body[0]), 0x00);
  EXPECT_EQ(static_cast<unsigned char>(body[2]), 0xC0);
  EXPECT_EQ(static_cast<unsigned char>(body[3]), 0x3F);
  EXPECT_EQ(static_cast<unsigned char>(body[12]), 255);
  EXPECT_EQ(static_cast<unsigned char>(body[13]), 0);
  EXPECT_EQ(static_cast<unsigned char>(body[14]), 7);
  std::remove(path.c_str());
}

TEST(Ply, RoundTripIsExact) {
  const std::string path = temp("round");
  const PointCloud in = sample();
  pvb::slam::dense::write_ply(path, in);
  const PointCloud out = pvb::slam::dense::read_ply(path);
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(out[i].x, in[i].x);
    EXPECT_EQ(out[i].y, in[i].y);
    EXPECT_EQ(out[i].z, in[i].z);
    EXPECT_EQ(out[i].r, in[i].r);
    EXPECT_EQ(out[i].g, in[i].g);
    EXPECT_EQ(out[i].b, in[i].b);
  }
  pvb::slam::dense::write_ply(path, {});
  EXPECT_TRUE(pvb::slam::dense::read_ply(path).empty());
  std::remove(path.c_str());
}

TEST(Ply, MalformedFilesAreClearErrors) {
  const std::string path = temp("bad");
  pvb::slam::dense::write_ply(path, sample());
  const std::string good = pvb::read_file(path);
  pvb::write_file(path, good.substr(0, good.size() - 5));  // body cut short
  try {
    pvb::slam::dense::read_ply(path);
    FAIL() << "truncated body accepted";
  } catch (const pvb::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  std::string ascii = good;
  ascii.replace(ascii.find("binary_little_endian"), 20, "ascii");
  pvb::write_file(path, ascii);
  try {
    pvb::slam::dense::read_ply(path);
    FAIL() << "ascii accepted";
  } catch (const pvb::IoError& e) {
    EXPECT_EQ(e.line(), 2) << e.what();
  }
  EXPECT_THROW(pvb::slam::dense::write_ply("/nonexistent-dir/x.ply", sample()), pvb::IoError);
  std::remove(path.c_str());
}

}  // namespace

// A full disk while the body is written: an error naming the PLY, and no
// file whose header announces vertices its body lacks (the old map stays).
TEST(Ply, FullDiskLeavesNoTruncatedPly) {
  const std::string path = temp("full");
  pvb::slam::dense::write_ply(path, sample());
  const std::string old_bytes = pvb::read_file(path);
  PointCloud big(100000, CloudPoint{1.0f, 2.0f, 3.0f, 4, 5, 6});
  std::string err = "(no error)";
  {
    const pvb::test::FileSizeLimit limit(64 * 1024);
    try {
      pvb::slam::dense::write_ply(path, big);
    } catch (const pvb::IoError& e) {
      err = e.what();
    }
  }
  EXPECT_EQ(err, path + ": write failed: File too large");
  EXPECT_EQ(pvb::read_file(path), old_bytes);
  EXPECT_FALSE(std::ifstream(path + ".tmp").good());
  std::remove(path.c_str());
}
