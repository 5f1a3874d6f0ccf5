#pragma once
// Time is int64 nanoseconds (t_ns) everywhere inside the project; seconds as
// double only at file boundaries (TUM format writes seconds with 6 decimals).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

namespace pvb::geom {

inline std::int64_t seconds_to_ns(double t_s) { return static_cast<std::int64_t>(std::llround(t_s * 1e9)); }
inline double ns_to_seconds(std::int64_t t_ns) { return static_cast<double>(t_ns) * 1e-9; }

/// Time of frame i of a stream at fps frames per second starting at t0_ns,
/// computed from i directly (no accumulated rounding).
inline std::int64_t frame_time_ns(std::int64_t t0_ns, std::int64_t i, double fps) {
  return t0_ns + static_cast<std::int64_t>(std::llround(static_cast<double>(i) * 1e9 / fps));
}

/// "SSSS.ssssss", the TUM timestamp text (microsecond resolution).
inline std::string format_tum_time(std::int64_t t_ns) {
  const std::int64_t us = (t_ns >= 0 ? t_ns + 500 : t_ns - 500) / 1000;
  char buf[48];
  const std::int64_t s = us / 1000000;
  const std::int64_t frac = std::llabs(us % 1000000);
  std::snprintf(buf, sizeof buf, "%s%lld.%06lld", (us < 0 && s == 0) ? "-" : "",
                static_cast<long long>(s), static_cast<long long>(frac));
  return buf;
}

}  // namespace pvb::geom
