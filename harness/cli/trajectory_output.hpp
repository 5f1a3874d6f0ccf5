#pragma once
// The trajectory files the live commands (slam, camera) write at the end:
// TUM lines of T_w_c, with the header ORB-SLAM2's own files lack.
#include <string>
#include <vector>

#include "pvb/common/text.hpp"
#include "pvb/geometry/stamped_pose.hpp"

namespace pvb::cli {

inline void write_tum_file(const std::string& path, const std::vector<geom::StampedPose>& poses) {
  write_file(path, geom::format_tum(poses, "# timestamp tx ty tz qx qy qz qw (T_w_c)\n"));
}

}  // namespace pvb::cli
