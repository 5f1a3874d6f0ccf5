#include "pvb/slam/dense/voxel_map.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/memory.hpp"

namespace pvb::slam::dense {
namespace {
constexpr double kUnitsPerMetre = 1e6;  // sums in micrometres

std::int64_t to_units(float v) { return std::llround(static_cast<double>(v) * kUnitsPerMetre); }

bool finite(const CloudPoint& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }
}  // namespace

namespace {
constexpr int kKeyBits = 21;  // per axis, signed: +-2^20 voxels
constexpr std::int64_t kKeyBias = std::int64_t(1) << (kKeyBits - 1);
constexpr std::uint64_t kKeyMask = (std::uint64_t(1) << kKeyBits) - 1;

std::uint64_t pack(std::int64_t x, std::int64_t y, std::int64_t z) {
  for (std::int64_t v : {x, y, z})
    if (v < -kKeyBias || v >= kKeyBias)
      throw Error("VoxelMap: a point lies beyond 2^20 voxels of the origin (voxel index " + std::to_string(v) + ")");
  return (static_cast<std::uint64_t>(x + kKeyBias) << (2 * kKeyBits)) |
         (static_cast<std::uint64_t>(y + kKeyBias) << kKeyBits) | static_cast<std::uint64_t>(z + kKeyBias);
}

/// splitmix64's finaliser: neighbouring voxels land far apart in the table.
std::uint64_t mix(std::uint64_t k) {
  k ^= k >> 30;
  k *= 0xbf58476d1ce4e5b9ull;
  k ^= k >> 27;
  k *= 0x94d049bb133111ebull;
  return k ^ (k >> 31);
}
}  // namespace

VoxelMap::VoxelMap(double leaf_m) : leaf_m_(leaf_m), slots_(1024) {
  if (!(leaf_m > 0)) throw Error("VoxelMap: leaf size must be > 0 m, got " + std::to_string(leaf_m));
}

void VoxelMap::grow() {
  std::vector<Slot> slots(slots_.size() * 2);
  const std::size_t mask = slots.size() - 1;
  for (const Slot& s : slots_) {
    if (s.cell == kNoCell) continue;
    std::size_t i = mix(s.key) & mask;
    while (slots[i].cell != kNoCell) i = (i + 1) & mask;
    slots[i] = s;
  }
  slots_.swap(slots);
}

std::uint32_t VoxelMap::find_or_make(std::uint64_t key) {
  const std::size_t mask = slots_.size() - 1;
  std::size_t i = mix(key) & mask;
  for (; slots_[i].cell != kNoCell; i = (i + 1) & mask)
    if (slots_[i].key == key) return slots_[i].cell;
  const auto c = static_cast<std::uint32_t>(cells_.size());
  if (c == kNoCell) throw Error("VoxelMap: more than 2^32 - 1 voxels");
  cells_.emplace_back();
  slots_[i] = {key, c};
  if (2 * cells_.size() > slots_.size()) grow();  // load factor <= 1/2
  return c;
}

VoxelMap::Handle VoxelMap::add(const PointCloud& cloud_w) {
  const double inv = 1.0 / leaf_m_;
  Handle handle(cloud_w.size(), kNoCell);
  for (std::size_t i = 0; i < cloud_w.size(); ++i) {
    const CloudPoint& p = cloud_w[i];
    if (!finite(p)) continue;
    const std::uint32_t ci =
        find_or_make(pack(static_cast<std::int64_t>(std::floor(p.x * inv)), static_cast<std::int64_t>(std::floor(p.y * inv)),
                          static_cast<std::int64_t>(std::floor(p.z * inv))));
    Cell& c = cells_[ci];
    if (c.n++ == 0) ++occupied_;
    c.sx += to_units(p.x), c.sy += to_units(p.y), c.sz += to_units(p.z);
    c.sr += p.r, c.sg += p.g, c.sb += p.b;
    handle[i] = ci;
  }
  return handle;
}

void VoxelMap::remove(const PointCloud& cloud_w, const Handle& handle) {
  if (handle.size() != cloud_w.size()) throw Error("VoxelMap::remove: the handle is not the cloud's");
  for (std::size_t i = 0; i < cloud_w.size(); ++i) {
    if (handle[i] == kNoCell) continue;
    Cell& c = cells_[handle[i]];
    const CloudPoint& p = cloud_w[i];
    c.sx -= to_units(p.x), c.sy -= to_units(p.y), c.sz -= to_units(p.z);
    c.sr -= p.r, c.sg -= p.g, c.sb -= p.b;
    if (--c.n == 0) --occupied_;
  }
}

PointCloud VoxelMap::cloud() const {
  std::vector<Slot> occupied;
  occupied.reserve(occupied_);
  for (const Slot& s : slots_)
    if (s.cell != kNoCell && cells_[s.cell].n > 0) occupied.push_back(s);
  // Packed keys sort as (x, y, z): each axis is biased to non-negative.
  std::sort(occupied.begin(), occupied.end(), [](const Slot& a, const Slot& b) { return a.key < b.key; });
  PointCloud out;
  out.reserve(occupied.size());
  for (const Slot& s : occupied) {
    const Cell& c = cells_[s.cell];
    const double n = static_cast<double>(c.n);
    const double to_m = 1.0 / (kUnitsPerMetre * n);
    out.push_back({static_cast<float>(c.sx * to_m), static_cast<float>(c.sy * to_m), static_cast<float>(c.sz * to_m),
                   static_cast<std::uint8_t>(std::lround(c.sr / n)), static_cast<std::uint8_t>(std::lround(c.sg / n)),
                   static_cast<std::uint8_t>(std::lround(c.sb / n))});
  }
  return out;
}

std::size_t VoxelMap::memory_bytes() const { return vector_heap_bytes(cells_) + vector_heap_bytes(slots_); }

}  // namespace pvb::slam::dense
