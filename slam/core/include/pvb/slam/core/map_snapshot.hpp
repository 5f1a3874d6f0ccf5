#pragma once
// A copy of the sparse map in plain structs: keyframe poses, map points and
// every keypoint measurement that bundle adjustment uses.  `pvbench slam
// --dump-map` writes it, `pvbench map-check` reads it to re-run a global
// bundle adjustment from ground truth (harness/run/map_check.hpp).
//
// Text format, one record per line, '#' starts a comment:
//   K fx fy cx cy bf
//   F keyframe_id t_ns qx qy qz qw tx ty tz        (T_c_w)
//   P point_id x y z reference_keyframe_id         (world frame, m)
//   O keyframe_index point_index u v u_right octave
// Indices count the F and P lines from 0; u, v are undistorted pixels,
// u_right < 0 marks a measurement without depth.
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/optim/optimizer.hpp"

namespace pvb::slam {

class Map;

struct MapSnapshot {
  struct Keyframe {
    std::uint64_t id = 0;
    std::int64_t t_ns = 0;
    geom::SE3d T_c_w = geom::SE3d::Identity();
  };
  struct Point {
    std::uint64_t id = 0;
    Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
    std::uint64_t reference_keyframe_id = 0;
  };
  struct Measurement {
    std::size_t keyframe = 0;  ///< index into keyframes
    std::size_t point = 0;     ///< index into points
    Eigen::Vector2d uv = Eigen::Vector2d::Zero();
    double u_right = -1.0;
    int octave = 0;
  };
  StereoIntrinsics K;
  double scale_factor = 1.2;  ///< pyramid scale: a level-l measurement has sigma scale_factor^l px
  std::vector<Keyframe> keyframes;
  std::vector<Point> points;
  std::vector<Measurement> measurements;
};

/// The good keyframes and points of `map` and their measurements, by id.
/// The caller holds the map lock.
MapSnapshot snapshot_map(const Map& map, const StereoIntrinsics& K, double scale_factor);

/// Writes the text format above.  Throws pvb::IoError when the stream fails.
void write_map_snapshot(const MapSnapshot& snapshot, std::ostream& os, const std::string& name);
/// Reads it; throws pvb::IoError naming `name` and the line of the first
/// malformed record (unknown tag, missing field, index out of range).
MapSnapshot read_map_snapshot(std::istream& is, const std::string& name);

}  // namespace pvb::slam
