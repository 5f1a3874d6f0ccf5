#pragma once
// Little-endian byte writing and bounds-checked reading for map files.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pvb/common/error.hpp"
#include "pvb/slam/core/map_file.hpp"

namespace pvb::slam::mapfile {

constexpr char kMagic[] = "PVBMAP\r\n";  // 8 bytes, without the NUL
constexpr std::size_t kMagicBytes = 8;
constexpr std::uint64_t kNone = ~std::uint64_t(0);  ///< no keyframe, no point
/// The sections of a version-1 file, in order.
constexpr std::array<const char*, 6> kSectionsV1 = {"HEAD", "KEYF", "POIN", "GRAP", "BOWV", "META"};
/// The sections of a version-2 file: INER (the inertial state) before META.
constexpr std::array<const char*, 7> kSectionsV2 = {"HEAD", "KEYF", "POIN", "GRAP", "BOWV", "INER", "META"};
constexpr std::size_t kInerSection = 5;  ///< INER's place in a version-2 or -3 file
/// The sections of a version-3 file: WHEL (the wheels' calibration) after INER.
constexpr std::array<const char*, 8> kSectionsV3 = {"HEAD", "KEYF", "POIN", "GRAP",
                                                    "BOWV", "INER", "WHEL", "META"};
constexpr std::size_t kWhelSection = 6;  ///< WHEL's place in a version-3 file
/// A position the file may hold: within kMaxMapCoordinateM of the origin on
/// every axis (and so finite).  The writer leaves out a point outside it;
/// the reader refuses one.
inline bool within_map_bounds(const Eigen::Vector3d& p) {
  return p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxMapCoordinateM;
}
/// The sections of a file of `version` (1 to 3), in order.
inline std::vector<const char*> section_tags(std::uint32_t version) {
  if (version == 1) return {kSectionsV1.begin(), kSectionsV1.end()};
  if (version == 2) return {kSectionsV2.begin(), kSectionsV2.end()};
  return {kSectionsV3.begin(), kSectionsV3.end()};
}
/// What WHEL may hold: a described radius and track within 0-10 m, each
/// factor within 0.5-2 (a wheel half or twice its described size is not
/// the robot described), finite sums and amounts rolled and turned.
constexpr double kMaxWheelDescriptionM = 10, kMinWheelScale = 0.5, kMaxWheelScale = 2;
inline bool wheel_scale_in_range(double s) { return s >= kMinWheelScale && s <= kMaxWheelScale; }
/// Bytes of one keypoint in KEYF: 7 f32, the octave, depth, point id, descriptor.
constexpr std::size_t kKeypointBytes = 7 * 4 + 1 + 4 + 8 + 32;
/// Bytes of a keyframe in KEYF before its keypoints: id, frame id, time,
/// session, pose (12 f64), keypoint count.
constexpr std::size_t kKeyframeHeadBytes = 8 + 8 + 8 + 4 + 96 + 4;
constexpr std::uint32_t kMaxKeypoints = 100000;
/// Bytes before a section's payload (tag, length) and after it (checksum).
constexpr std::uint64_t kSectionHeadBytes = 12, kSectionTailBytes = 8;
/// Keyframe and point ids lie below 2^48: a run that made a keyframe every
/// frame at 30 Hz would take 297 000 years to reach it, and the ids a
/// session goes on to give never reach the "none" marker (all ones).
constexpr std::uint64_t kMaxId = std::uint64_t(1) << 48;
/// A point's times predicted visible (and found) are at most 2^30: a year
/// of frames at 30 Hz is 0.88 * 2^30.  Counting on from there cannot
/// overflow an int.
constexpr std::int32_t kMaxVisible = std::int32_t(1) << 30;

/// A sensor setup's code in INER (fixed, whatever the enum's order).
inline std::uint32_t sensor_code(sensor::SensorSetup s) {
  switch (s) {
    case sensor::SensorSetup::kCamera:
      return 0;
    case sensor::SensorSetup::kCameraImu:
      return 1;
    case sensor::SensorSetup::kCameraImuWheels:
      return 2;
    case sensor::SensorSetup::kCameraAccel:
      return 3;
  }
  return 0;
}
inline std::optional<sensor::SensorSetup> sensor_of_code(std::uint32_t code) {
  for (sensor::SensorSetup s : sensor::kSensorSetups)
    if (sensor_code(s) == code) return s;
  return std::nullopt;
}

/// What INER may hold (the reader refuses the rest; the writer leaves it out).
inline bool gravity_in_range(const Eigen::Vector3d& g_w) {
  return g_w.allFinite() && g_w.norm() >= kMinGravityMps2 && g_w.norm() <= kMaxGravityMps2;
}
inline bool bias_in_range(const ImuBias& b) {
  return b.gyro_radps.allFinite() && b.accel_mps2.allFinite() && b.gyro_radps.norm() <= kMaxGyroBiasRadps &&
         b.accel_mps2.norm() <= kMaxAccelBiasMps2;
}
inline bool speed_in_range(const Eigen::Vector3d& v_w) {
  return v_w.allFinite() && v_w.norm() <= kMaxSpeedMps;
}
/// Finite, a rotation (orthonormal within 1e-6, determinant +1) and a
/// translation within kMaxExtrinsicM.
inline bool rigid_in_range(const geom::SE3d& T) {
  const Eigen::Matrix3d R = T.linear();
  return T.matrix().allFinite() &&
         (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-6 &&
         R.determinant() > 0 && T.translation().norm() <= kMaxExtrinsicM;
}

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
  void clear() { data_.clear(); }
  const std::string& data() const { return data_; }

 private:
  void le(std::uint64_t v, int n) {
    char b[8];  // one append of n bytes (a loop of push_back was most of a save)
    for (int i = 0; i < n; ++i) b[i] = static_cast<char>((v >> (8 * i)) & 0xff);
    data_.append(b, static_cast<std::size_t>(n));
  }
  std::string data_;
};

/// Reads a byte range of one section; running past its end throws IoError
/// naming the file, the section and the offset (a truncated or damaged
/// file).  Offsets are 64-bit: a map file may be larger than 2 GiB.  The
/// range is in memory, or read from the file a piece at a time.
class ByteReader {
 public:
  /// `p`, `n`: the range of the part named `label` ("KEYF section", "file
  /// header"); the range begins at byte `section_offset` of that part
  /// (counted from a section's tag: 12 for a payload) and `file_offset` of
  /// the file.
  ByteReader(const char* p, std::uint64_t n, std::string file, std::string label,
             std::uint64_t section_offset, std::uint64_t file_offset)
      : p_(p),
        n_(n),
        file_(std::move(file)),
        label_(std::move(label)),
        section_base_(section_offset),
        file_base_(file_offset) {}
  /// The `n` bytes at `file_offset` of `src` (which outlives the reader):
  /// in place when they are in memory, else read as needed.
  ByteReader(const MapFileBytes& src, std::uint64_t file_offset, std::uint64_t n, std::string label,
             std::uint64_t section_offset)
      : ByteReader(src.data() ? src.data() + file_offset : nullptr, n, src.name(), std::move(label), section_offset,
                   file_offset) {
    if (!p_) src_ = &src;
  }

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
  /// The next `n` bytes, valid until the next call.
  const char* bytes(std::uint64_t n) {
    const char* p = at(n);
    pos_ += n;
    return p;
  }
  std::uint64_t remaining() const { return n_ - pos_; }
  bool at_end() const { return pos_ == n_; }
  /// Throws IoError "FILE: LABEL at byte N (file byte M): what", N counted
  /// from the section's tag.
  [[noreturn]] void fail(const std::string& what) const {
    throw IoError(file_, where(label_, section_base_ + pos_, file_base_ + pos_) + what);
  }
  /// "KEYF section at byte N (file byte M): ", as every error inside a
  /// section begins ("file header at byte N: " where the two are one).
  static std::string where(const std::string& label, std::uint64_t section_offset,
                           std::uint64_t file_offset) {
    return label + " at byte " + std::to_string(section_offset) +
           (section_offset == file_offset ? std::string()
                                          : " (file byte " + std::to_string(file_offset) + ")") +
           ": ";
  }
  /// A count of items of at least `min_bytes` each that the rest can hold.
  std::uint64_t count(std::uint64_t min_bytes, const char* what) {
    const std::uint64_t n = u64();
    if (min_bytes > 0 && n > remaining() / min_bytes)
      fail(std::to_string(n) + " " + what + " cannot fit in the " + std::to_string(remaining()) + " bytes left");
    return n;
  }

