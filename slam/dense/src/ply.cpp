#include "pvb/slam/dense/ply.hpp"

#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"

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

void write_ply(const std::string& path, const PointCloud& cloud) {
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment PE-SLAM Bench dense map (T_w_c of the keyframes), "
            "metres\n"
         << "element vertex " << cloud.size() << "\n"
         << "property float x\nproperty float y\nproperty float z\n"
         << "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  // Through a temporary file: a write that fails (disk full) leaves no PLY
  // whose header announces vertices its body lacks.
  write_file_via_temp(path, [&](OutputFile& f) {
    f.append(header.str());
    std::vector<unsigned char> buf;
    constexpr std::size_t kChunk = 65536;
    buf.reserve(kChunk * kVertexBytes);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const CloudPoint& p = cloud[i];
      unsigned char v[kVertexBytes];
      put_float_le(v, p.x);
      put_float_le(v + 4, p.y);
      put_float_le(v + 8, p.z);
      v[12] = p.r;
      v[13] = p.g;
      v[14] = p.b;
      buf.insert(buf.end(), v, v + kVertexBytes);
      if (buf.size() >= kChunk * kVertexBytes || i + 1 == cloud.size()) {
        f.append(reinterpret_cast<const char*>(buf.data()), buf.size());
        buf.clear();
      }
    }
  });
}

PointCloud read_ply(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw IoError(path, "cannot open");
  static const char* kProps[] = {"property float x",   "property float y",     "property float z",
                                 "property uchar red", "property uchar green", "property uchar blue"};
  std::string line;
  int line_no = 0;
  auto next_line = [&]() {
    if (!std::getline(f, line)) throw IoError(path, "header ends early", line_no);
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  };
  if (next_line() != "ply") throw IoError(path, "expected 'ply', got '" + line + "'", line_no);
  if (next_line() != "format binary_little_endian 1.0")
    throw IoError(path, "expected 'format binary_little_endian 1.0', got '" + line + "'", line_no);
  std::size_t count = 0;
  bool have_vertex = false;
  int prop = 0;
  while (next_line() != "end_header") {
    if (line.rfind("comment", 0) == 0 || line.rfind("obj_info", 0) == 0) continue;
    if (line.rfind("element ", 0) == 0) {
      std::istringstream ss(line.substr(8));
      std::string name;
      long long n = -1;
      ss >> name >> n;
      if (name != "vertex" || have_vertex || n < 0)
        throw IoError(path, "expected one 'element vertex N', got '" + line + "'", line_no);
      have_vertex = true;
      count = static_cast<std::size_t>(n);
      continue;
    }
    if (!have_vertex || prop >= 6 || line != kProps[prop])
      throw IoError(
          path,
          std::string("expected '") + (prop < 6 ? kProps[prop] : "end_header") + "', got '" + line + "'",
          line_no);
    ++prop;
  }
  if (!have_vertex || prop != 6)
    throw IoError(path, "header lacks the vertex element or its x y z red green blue", line_no);
  std::vector<unsigned char> body(count * kVertexBytes);
  f.read(reinterpret_cast<char*>(body.data()), static_cast<std::streamsize>(body.size()));
  if (static_cast<std::size_t>(f.gcount()) != body.size())
    throw IoError(path, "body truncated: " + std::to_string(count) + " vertices announced, " +
                            std::to_string(static_cast<std::size_t>(f.gcount()) / kVertexBytes) + " present");
  PointCloud out(count);
  for (std::size_t i = 0; i < count; ++i) {
    const unsigned char* v = body.data() + i * kVertexBytes;
    out[i] = {get_float_le(v), get_float_le(v + 4), get_float_le(v + 8), v[12], v[13], v[14]};
  }
  return out;
}

}  // namespace pvb::slam::dense
