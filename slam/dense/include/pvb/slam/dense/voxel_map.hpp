#pragma once
// A voxel grid that keyframe clouds enter and leave, for a dense map that
// follows the keyframe poses as bundle adjustment and loop closing move
// them.  Each voxel keeps the sums of the points binned into it and their
// count; the map's cloud is one point per voxel at the mean position with
// the mean colour, as voxel_filter() gives.  Positions are summed as
// integer micrometres, so remove() undoes add() exactly: a keyframe moved
// out and back in leaves the map bit for bit as it was, whatever the order
// of the updates in between.
//
// Voxels live in blocks of 32 x 32 x 32 (64 cm at a 2 cm leaf), each with
// its own small open-addressing table.  With a memory budget, the blocks
// used longest ago are written to a spill file (compressed, empty voxels
// dropped) whenever the resident blocks exceed it, and read back when a
// point lands in them again: the map's memory stays bounded however far the
// robot drives, and its cloud is the same bit for bit whatever was spilled.
// cloud() and for_each_slab() read spilled blocks without keeping them.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "pvb/slam/dense/point_cloud.hpp"
#include "pvb/slam/dense/spill_file.hpp"

namespace pvb::slam::dense {

/// Where a bounded map spills and how much it keeps in memory.
struct SpillOptions {
  std::size_t budget_bytes = 0;  ///< resident blocks' bytes; 0: never spill
  std::string dir;               ///< spill file's folder ("": the system's temporary folder)
};

/// What a bounded structure holds in memory and on disk.
struct SpillStats {
  std::size_t resident_bytes = 0;   ///< in memory (heap blocks)
  std::uint64_t disk_bytes = 0;     ///< live records in the spill file, compressed
  std::uint64_t writes = 0, reads = 0;  ///< records written (spilled) and read back
};

class VoxelMap {
 public:
  /// leaf_m > 0: the voxel edge, metres.
  explicit VoxelMap(double leaf_m, SpillOptions spill = {});
  VoxelMap(VoxelMap&&) noexcept;
  VoxelMap& operator=(VoxelMap&&) noexcept;
  ~VoxelMap();

  /// Bins every finite point of the cloud (world frame) into its voxel.
  /// Throws pvb::Error for a point beyond +-2^20 voxels of the origin.
  void add(const PointCloud& cloud_w);
  /// Takes out the points add() put in: the same cloud, bit for bit.
  void remove(const PointCloud& cloud_w);

  /// One point per occupied voxel, sorted by voxel index (x, then y, then z).
  PointCloud cloud() const;
  /// The same points in the same order, handed over a slab at a time (the
  /// voxels of one block column in x), so that a caller can stream the map
  /// without holding it whole.
  void for_each_slab(const std::function<void(const PointCloud&)>& out) const;
  /// Occupied voxels, spilled or not.
  std::size_t voxels() const { return occupied_; }
  double leaf_m() const { return leaf_m_; }
  /// Heap bytes in memory: the resident blocks and the block index.
  std::size_t memory_bytes() const;
  SpillStats spill_stats() const;

  struct Cell {
    std::int64_t sx = 0, sy = 0, sz = 0;  ///< micrometres
    std::int32_t sr = 0, sg = 0, sb = 0;
    std::int32_t n = 0;
  };
  struct Block;

 private:
  struct Spilled {
    SpillFile::Extent extent;
    std::uint32_t occupied = 0;
  };
  Block& block(std::uint64_t block_key);
  void bin(const CloudPoint& p, int sign);
  /// Every finite point of the cloud in (+1) or out (-1), then the budget.
  void bin_all(const PointCloud& cloud_w, int sign);
  void account_touched();
  void enforce_budget();
  void spill(std::uint64_t block_key, Block& b);
  void gather(std::uint64_t block_key, std::vector<std::pair<std::uint64_t, Cell>>* cells) const;

  double leaf_m_;
  SpillOptions options_;
  std::size_t occupied_ = 0;
  std::size_t resident_bytes_ = 0;  ///< the resident blocks' heap bytes as last counted
  std::uint64_t tick_ = 0;          ///< one per add()/remove(): a block's last use
  std::unordered_map<std::uint64_t, std::unique_ptr<Block>> resident_;
  std::unordered_map<std::uint64_t, Spilled> spilled_;
  std::vector<Block*> touched_;  ///< blocks changed by the current call
  std::uint64_t last_key_ = ~std::uint64_t(0);
  Block* last_ = nullptr;  ///< the block the previous point went to
  std::unique_ptr<SpillFile> file_;
};

}  // namespace pvb::slam::dense
