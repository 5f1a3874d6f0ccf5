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
// add() returns which voxel each point went to, and remove() takes that
// back instead of looking the voxels up again; voxels that become empty
// stay allocated (a correction usually refills them at once), so a cell's
// index never changes and the handles stay valid.  Voxels are found through
// an open-addressing table (linear probing over packed keys): a loop
// correction re-bins millions of points, and a node-based map spends most
// of that time in cache misses and allocation.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pvb/slam/dense/point_cloud.hpp"

namespace pvb::slam::dense {

class VoxelMap {
 public:
  /// Where each point of a cloud went: a cell index, or kNoCell for a
  /// non-finite point.
  using Handle = std::vector<std::uint32_t>;
  static constexpr std::uint32_t kNoCell = 0xffffffffu;

  /// leaf_m > 0: the voxel edge, metres.
  explicit VoxelMap(double leaf_m);

  /// Bins every finite point of the cloud (world frame) into its voxel.
  /// Throws pvb::Error for a point beyond +-2^20 voxels of the origin.
  Handle add(const PointCloud& cloud_w);
  /// Takes out the points add() put in: the same cloud, bit for bit, with
  /// the handle add() returned for it.
  void remove(const PointCloud& cloud_w, const Handle& handle);

  /// One point per occupied voxel, sorted by voxel index (x, then y, then z).
  PointCloud cloud() const;
  /// Occupied voxels.
  std::size_t voxels() const { return occupied_; }
  double leaf_m() const { return leaf_m_; }
  /// Heap bytes of the cells and the table.
  std::size_t memory_bytes() const;

 private:
  struct Cell {
    std::int64_t sx = 0, sy = 0, sz = 0;  ///< micrometres
    std::int32_t sr = 0, sg = 0, sb = 0;
    std::int32_t n = 0;
  };
  /// The cell of a packed voxel key, made when new.
  std::uint32_t find_or_make(std::uint64_t key);
  void grow();

  double leaf_m_;
  std::size_t occupied_ = 0;
  std::vector<Cell> cells_;
  struct Slot {
    std::uint64_t key = 0;
    std::uint32_t cell = kNoCell;  ///< kNoCell: free
  };
  std::vector<Slot> slots_;  ///< the key beside its cell: one cache line per probe
};

}  // namespace pvb::slam::dense
