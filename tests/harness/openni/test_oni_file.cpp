// The .oni record scanner on files written byte by byte to the OpenNI2 2.2
// layout (file header, then records with a 28-byte header).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/openni/oni_file.hpp"

using namespace pvb::openni;

namespace {

struct Bytes {
  std::vector<unsigned char> b;
  void u8(std::uint8_t v) { b.push_back(v); }
  void u16(std::uint16_t v) {
    for (int i = 0; i < 2; ++i) b.push_back(static_cast<unsigned char>(v >> (8 * i)));
  }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<unsigned char>(v >> (8 * i)));
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) b.push_back(static_cast<unsigned char>(v >> (8 * i)));
  }
  void str(const std::string& s) { b.insert(b.end(), s.begin(), s.end()); }
};

void file_header(Bytes& f) {
  f.str("NI10");
  f.u8(1);
  f.u8(0);
  f.u16(1);
  f.u32(0);
  f.u64(~0ull);
  f.u32(2);
}

// A record: header (fields size includes it) + fields + payload.
void record(Bytes& f, std::uint32_t type, std::uint32_t node, const Bytes& fields, std::size_t payload) {
  f.u32(0x0052494E);
  f.u32(type);
  f.u32(node);
  f.u32(static_cast<std::uint32_t>(28 + fields.b.size()));
  f.u32(static_cast<std::uint32_t>(payload));
  f.u64(0);
  f.b.insert(f.b.end(), fields.b.begin(), fields.b.end());
  f.b.insert(f.b.end(), payload, 0xAB);
}

void node_added(Bytes& f, std::uint32_t node, std::uint32_t node_type, const std::string& name) {
  Bytes fl;
  fl.u32(static_cast<std::uint32_t>(name.size() + 1));
  fl.str(name);
  fl.u8(0);
  fl.u32(node_type);
  fl.u32(0x454E4F4E);  // codec
  fl.u32(3);
  fl.u64(0);
  fl.u64(100);
  fl.u64(0);
  record(f, 0x0D, node, fl, 0);
}

void new_data(Bytes& f, std::uint32_t node, std::uint32_t frame, std::size_t bytes) {
  Bytes fl;
  fl.u64(frame * 33333ull);
  fl.u32(frame);
  record(f, 0x0A, node, fl, bytes);
}

Bytes recording(int frames, bool with_end) {
  Bytes f;
  file_header(f);
  node_added(f, 1, kOniNodeDepth, "Depth");
  node_added(f, 2, kOniNodeImage, "Image");
  Bytes begin;
  begin.u32(~0u);
  begin.u64(~0ull);
  record(f, 0x09, 1, Bytes{}, 0);
  record(f, 0x08, 1, begin, 0);
  record(f, 0x09, 2, Bytes{}, 0);
  record(f, 0x08, 2, begin, 0);
  for (int i = 1; i <= frames; ++i) {
    new_data(f, 1, static_cast<std::uint32_t>(i), 600);
    new_data(f, 2, static_cast<std::uint32_t>(i), 900);
  }
  if (with_end) record(f, 0x0B, 0, Bytes{}, 0);
  return f;
}

std::string write(const Bytes& f, const std::string& name, std::size_t keep = SIZE_MAX) {
  const std::string path =
      ::testing::TempDir() + "pvb_oni_" + name + "_" + std::to_string(::getpid()) + ".oni";
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(f.b.data()),
            static_cast<std::streamsize>(std::min(keep, f.b.size())));
  return path;
}

}  // namespace

TEST(OniFile, CountsFramesPerStream) {
  const std::string path = write(recording(5, true), "whole");
  const OniFileSummary s = scan_oni_file(path);
  EXPECT_EQ(s.frames_of(kOniNodeDepth), 5u);
  EXPECT_EQ(s.frames_of(kOniNodeImage), 5u);
  EXPECT_EQ(s.nodes_begun(), 2u);
  EXPECT_TRUE(s.has_end);
  EXPECT_EQ(s.broken_at, 0u);
  EXPECT_EQ(s.end_bytes, s.size_bytes);
  EXPECT_NO_THROW(check_oni_complete(path, s));
}

TEST(OniFile, ZerosAfterTheEndRecordAreNotRecords) {
  Bytes f = recording(3, true);
  const std::size_t end = f.b.size();
  f.b.resize(2 * end, 0);  // what Debian's recorder leaves behind
  const OniFileSummary s = scan_oni_file(write(f, "padded"));
  EXPECT_TRUE(s.has_end);
  EXPECT_EQ(s.end_bytes, end);
  EXPECT_EQ(s.size_bytes, 2 * end);
  EXPECT_EQ(s.frames_of(kOniNodeImage), 3u);
}

TEST(OniFile, TruncatedFileIsReportedWithTheBrokenRecord) {
  const Bytes full = recording(5, true);
  const std::string path = write(full, "cut", full.b.size() - 1000);
  const OniFileSummary s = scan_oni_file(path);
  EXPECT_GT(s.broken_at, 0u);
  EXPECT_FALSE(s.has_end);
  EXPECT_LT(s.frames_of(kOniNodeImage), 5u);
  try {
    check_oni_complete(path, s);
    FAIL() << "a truncated file passed";
  } catch (const pvb::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(OniFile, MissingEndRecordMeansIncomplete) {
  const std::string path = write(recording(2, false), "noend");
  const OniFileSummary s = scan_oni_file(path);
  EXPECT_EQ(s.broken_at, 0u);
  EXPECT_FALSE(s.has_end);
  EXPECT_THROW(check_oni_complete(path, s), pvb::IoError);
}

TEST(OniFile, RecorderThatHasNotStartedShowsNoDataBegin) {
  Bytes f;
  file_header(f);
  node_added(f, 1, kOniNodeDepth, "Depth");
  const OniFileSummary s = scan_oni_file(write(f, "early"));
  EXPECT_EQ(s.nodes_begun(), 0u);
  EXPECT_EQ(s.nodes.size(), 1u);
}

TEST(OniFile, RejectsOtherFiles) {
  Bytes f;
  f.str("PNG\r\n and more bytes than a header needs");
  EXPECT_THROW(scan_oni_file(write(f, "png")), pvb::IoError);
  EXPECT_THROW(scan_oni_file("/nonexistent/x.oni"), pvb::IoError);
}
