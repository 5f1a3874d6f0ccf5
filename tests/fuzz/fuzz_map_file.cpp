// Fuzz target: the map file reader.  Each input is read as it is (mostly
// stopped by a checksum), then again with its section checksums made right,
// so that mutations reach the section parsers: every count, id, index and
// value must be checked there.  Any input must give a map or a pvb::Error,
// and a map read must be written back as a file the reader reads (the
// writer never writes what the reader refuses).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/fnv.hpp"
#include "pvb/slam/core/map_file.hpp"

namespace {

std::uint64_t get_u64(const std::string& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t(static_cast<unsigned char>(b[at + i])) << (8 * i);
  return v;
}

void put_u64(std::string& b, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) b[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}

/// Recomputes each section's checksum where the lengths allow.
std::string with_checksums(std::string b) {
  std::size_t at = 16;  // magic, version, section count
  while (at + 12 <= b.size()) {
    const std::uint64_t length = get_u64(b, at + 4);
    if (length > b.size() - at - 12 || b.size() - at - 12 - length < 8) break;
    put_u64(b, at + 12 + length, pvb::fnv1a64(b.data() + at + 12, length));
    at += 12 + length + 8;
  }
  return b;
}

/// The map of `bytes`, written again; empty when the reader refuses `bytes`.
std::string read(const std::string& bytes) {
  try {
    const pvb::slam::MapFileHeader h = pvb::slam::read_map_header(bytes, "input.pvbmap");
    pvb::slam::MapSettings s = h.settings;
    s.distortion = {};  // no per-pixel undistortion table: the reader is what is under test
    pvb::slam::Map map;
    pvb::slam::decode_map(bytes, "input.pvbmap", h, pvb::slam::camera_for(s), &map);
    std::lock_guard<std::mutex> lock(map.mutex());
    return pvb::slam::encode_map(map, h.settings, h.sessions, h.app_json);
  } catch (const pvb::Error&) {
    return "";
  }
}

void read_and_write_back(const std::string& bytes) {
  const std::string again = read(bytes);
  if (again.empty()) return;
  try {
    const pvb::slam::MapFileHeader h = pvb::slam::read_map_header(again, "again.pvbmap");
    pvb::slam::MapSettings s = h.settings;
    s.distortion = {};
    pvb::slam::Map map;
    pvb::slam::decode_map(again, "again.pvbmap", h, pvb::slam::camera_for(s), &map);
  } catch (const pvb::Error& e) {
    std::fprintf(stderr, "a map read was written back as a file the reader refuses: %s\n", e.what());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  read_and_write_back(bytes);
  read_and_write_back(with_checksums(bytes));
  return 0;
}
