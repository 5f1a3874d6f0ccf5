#pragma once
// Map files: a sparse map saved to disk and read back (docs/map_file.md).
// A versioned binary format: the magic "PVBMAP\r\n", a version, then
// sections (HEAD settings, KEYF keyframes, POIN points, GRAP graph, BOWV
// bags of words, META the application's JSON), each with its length and an
// FNV-1a checksum.  A map with a trusted inertial state (MapGravity::ready)
// is written as version 2, with an INER section (gravity, the IMU's
// extrinsics, the keyframes' velocities, biases and chain in time) before
// META; any other as version 1.  Both versions are read.
// What is saved is the map's own state (poses, keypoints, descriptors,
// point positions and statistics, the graph); what follows from it (point
// descriptors, normals, scale ranges) is recomputed on load, so save ->
// load -> save gives the same bytes.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "pvb/slam/core/map.hpp"
#include "pvb/slam/core/map_settings.hpp"
#include "pvb/slam/core/settings.hpp"

namespace pvb::slam {

/// The file's header and application data, without the map itself.
struct MapFileHeader {
  std::uint32_t version = 0;   ///< 1 (no inertial state), 2 (INER) or 3 (INER and WHEL)
  MapSettings settings;        ///< from HEAD, and the sensors from INER
  std::uint32_t sessions = 0;  ///< mapping sessions the map holds
  std::string app_json;        ///< the META section (the caller's JSON, "" when none)
  /// Where each section's payload lies in the file (offset, length), in
  /// file order; checked by read_map_header, used by decode_map.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> sections;
};

/// The newest version written and read; a map without inertial state is
/// still written as version 1 (kMapFileVersionVisual), byte for byte as
/// before version 2 existed.
constexpr std::uint32_t kMapFileVersion = 3;
/// A map with inertial state but no wheel calibration is version 2.
constexpr std::uint32_t kMapFileVersionInertial = 2;
constexpr std::uint32_t kMapFileVersionVisual = 1;
/// The largest map file read: 4 GiB, about 30 000 keyframes (a
/// 709-keyframe lawnmower map is 103 MB).  Loading one reads it a piece
/// at a time (MapFileBytes::open); saving writes it so (encode_map to a sink).
constexpr std::uint64_t kMaxMapFileBytes = std::uint64_t(4) << 30;
/// Every keyframe's camera centre and every point lies within this many
/// metres of the map's origin on each axis, and no keypoint's depth is
/// larger: 1000 km, far beyond any station.
constexpr double kMaxMapCoordinateM = 1e6;
/// Extrinsics (T_b_c, T_base_c) of a map and a run that both use them
/// agree when they differ by at most 1 mm and 0.1 degrees.
constexpr double kMaxExtrinsicShiftM = 1e-3, kMaxExtrinsicTurnDeg = 0.1;
/// What INER may hold: gravity's magnitude within 9.0-10.6 m/s^2 (the
/// Earth's is 9.78-9.83); extrinsic translations within 10 m (as the
/// settings); a keyframe's speed up to 100 m/s, its gyro bias up to
/// 1 rad/s and accelerometer bias up to 5 m/s^2 (norms: far beyond any
/// MEMS IMU's).  The writer leaves out what lies beyond (docs/map_file.md).
constexpr double kMinGravityMps2 = 9.0, kMaxGravityMps2 = 10.6;
constexpr double kMaxExtrinsicM = 10;
constexpr double kMaxSpeedMps = 100, kMaxGyroBiasRadps = 1, kMaxAccelBiasMps2 = 5;

/// A map file's bytes, wherever they are: in memory, or in the file and
/// read a piece at a time as the reader goes (loading a map then holds the
/// map, not the map and its file).  Copies share the open file.
class MapFileBytes {
 public:
  /// The file at `path`, once it is a regular file no larger than
  /// kMaxMapFileBytes; nothing else is read yet.  Readers take
  /// `piece_bytes` at a time (at least what one value needs).  Throws
  /// IoError naming `path`.
  static MapFileBytes open(const std::string& path, std::uint64_t piece_bytes = std::uint64_t(1) << 20);
  /// Bytes in memory, named `name` in errors; `bytes` must outlive this.
  static MapFileBytes in_memory(const std::string& bytes, std::string name);