 private:
  void need(std::uint64_t n) const {
    if (n > n_ - pos_) fail("ends early (needs " + std::to_string(n) + " more bytes)");
  }
  /// `n` bytes at pos_ (checked against the range), without moving on.
  const char* at(std::uint64_t n) {
    need(n);
    if (p_) return p_ + pos_;
    if (pos_ < piece_at_ || pos_ + n > piece_at_ + piece_.size()) {
      piece_.resize(static_cast<std::size_t>(std::min(std::max(n, src_->piece_bytes()), n_ - pos_)));
      src_->read(file_base_ + pos_, piece_.data(), piece_.size());
      piece_at_ = pos_;
    }
    return piece_.data() + (pos_ - piece_at_);
  }
  std::uint64_t le(int n) {
    const auto* q = reinterpret_cast<const unsigned char*>(at(static_cast<std::uint64_t>(n)));
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= std::uint64_t(q[i]) << (8 * i);
    pos_ += static_cast<std::uint64_t>(n);
    return v;
  }
  const char* p_;
  std::uint64_t n_;
  std::uint64_t pos_ = 0;
  std::string file_, label_;
  std::uint64_t section_base_, file_base_;
  const MapFileBytes* src_ = nullptr;  ///< where the bytes are read from when not in memory
  std::string piece_;                   ///< the piece read last, from pos piece_at_
  std::uint64_t piece_at_ = 0;
};

}  // namespace pvb::slam::mapfile
