#include "pvb/slam/dense/voxel_map.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/memory.hpp"

namespace pvb::slam::dense {
namespace {
constexpr double kUnitsPerMetre = 1e6;  // sums in micrometres
constexpr int kKeyBits = 21;            // per axis, signed: +-2^20 voxels
constexpr std::int64_t kKeyBias = std::int64_t(1) << (kKeyBits - 1);
constexpr int kBlockBits = 5;  // 32 voxels a side
constexpr std::uint64_t kLocalMask = (1u << kBlockBits) - 1;
constexpr std::uint32_t kFree = 0xffffffffu;

std::int64_t to_units(float v) { return std::llround(static_cast<double>(v) * kUnitsPerMetre); }

bool finite(const CloudPoint& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

/// The voxel index of a coordinate, biased to [0, 2^21).
std::uint64_t biased(float v, double inv) {
  const auto i = static_cast<std::int64_t>(std::floor(v * inv));
  if (i < -kKeyBias || i >= kKeyBias)
    throw Error("VoxelMap: a point lies beyond 2^20 voxels of the origin (voxel index " + std::to_string(i) + ")");
  return static_cast<std::uint64_t>(i + kKeyBias);
}

std::uint64_t block_key(std::uint64_t ux, std::uint64_t uy, std::uint64_t uz) {
  return ((ux >> kBlockBits) << 32) | ((uy >> kBlockBits) << 16) | (uz >> kBlockBits);
}
std::uint16_t local_key(std::uint64_t ux, std::uint64_t uy, std::uint64_t uz) {
  return static_cast<std::uint16_t>(((ux & kLocalMask) << (2 * kBlockBits)) | ((uy & kLocalMask) << kBlockBits) |
                                    (uz & kLocalMask));
}
/// A voxel's biased index along one axis from its block's and its own.
std::uint64_t axis(std::uint64_t block_key, std::uint16_t local, int a) {
  const std::uint64_t b = (block_key >> (16 * (2 - a))) & 0xffff;
  const std::uint64_t l = (local >> (kBlockBits * (2 - a))) & kLocalMask;
  return (b << kBlockBits) | l;
}
/// Packed voxel keys sort as (x, y, z): each axis is biased to non-negative.
std::uint64_t voxel_key(std::uint64_t block_key, std::uint16_t local) {
  return (axis(block_key, local, 0) << (2 * kKeyBits)) | (axis(block_key, local, 1) << kKeyBits) |
         axis(block_key, local, 2);
}

void put_varint(std::string& s, std::uint64_t v) {
  while (v >= 0x80) {
    s.push_back(static_cast<char>(v | 0x80));
    v >>= 7;
  }
  s.push_back(static_cast<char>(v));
}
std::uint64_t get_varint(const char*& p, const char* end) {
  std::uint64_t v = 0;
  for (int shift = 0; shift < 64; shift += 7) {
    if (p == end) throw Error("VoxelMap: a spilled block is cut short");
    const auto byte = static_cast<unsigned char>(*p++);
    v |= static_cast<std::uint64_t>(byte & 0x7f) << shift;
    if (!(byte & 0x80)) return v;
  }
  throw Error("VoxelMap: a spilled block holds a bad number");
}
std::uint64_t zigzag(std::uint64_t v) { return (v << 1) ^ (0 - (v >> 63)); }
std::uint64_t unzigzag(std::uint64_t v) { return (v >> 1) ^ (0 - (v & 1)); }
}  // namespace

struct VoxelMap::Block {
  std::vector<Cell> cells;
  std::vector<std::uint16_t> local;                ///< each cell's voxel within the block
  std::vector<std::uint32_t> slots = std::vector<std::uint32_t>(64, kFree);  ///< (local << 16) | cell
  std::uint32_t occupied = 0;
  std::uint64_t last_use = 0, touched_at = 0;
  std::size_t bytes = 0;  ///< heap bytes as last counted

