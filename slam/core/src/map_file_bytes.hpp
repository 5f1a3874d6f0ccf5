#pragma once
// Little-endian byte writing and bounds-checked reading for map files.
#include <array>
#include <cstdint>
#include <cstring>
#include <string>

#include "pvb/common/error.hpp"

namespace pvb::slam::mapfile {

constexpr char kMagic[] = "PVBMAP\r\n";  // 8 bytes, without the NUL
constexpr std::size_t kMagicBytes = 8;
constexpr std::uint64_t kNone = ~std::uint64_t(0);  ///< no keyframe, no point
constexpr std::array<const char*, 6> kSections = {"HEAD", "KEYF", "POIN", "GRAP", "BOWV", "META"};
/// Bytes of one keypoint in KEYF: 7 f32, the octave, depth, point id, descriptor.
constexpr std::size_t kKeypointBytes = 7 * 4 + 1 + 4 + 8 + 32;
/// Bytes of a keyframe in KEYF before its keypoints: id, frame id, time,
/// session, pose (12 f64), keypoint count.
constexpr std::size_t kKeyframeHeadBytes = 8 + 8 + 8 + 4 + 96 + 4;
constexpr std::uint32_t kMaxKeypoints = 100000;

class ByteWriter {
 public:
  void u8(std::uint8_t v) { data_.push_back(static_cast<char>(v)); }
  void u32(std::uint32_t v) { le(v, 4); }
  void i32(std::int32_t v) { le(static_cast<std::uint32_t>(v), 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void i64(std::int64_t v) { le(static_cast<std::uint64_t>(v), 8); }
  void f32(float v) {
    std::uint32_t b;
    std::memcpy(&b, &v, 4);
    le(b, 4);
  }
  void f64(double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, 8);
    le(b, 8);
  }
  void bytes(const void* p, std::size_t n) { data_.append(static_cast<const char*>(p), n); }
  void reserve(std::size_t n) { data_.reserve(n); }
  const std::string& data() const { return data_; }

 private:
  void le(std::uint64_t v, int n) {
    char b[8];  // one append of n bytes (a loop of push_back was most of a save)
    for (int i = 0; i < n; ++i) b[i] = static_cast<char>((v >> (8 * i)) & 0xff);
    data_.append(b, static_cast<std::size_t>(n));
  }
  std::string data_;
};

/// Reads a byte range; running past its end throws IoError naming the
/// file, the section and the offset (a truncated or damaged file).
class ByteReader {
 public:
  ByteReader(const char* p, std::size_t n, std::string file, std::string section, std::size_t base_offset)
      : p_(p), n_(n), file_(std::move(file)), section_(std::move(section)), base_(base_offset) {}

  std::uint8_t u8() { return static_cast<std::uint8_t>(le(1)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(le(4)); }
  std::int32_t i32() { return static_cast<std::int32_t>(static_cast<std::uint32_t>(le(4))); }
  std::uint64_t u64() { return le(8); }
  std::int64_t i64() { return static_cast<std::int64_t>(le(8)); }
  float f32() {
    const auto b = static_cast<std::uint32_t>(le(4));
    float v;
    std::memcpy(&v, &b, 4);
    return v;
  }
  double f64() {
    const std::uint64_t b = le(8);
    double v;
    std::memcpy(&v, &b, 8);
    return v;
  }
  const char* bytes(std::size_t n) {
    need(n);
    const char* p = p_ + pos_;
    pos_ += n;
    return p;
  }
  std::size_t remaining() const { return n_ - pos_; }
  bool at_end() const { return pos_ == n_; }
  /// Throws IoError "FILE: SECTION section at byte OFFSET: what".
  [[noreturn]] void fail(const std::string& what) const {
    throw IoError(file_, section_ + " section at byte " + std::to_string(base_ + pos_) + ": " + what);
  }
  /// A count of items of at least `min_bytes` each that the rest can hold.
  std::uint64_t count(std::size_t min_bytes, const char* what) {
    const std::uint64_t n = u64();
    if (min_bytes > 0 && n > remaining() / min_bytes)
      fail(std::to_string(n) + " " + what + " cannot fit in the " + std::to_string(remaining()) + " bytes left");
    return n;
  }

 private:
  void need(std::size_t n) const {
    if (n > n_ - pos_) fail("ends early (needs " + std::to_string(n) + " more bytes)");
  }
  std::uint64_t le(int n) {
    need(static_cast<std::size_t>(n));
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= std::uint64_t(static_cast<unsigned char>(p_[pos_ + i])) << (8 * i);
    pos_ += n;
    return v;
  }
  const char* p_;
  std::size_t n_;
  std::size_t pos_ = 0;
  std::string file_, section_;
  std::size_t base_;
};

}  // namespace pvb::slam::mapfile
