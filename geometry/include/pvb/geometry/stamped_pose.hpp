#pragma once
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/geometry/time.hpp"

namespace pvb::geom {

/// A pose at a time: T_w_c maps camera (optical) points into the world.
struct StampedPose {
  std::int64_t t_ns = 0;
  SE3d T_w_c = SE3d::Identity();
};

/// One TUM trajectory line: "t tx ty tz qx qy qz qw" (no newline).
inline std::string format_tum_line(const StampedPose& p) {
  Quatd q(p.T_w_c.linear());
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1.0;  // canonical sign so output is unique
  const Vec3d& t = p.T_w_c.translation();
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s %.9f %.9f %.9f %.9f %.9f %.9f %.9f", format_tum_time(p.t_ns).c_str(),
                t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  return buf;
}

/// A whole TUM file: `header` (with its newline) and one line per pose.
inline std::string format_tum(const std::vector<StampedPose>& poses, const std::string& header) {
  std::string out = header;
  for (const StampedPose& p : poses) {
    out += format_tum_line(p);
    out += '\n';
  }
  return out;
}

}  // namespace pvb::geom