  std::uint64_t size() const { return size_; }
  const std::string& name() const { return name_; }
  /// The bytes when they are in memory, else null.
  const char* data() const { return data_; }
  std::uint64_t piece_bytes() const { return piece_bytes_; }
  /// Copies `n` bytes from `offset` (within size()) into `out`; throws
  /// IoError naming the file when they cannot be read.
  void read(std::uint64_t offset, char* out, std::uint64_t n) const;

 private:
  struct File;
  std::string name_;
  std::uint64_t size_ = 0;
  std::uint64_t piece_bytes_ = 0;
  const char* data_ = nullptr;
  std::shared_ptr<File> file_;
};

/// Reads a map file whole, once its size and framing allow: a file larger
/// than kMaxMapFileBytes, or whose sections' lengths (read from their
/// heads, without reading the payloads) do not add up to its size, is
/// refused before its bytes are read.  Throws IoError naming `path`.
/// (System::load_map reads through MapFileBytes::open instead.)
std::string read_map_file(const std::string& path);

/// A keyframe's bag of words, wherever it is kept (a keyframe in the place
/// database has handed its own to the database: PlaceRecognizer::bag_of).
using BagOf = std::function<place::BowVector(const KeyFrame&)>;

/// Where encode_map puts the file's bytes: `append` takes the next ones in
/// order; `patch` overwrites bytes already appended (a section's length,
/// known once its payload is written).
struct MapByteSink {
  std::function<void(const char* data, std::size_t n)> append;
  std::function<void(std::uint64_t offset, const char* data, std::size_t n)> patch;
};

/// The map file's bytes for every keyframe and point in `map` (bad ones
/// are not in it, nor a provisional map that was never merged: it lies in
/// a frame of its own); bags of words from `bag_of`, or each keyframe's own
/// when it is empty.  Version 2 with INER when the map's gravity is ready
/// (within kMinGravityMps2..kMaxGravityMps2) and `settings.sensors` uses
/// an accelerometer, else version 1.  The keyframes of the session now
/// running (map.session()) are saved with `session_offset_ns` added to
/// their stamps (System::session_clock_offset_ns()).  Call with the map's
/// mutex held.
std::string encode_map(const Map& map, const MapSettings& settings, std::uint32_t sessions,
                       const std::string& app_json, const BagOf& bag_of = nullptr,
                       std::int64_t session_offset_ns = 0);
/// The same bytes handed to `sink` a piece at a time (about 1 MB), a
/// section after another: saving holds one piece of the file, not the
/// file.  Returns the bytes written.
std::uint64_t encode_map(const Map& map, const MapSettings& settings, std::uint32_t sessions,
                         const std::string& app_json, const BagOf& bag_of, std::int64_t session_offset_ns,
                         const MapByteSink& sink);

/// Checks the whole file (magic, version, sections, checksums) and returns
/// its header.  Throws IoError naming `file` and what is wrong (truncated,
/// damaged, not a map file, a newer version), with the section and the byte
/// ("KEYF section at byte N (file byte M): ...", N counted from the
/// section's tag).
MapFileHeader read_map_header(const MapFileBytes& bytes);
MapFileHeader read_map_header(const std::string& bytes, const std::string& file);

/// The camera model of the map's settings (that read_map_header checked).
std::shared_ptr<const CameraModel> camera_for(const MapSettings& settings);

/// Reads the keyframes, points and graph of the file whose header
/// read_map_header gave into `map` (empty), with frames on camera `cam`
/// (the checksums are not checked again); from a version-2 file also the
/// inertial state: the map's gravity (ready), each keyframe's velocity and
/// bias and its links to its neighbours in time (without the readings
/// between them: a loaded chain has no intervals).  Every reference is checked
/// (ids, keypoint indices, the spanning tree) and every value against what
/// a camera of the map's settings could have made (docs/map_file.md, "Bad
/// files"); a bad one throws IoError naming `file`, the section and the
/// item.  Point descriptors, normals and scale ranges are computed.  With
/// a `spill`, each keyframe's features go into it as the keyframe is read,
/// and the pages that linking the points reads leave the process again
/// every kLoadSpillDropPoints points, so the features never all lie in
/// memory at once.
void decode_map(const MapFileBytes& bytes, const MapFileHeader& header, const std::shared_ptr<const CameraModel>& cam,
                Map* map, const std::shared_ptr<FeatureSpill>& spill = nullptr);
inline constexpr std::size_t kLoadSpillDropPoints = 16384;
void decode_map(const std::string& bytes, const std::string& file, const MapFileHeader& header,
                const std::shared_ptr<const CameraModel>& cam, Map* map);

}  // namespace pvb::slam
