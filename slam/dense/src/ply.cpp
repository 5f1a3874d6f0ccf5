#include "pvb/slam/dense/ply.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/text.hpp"

namespace pvb::slam::dense {
namespace {

constexpr std::size_t kVertexBytes = 3 * sizeof(float) + 3;  // packed: x y z r g b

// Bytes are put and taken explicitly little endian, whatever the host.
void put_float_le(unsigned char* dst, float v) {
  std::uint32_t u;
  std::memcpy(&u, &v, 4);
  for (int i = 0; i < 4; ++i) dst[i] = static_cast<unsigned char>(u >> (8 * i));
}

float get_float_le(const unsigned char* src) {
  std::uint32_t u = 0;
  for (int i = 0; i < 4; ++i) u |= static_cast<std::uint32_t>(src[i]) << (8 * i);
  float v;
  std::memcpy(&v, &u, 4);
  return v;
}

}  // namespace

void write_ply(const std::string& path, std::size_t vertices, const CloudChunks& chunks) {
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment PE-SLAM Bench dense map (T_w_c of the keyframes), "
            "metres\n"
         << "element vertex " << vertices << "\n"
         << "property float x\nproperty float y\nproperty float z\n"
         << "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  // Through a temporary file: a write that fails (disk full) leaves no PLY
  // whose header announces vertices its body lacks.
  write_file_via_temp(path, [&](OutputFile& f) {
    f.append(header.str());
    std::vector<unsigned char> buf;
    constexpr std::size_t kChunk = 65536;
    buf.reserve(kChunk * kVertexBytes);
    std::size_t written = 0;
    const auto flush = [&] {
      f.append(reinterpret_cast<const char*>(buf.data()), buf.size());
      buf.clear();
    };
    chunks([&](const PointCloud& cloud) {
      for (const CloudPoint& p : cloud) {
        unsigned char v[kVertexBytes];
        put_float_le(v, p.x);
        put_float_le(v + 4, p.y);
        put_float_le(v + 8, p.z);
        v[12] = p.r;
        v[13] = p.g;
        v[14] = p.b;
        buf.insert(buf.end(), v, v + kVertexBytes);
        if (buf.size() >= kChunk * kVertexBytes) flush();
      }
      written += cloud.size();
    });
    if (!buf.empty()) flush();
    if (written != vertices)
      throw IoError(path, "the header announces " + std::to_string(vertices) + " vertices but " +
                              std::to_string(written) + " came");
  });
}

void write_ply(const std::string& path, const PointCloud& cloud) {
  write_ply(path, cloud.size(), [&](const std::function<void(const PointCloud&)>& sink) { sink(cloud); });
}

namespace {

constexpr std::size_t kMaxHeaderLineBytes = 1024;
constexpr int kMaxHeaderLines = 256;

/// The header as read_ply understands it, and where the body starts.
struct PlyHeader {
  std::uint64_t count = 0;
  std::uint64_t body_offset = 0;
};

/// A header line quoted for a message: escaped, and cut at 60 characters.
std::string quoted(const std::string& line) {
  return "'" + printable(line.size() > 60 ? line.substr(0, 60) + "..." : line) + "'";
}

/// A whole number of vertices: digits only, within 64 bits.
bool parse_count(const std::string& text, std::uint64_t* n) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), *n);
  return ec == std::errc() && end == text.data() + text.size();
}

PlyHeader read_ply_header(std::istream& f, const std::string& path) {
  static const char* kProps[] = {"property float x",   "property float y",     "property float z",
                                 "property uchar red", "property uchar green", "property uchar blue"};
  std::string line;
  int line_no = 0;
  std::uint64_t offset = 0;
  auto next_line = [&]() -> const std::string& {
    line.clear();
    for (char c; f.get(c) && c != '\n';) {
      if (line.size() == kMaxHeaderLineBytes) throw IoError(path, "header line longer than 1024 bytes", line_no + 1);
      line += c;
    }
    if (!f && line.empty()) throw IoError(path, "the header ends before 'end_header'", line_no);
    if (++line_no > kMaxHeaderLines) throw IoError(path, "no 'end_header' in the first 256 lines", line_no);
    offset += line.size() + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  };
  if (next_line() != "ply") throw IoError(path, "expected 'ply', got " + quoted(line), line_no);
  if (next_line() != "format binary_little_endian 1.0")
    throw IoError(path, "expected 'format binary_little_endian 1.0', got " + quoted(line), line_no);
  PlyHeader h;
  bool have_vertex = false;
  int prop = 0;
  while (next_line() != "end_header") {
    if (line.rfind("comment", 0) == 0 || line.rfind("obj_info", 0) == 0) continue;
    if (line.rfind("element ", 0) == 0) {
      std::istringstream ss(line.substr(8));
      std::string name, count, extra;
      ss >> name >> count >> extra;
      if (name != "vertex" || have_vertex || !extra.empty() || !parse_count(count, &h.count))
        throw IoError(path, "expected one 'element vertex N' with N a whole number, got " + quoted(line), line_no);
      have_vertex = true;
      continue;
    }
    if (!have_vertex || prop >= 6 || line != kProps[prop])
      throw IoError(path, std::string("expected '") + (prop < 6 ? kProps[prop] : "end_header") + "', got " + quoted(line),
                    line_no);
    ++prop;
  }
  if (!have_vertex || prop != 6)
    throw IoError(path, "header lacks the vertex element or its x y z red green blue", line_no);
  h.body_offset = offset;
  return h;
}

}  // namespace

PointCloud read_ply(const std::string& path, PlyReadStats* stats) {
  require_regular_file(path);
  std::ifstream f(path, std::ios::binary);
  if (!f) throw IoError(path, "cannot open for reading");
  const PlyHeader h = read_ply_header(f, path);
  // The body's size is checked against the file before anything is
  // allocated for it: a header may announce any count.
  f.clear();
  f.seekg(0, std::ios::end);
  const auto file_bytes = static_cast<std::uint64_t>(f.tellg());
  if (h.body_offset > file_bytes) throw IoError(path, "'end_header' is not followed by a newline");
  const std::uint64_t body_bytes = file_bytes - h.body_offset;
  if (h.count > body_bytes / kVertexBytes)
    throw IoError(path, "body truncated: " + std::to_string(h.count) + " vertices announced (" +
                            std::to_string(h.count) + " x 15 bytes), " + std::to_string(body_bytes / kVertexBytes) +
                            " present");
  if (body_bytes != h.count * kVertexBytes)
    throw IoError(path, std::to_string(h.count) + " vertices announced, but the body holds " +
                            std::to_string(body_bytes - h.count * kVertexBytes) +
                            " bytes more than they take (a wrong count in the header?)");
  const auto count = static_cast<std::size_t>(h.count);
  std::vector<unsigned char> body(count * kVertexBytes);
  f.seekg(static_cast<std::streamoff>(h.body_offset));
  if (!f.read(reinterpret_cast<char*>(body.data()), static_cast<std::streamsize>(body.size())))
    throw IoError(path, "cannot read the body");
  PointCloud out;
  out.reserve(count);
  std::size_t dropped = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const unsigned char* v = body.data() + i * kVertexBytes;
    const CloudPoint p{get_float_le(v), get_float_le(v + 4), get_float_le(v + 8), v[12], v[13], v[14]};
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
      out.push_back(p);
    else
      ++dropped;
  }
  if (stats) stats->non_finite_dropped = dropped;
  return out;
}

}  // namespace pvb::slam::dense
