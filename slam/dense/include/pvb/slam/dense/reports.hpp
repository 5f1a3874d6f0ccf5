#pragma once
// What the dense mapper reports, as plain values: the map around the first
// loop correction, its running figures and the bytes it holds.  Users of
// these need not include the mapper itself (dense_mapper.hpp).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pvb/slam/dense/point_cloud.hpp"

namespace pvb::slam::dense {

/// The corrected map just before and just after the first loop correction.
struct LoopSnapshot {
  PointCloud before, after;
  std::size_t keyframes_moved = 0;
};

/// Figures for reports.
struct DenseMapperStats {
  std::size_t keyframes = 0;  ///< keyframes processed
  std::size_t points = 0;     ///< points over all keyframe clouds (before the global filter)
  double total_ms = 0;        ///< back-projection + voxel filter, summed over keyframes
  std::size_t pose_updates = 0;    ///< update_poses() applied
  std::size_t keyframes_moved = 0; ///< keyframes re-binned, over all updates
  std::vector<double> update_ms;   ///< per update: the re-binning time
  std::vector<double> loop_update_ms;  ///< the same for the loop corrections
};

/// Bytes the mapper holds (heap blocks as malloc sizes them).
struct DenseMemory {
  std::size_t keyframes = 0;        ///< keyframes kept
  std::size_t keyframe_bytes = 0;   ///< their clouds (camera frame), voxel handles and entries
  std::size_t map_bytes = 0;        ///< the live and the corrected voxel maps
  std::size_t total() const { return keyframe_bytes + map_bytes; }
  /// What is spilled to disk (compressed bytes of live records): keyframe
  /// clouds and the first loop's maps, and the two maps' blocks.
  std::uint64_t spilled_keyframe_bytes = 0;
  std::uint64_t spilled_map_bytes = 0;
  std::size_t keyframes_spilled = 0;  ///< keyframes whose cloud is only on disk now
};

}  // namespace pvb::slam::dense