  Cell& find_or_make(std::uint16_t l) {
    std::size_t mask = slots.size() - 1;
    std::size_t i = ((l * 0x9e3779b1u) >> 16) & mask;
    for (; slots[i] != kFree; i = (i + 1) & mask)
      if ((slots[i] >> 16) == l) return cells[slots[i] & 0xffff];
    const auto c = static_cast<std::uint32_t>(cells.size());
    cells.emplace_back();
    local.push_back(l);
    slots[i] = (std::uint32_t(l) << 16) | c;
    if (2 * cells.size() > slots.size()) rehash(2 * slots.size());
    return cells[c];
  }
  void rehash(std::size_t n) {
    std::vector<std::uint32_t> s(n, kFree);
    const std::size_t mask = n - 1;
    for (std::uint32_t c = 0; c < cells.size(); ++c) {
      std::size_t i = ((local[c] * 0x9e3779b1u) >> 16) & mask;
      while (s[i] != kFree) i = (i + 1) & mask;
      s[i] = (std::uint32_t(local[c]) << 16) | c;
    }
    slots.swap(s);
  }
  std::size_t heap_bytes() const {
    return heap_block_bytes(sizeof(Block)) + vector_heap_bytes(cells) + vector_heap_bytes(local) +
           vector_heap_bytes(slots);
  }
};

namespace {
/// A voxel's reference position along one axis (its centre, micrometres):
/// spilled sums are stored relative to n times it, which keeps them small.
std::uint64_t centre_units(std::uint64_t biased_index, double leaf_m) {
  const double centre_m = (static_cast<double>(static_cast<std::int64_t>(biased_index) - kKeyBias) + 0.5) * leaf_m;
  return static_cast<std::uint64_t>(std::llround(centre_m * kUnitsPerMetre));
}

/// Occupied cells of a block, in local-key order, as varints (sums relative
/// to the voxel centres, modulo 2^64 so that any sum comes back exactly).
std::string encode(std::uint64_t key, const VoxelMap::Block& b, double leaf_m) {
  std::vector<std::uint32_t> order;
  for (std::uint32_t c = 0; c < b.cells.size(); ++c)
    if (b.cells[c].n > 0) order.push_back(c);
  std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return b.local[x] < b.local[y]; });
  std::string s;
  put_varint(s, order.size());
  std::uint16_t prev = 0;
  for (std::uint32_t c : order) {
    const VoxelMap::Cell& cell = b.cells[c];
    const std::uint16_t l = b.local[c];
    put_varint(s, l - prev);
    prev = l;
    const auto n = static_cast<std::uint64_t>(cell.n);
    put_varint(s, n);
    const std::int64_t sums[3] = {cell.sx, cell.sy, cell.sz};
    for (int a = 0; a < 3; ++a)
      put_varint(s, zigzag(static_cast<std::uint64_t>(sums[a]) - n * centre_units(axis(key, l, a), leaf_m)));
    for (std::int32_t v : {cell.sr, cell.sg, cell.sb}) put_varint(s, static_cast<std::uint32_t>(v));
  }
  return s;
}

void decode(std::uint64_t key, const std::string& s, double leaf_m, VoxelMap::Block* b) {
  const char* p = s.data();
  const char* end = p + s.size();
  const std::uint64_t count = get_varint(p, end);
  if (count > (1u << (3 * kBlockBits))) throw Error("VoxelMap: a spilled block holds too many voxels");
  std::uint64_t l = 0;
  for (std::uint64_t i = 0; i < count; ++i) {
    l += get_varint(p, end);
    if (l >= (1u << (3 * kBlockBits))) throw Error("VoxelMap: a spilled block holds a voxel outside it");
    VoxelMap::Cell& c = b->find_or_make(static_cast<std::uint16_t>(l));
    const std::uint64_t n = get_varint(p, end);
    c.n = static_cast<std::int32_t>(n);
    std::int64_t* sums[3] = {&c.sx, &c.sy, &c.sz};
    for (int a = 0; a < 3; ++a)
      *sums[a] = static_cast<std::int64_t>(unzigzag(get_varint(p, end)) +
                                           n * centre_units(axis(key, static_cast<std::uint16_t>(l), a), leaf_m));
    for (std::int32_t* v : {&c.sr, &c.sg, &c.sb}) *v = static_cast<std::int32_t>(get_varint(p, end));
    ++b->occupied;
  }
}
}  // namespace

VoxelMap::VoxelMap(double leaf_m, SpillOptions spill) : leaf_m_(leaf_m), options_(std::move(spill)) {
  if (!(leaf_m > 0)) throw Error("VoxelMap: leaf size must be > 0 m, got " + std::to_string(leaf_m));
}
VoxelMap::VoxelMap(VoxelMap&&) noexcept = default;
VoxelMap& VoxelMap::operator=(VoxelMap&&) noexcept = default;
VoxelMap::~VoxelMap() = default;

VoxelMap::Block& VoxelMap::block(std::uint64_t key) {
  if (key == last_key_) return *last_;
  Block* b;
  if (auto it = resident_.find(key); it != resident_.end()) {
    b = it->second.get();
  } else {
    auto owned = std::make_unique<Block>();
    b = owned.get();
    if (auto sp = spilled_.find(key); sp != spilled_.end()) {  // the robot is back: read it in
      decode(key, file_->read(sp->second.extent), leaf_m_, b);
      file_->release(sp->second.extent);
      spilled_.erase(sp);
    }
    resident_.emplace(key, std::move(owned));
  }
  b->last_use = tick_;
  if (b->touched_at != tick_) {
    b->touched_at = tick_;
    touched_.push_back(b);
  }
  last_key_ = key;
  last_ = b;
  return *b;
}

void VoxelMap::bin(const CloudPoint& p, int sign) {
  const double inv = 1.0 / leaf_m_;
  const std::uint64_t ux = biased(p.x, inv), uy = biased(p.y, inv), uz = biased(p.z, inv);
  Block& b = block(block_key(ux, uy, uz));
  Cell& c = b.find_or_make(local_key(ux, uy, uz));
  if (sign > 0) {
    if (c.n++ == 0) ++b.occupied, ++occupied_;
    c.sx += to_units(p.x), c.sy += to_units(p.y), c.sz += to_units(p.z);
    c.sr += p.r, c.sg += p.g, c.sb += p.b;
  } else {
    if (c.n == 0) throw Error("VoxelMap::remove: a point that was not added");
    c.sx -= to_units(p.x), c.sy -= to_units(p.y), c.sz -= to_units(p.z);
    c.sr -= p.r, c.sg -= p.g, c.sb -= p.b;
    if (--c.n == 0) --b.occupied, --occupied_;
  }
}

