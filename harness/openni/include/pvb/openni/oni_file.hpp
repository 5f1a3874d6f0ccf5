#pragma once
// A reader for the record structure of OpenNI2 .oni files (no pixel
// decoding).  Used to refuse truncated recordings with a clear message
// before the OpenNI2 player sees them, to learn when an asynchronous
// recorder has really started, and to count the frames that landed.
//
// Layout (OpenNI2 2.2, little-endian, packed): a 24-byte file header
// ("NI10", version, max timestamp, max node id), then records, each a
// 28-byte header {magic "NIR\0", type, node id, fields size (header
// included), payload size, undo position} followed by its fields and payload.
#include <cstdint>
#include <map>
#include <string>

namespace pvb::openni {

/// Record types the scanner distinguishes.
enum class OniRecordType : std::uint32_t {
  kNodeAdded = 0x0D,
  kNodeDataBegin = 0x08,
  kNewData = 0x0A,
  kEnd = 0x0B,
};

/// One stream (a "node") of the file.
struct OniNode {
  std::uint32_t node_type = 0;  ///< 2 depth, 3 image (colour), 5 IR
  std::uint32_t frames = 0;     ///< NEW_DATA records seen
  bool data_begun = false;      ///< a NODE_DATA_BEGIN record was seen
};

struct OniFileSummary {
  std::uint64_t size_bytes = 0;
  std::map<std::uint32_t, OniNode> nodes;  ///< by node id
  bool has_end = false;                    ///< the END record closes the file
  std::uint64_t end_bytes = 0;             ///< offset just past the END record (when has_end)
  /// Byte offset where the records stop making sense (a record running past
  /// the end of the file or a bad magic), or 0 when every record is whole.
  std::uint64_t broken_at = 0;

  /// Frames of the first node of this type (0 when absent).
  std::uint32_t frames_of(std::uint32_t node_type) const;
  /// Nodes whose data has begun.
  std::size_t nodes_begun() const;
};

inline constexpr std::uint32_t kOniNodeDepth = 2;
inline constexpr std::uint32_t kOniNodeImage = 3;

/// Scans the records of `path`.  A partly written file is summarised up to
/// its last whole record.  Throws IoError when the file cannot be read or
/// does not start with an .oni header.
OniFileSummary scan_oni_file(const std::string& path);

/// Throws IoError(path, ...) naming the problem unless the file is a
/// complete recording with depth and colour frames.
void check_oni_complete(const std::string& path, const OniFileSummary& summary);

}  // namespace pvb::openni
