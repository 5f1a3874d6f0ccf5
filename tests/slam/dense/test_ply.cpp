// PLY round trip: write, then parse header and body independently (byte
// level) and with read_ply; malformed files give an IoError naming the line.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
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
  std::remove(path.c_str());
}

namespace {

std::string ply_error(const std::string& path) {
  try {
    pvb::slam::dense::read_ply(path);
  } catch (const pvb::IoError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string with_count(const std::string& good, const std::string& count) {
  std::string s = good;
  s.replace(s.find("element vertex 3"), 16, "element vertex " + count);
  return s;
}

}  // namespace

// A header's vertex count is checked against the bytes present before
// anything is allocated, and must match them exactly.
TEST(Ply, VertexCountMustMatchTheBody) {
  const std::string path = temp("count");
  pvb::slam::dense::write_ply(path, sample());
  const std::string good = pvb::read_file(path);
  pvb::write_file(path, with_count(good, "4294967295"));
  EXPECT_NE(ply_error(path).find("body truncated: 4294967295 vertices announced"), std::string::npos)
      << ply_error(path);
  pvb::write_file(path, with_count(good, "1000000000000000000"));
  EXPECT_NE(ply_error(path).find("body truncated"), std::string::npos) << ply_error(path);
  for (const char* bad : {"lots", "1e18", "-3", "3 4", "99999999999999999999"}) {
    pvb::write_file(path, with_count(good, bad));
    EXPECT_NE(ply_error(path).find("expected one 'element vertex N' with N a whole number"), std::string::npos)
        << bad << ": " << ply_error(path);
  }
  pvb::write_file(path, with_count(good, "2"));  // fewer than the body holds
  EXPECT_NE(ply_error(path).find("2 vertices announced, but the body holds 15 bytes more"), std::string::npos)
      << ply_error(path);
  std::remove(path.c_str());
}

TEST(Ply, NonFiniteVerticesAreDroppedAndCounted) {
  const std::string path = temp("nan");
  PointCloud in = sample();
  in[1].y = std::numeric_limits<float>::quiet_NaN();
  in[2].z = std::numeric_limits<float>::infinity();
  pvb::slam::dense::write_ply(path, in);
  pvb::slam::dense::PlyReadStats stats;
  const PointCloud out = pvb::slam::dense::read_ply(path, &stats);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].x, in[0].x);
  EXPECT_EQ(stats.non_finite_dropped, 2u);
  std::remove(path.c_str());
}

TEST(Ply, OnlyRegularFilesAreRead) {
  const std::string dir = temp("dir");
  std::filesystem::create_directories(dir);
  EXPECT_EQ(ply_error(dir), dir + ": is a folder; expected a regular file");
  std::filesystem::remove_all(dir);
  const std::string fifo = temp("fifo");
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(ply_error(fifo), fifo + ": is a FIFO; expected a regular file");  // and no hang
  std::filesystem::remove(fifo);
}

TEST(Ply, BinaryBytesInTheHeaderAreEscapedInTheError) {
  const std::string path = temp("binary");
  pvb::write_file(path, std::string("ply\nform\x01\xff\x1b[2J\n"));
  EXPECT_EQ(ply_error(path), path + ":2: expected 'format binary_little_endian 1.0', got 'form\\x01\\xff\\x1b[2J'");
  std::remove(path.c_str());
}