void VoxelMap::add(const PointCloud& cloud_w) { bin_all(cloud_w, +1); }

void VoxelMap::remove(const PointCloud& cloud_w) { bin_all(cloud_w, -1); }

void VoxelMap::bin_all(const PointCloud& cloud_w, int sign) {
  ++tick_;
  try {
    for (const CloudPoint& p : cloud_w)
      if (finite(p)) bin(p, sign);
  } catch (...) {
    account_touched();
    throw;
  }
  account_touched();
  enforce_budget();
}

void VoxelMap::account_touched() {
  for (Block* b : touched_) {
    const std::size_t now = b->heap_bytes();
    resident_bytes_ += now - b->bytes;
    b->bytes = now;
  }
  touched_.clear();
}

void VoxelMap::enforce_budget() {
  if (options_.budget_bytes == 0 || resident_bytes_ <= options_.budget_bytes) return;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> by_age;  // last use, key
  by_age.reserve(resident_.size());
  for (const auto& [key, b] : resident_) by_age.emplace_back(b->last_use, key);
  std::sort(by_age.begin(), by_age.end());
  const std::size_t target = options_.budget_bytes / 8 * 7;  // room for a while before the next round
  for (const auto& [use, key] : by_age) {
    if (resident_bytes_ <= target) break;
    auto it = resident_.find(key);
    spill(key, *it->second);
    resident_.erase(it);
  }
  last_key_ = ~std::uint64_t(0);
  last_ = nullptr;
}

void VoxelMap::spill(std::uint64_t key, Block& b) {
  resident_bytes_ -= b.bytes;
  if (b.occupied == 0) return;  // nothing to keep
  if (!file_) file_ = std::make_unique<SpillFile>(options_.dir);
  spilled_[key] = {file_->write(encode(key, b, leaf_m_)), b.occupied};
}

void VoxelMap::gather(std::uint64_t key, std::vector<std::pair<std::uint64_t, Cell>>* cells) const {
  const Block* b;
  Block loaded;
  if (auto it = resident_.find(key); it != resident_.end()) {
    b = it->second.get();
  } else {
    decode(key, file_->read(spilled_.at(key).extent), leaf_m_, &loaded);
    b = &loaded;
  }
  for (std::size_t c = 0; c < b->cells.size(); ++c)
    if (b->cells[c].n > 0) cells->emplace_back(voxel_key(key, b->local[c]), b->cells[c]);
}

void VoxelMap::for_each_slab(const std::function<void(const PointCloud&)>& out) const {
  std::vector<std::uint64_t> keys;
  keys.reserve(resident_.size() + spilled_.size());
  for (const auto& [key, b] : resident_)
    if (b->occupied > 0) keys.push_back(key);
  for (const auto& [key, s] : spilled_) keys.push_back(key);
  std::sort(keys.begin(), keys.end());  // block x first: slabs come in voxel-key order
  std::vector<std::pair<std::uint64_t, Cell>> cells;
  PointCloud slab;
  for (std::size_t i = 0; i < keys.size();) {
    cells.clear();
    const std::uint64_t bx = keys[i] >> 32;
    for (; i < keys.size() && (keys[i] >> 32) == bx; ++i) gather(keys[i], &cells);
    std::sort(cells.begin(), cells.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    slab.clear();
    for (const auto& [vk, c] : cells) {
      const double n = static_cast<double>(c.n);
      const double to_m = 1.0 / (kUnitsPerMetre * n);
      slab.push_back({static_cast<float>(c.sx * to_m), static_cast<float>(c.sy * to_m),
                      static_cast<float>(c.sz * to_m), static_cast<std::uint8_t>(std::lround(c.sr / n)),
                      static_cast<std::uint8_t>(std::lround(c.sg / n)),
                      static_cast<std::uint8_t>(std::lround(c.sb / n))});
    }
    if (!slab.empty()) out(slab);
  }
}

PointCloud VoxelMap::cloud() const {
  PointCloud all;
  all.reserve(occupied_);
  for_each_slab([&](const PointCloud& slab) { append(all, slab); });
  return all;
}

std::size_t VoxelMap::memory_bytes() const {
  return resident_bytes_ + unordered_map_bytes(resident_) + unordered_map_bytes(spilled_) +
         vector_heap_bytes(touched_);
}

SpillStats VoxelMap::spill_stats() const {
  SpillStats s;
  s.resident_bytes = memory_bytes();
  if (file_) s.disk_bytes = file_->live_bytes(), s.writes = file_->writes(), s.reads = file_->reads();
  return s;
}

}  // namespace pvb::slam::dense
