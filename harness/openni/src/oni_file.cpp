#include "pvb/openni/oni_file.hpp"

#include <cstring>
#include <fstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

namespace pvb::openni {
namespace {

constexpr std::uint32_t kRecordMagic = 0x0052494E;  // "NIR\0"
constexpr std::size_t kFileHeaderBytes = 24;
constexpr std::size_t kRecordHeaderBytes = 28;

std::uint32_t u32_at(const unsigned char* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

}  // namespace

std::uint32_t OniFileSummary::frames_of(std::uint32_t node_type) const {
  for (const auto& [id, node] : nodes)
    if (node.node_type == node_type) return node.frames;
  return 0;
}

std::size_t OniFileSummary::nodes_begun() const {
  std::size_t n = 0;
  for (const auto& [id, node] : nodes) n += node.data_begun ? 1 : 0;
  return n;
}

OniFileSummary scan_oni_file(const std::string& path) {
  require_regular_file(path);  // a FIFO would block the open, a folder reads as garbage
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, "cannot open the file");
  in.seekg(0, std::ios::end);
  OniFileSummary s;
  s.size_bytes = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  unsigned char header[kFileHeaderBytes];
  if (!in.read(reinterpret_cast<char*>(header), kFileHeaderBytes) || std::memcmp(header, "NI10", 4) != 0)
    throw IoError(path, "not an OpenNI2 recording (no NI10 file header)");

  std::uint64_t pos = kFileHeaderBytes;
  while (pos < s.size_bytes) {
    unsigned char rec[kRecordHeaderBytes + 64];
    const std::uint64_t left = s.size_bytes - pos;
    if (left < kRecordHeaderBytes) {
      s.broken_at = pos;
      break;
    }
    in.seekg(static_cast<std::streamoff>(pos));
    const std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(left, sizeof rec));
    if (!in.read(reinterpret_cast<char*>(rec), static_cast<std::streamsize>(want))) {
      s.broken_at = pos;
      break;
    }
    const std::uint32_t magic = u32_at(rec), type = u32_at(rec + 4), node = u32_at(rec + 8);
    const std::uint64_t fields = u32_at(rec + 12), payload = u32_at(rec + 16);
    if (magic != kRecordMagic || fields < kRecordHeaderBytes || fields + payload > left) {
      s.broken_at = pos;
      break;
    }
    switch (static_cast<OniRecordType>(type)) {
      case OniRecordType::kNodeAdded:
        // fields: u32 name size, name, u32 node type, ...
        if (want >= kRecordHeaderBytes + 4) {
          const std::uint32_t name_bytes = u32_at(rec + kRecordHeaderBytes);
          const std::size_t type_at = kRecordHeaderBytes + 4 + name_bytes;
          if (type_at + 4 <= want && type_at + 4 <= fields) s.nodes[node].node_type = u32_at(rec + type_at);
        }
        break;
      case OniRecordType::kNodeDataBegin:
        s.nodes[node].data_begun = true;
        break;
      case OniRecordType::kNewData:
        ++s.nodes[node].frames;
        break;
      case OniRecordType::kEnd:
        s.has_end = true;
        break;
    }
    pos += fields + payload;
    if (s.has_end) {
      s.end_bytes = pos;
      break;
    }
  }
  return s;
}

void check_oni_complete(const std::string& path, const OniFileSummary& s) {
  if (s.broken_at != 0)
    throw IoError(path, "truncated or corrupt recording: the record at byte " + std::to_string(s.broken_at) +
                            " runs past the end of the file (" + std::to_string(s.size_bytes) + " bytes)");
  if (!s.has_end)
    throw IoError(path,
                  "truncated or incomplete recording: no end record (was the recorder stopped cleanly?)");
  if (s.frames_of(kOniNodeDepth) == 0 || s.frames_of(kOniNodeImage) == 0)
    throw IoError(path, "the recording needs depth and colour frames (has " +
                            std::to_string(s.frames_of(kOniNodeDepth)) + " depth, " +
                            std::to_string(s.frames_of(kOniNodeImage)) + " colour)");
}

}  // namespace pvb::openni
