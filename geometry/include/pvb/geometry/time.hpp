#pragma once
// Time is int64 nanoseconds (t_ns) everywhere inside the project; seconds as
// double only at file boundaries (TUM format writes seconds with 6 decimals).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

namespace pvb::geom {

/// Largest |time| in seconds a file may give (about 285 years from 0):
/// t_ns stays inside int64 (which ends at 9.22e9 s) with room to spare.
constexpr double kMaxAbsTimeS = 9.0e9;

/// Seconds to nanoseconds, rounded.  Precondition: |t_s| <= kMaxAbsTimeS
/// (use checked_seconds_to_ns() on values read from outside).
inline std::int64_t seconds_to_ns(double t_s) { return static_cast<std::int64_t>(std::llround(t_s * 1e9)); }
inline double ns_to_seconds(std::int64_t t_ns) { return static_cast<double>(t_ns) * 1e-9; }

/// seconds_to_ns(t_s), or nullopt when t_s is not finite or |t_s| >
/// kMaxAbsTimeS (a double outside int64's range must not be converted).
inline std::optional<std::int64_t> checked_seconds_to_ns(double t_s) {
  if (!(std::fabs(t_s) <= kMaxAbsTimeS)) return std::nullopt;  // NaN fails too
  return seconds_to_ns(t_s);
}

/// a + b, or nullopt when the sum leaves int64's range.
inline std::optional<std::int64_t> checked_add_ns(std::int64_t a, std::int64_t b) {
  std::int64_t sum = 0;
  if (__builtin_add_overflow(a, b, &sum)) return std::nullopt;
  return sum;
}

/// a + b, clamped to int64's range instead of overflowing.
inline std::int64_t saturating_add_ns(std::int64_t a, std::int64_t b) {
  std::int64_t sum = 0;
  if (!__builtin_add_overflow(a, b, &sum)) return sum;
  return b > 0 ? std::numeric_limits<std::int64_t>::max() : std::numeric_limits<std::int64_t>::min();
}

/// Time of frame i of a stream at fps frames per second starting at t0_ns,
/// computed from i directly (no accumulated rounding).
inline std::int64_t frame_time_ns(std::int64_t t0_ns, std::int64_t i, double fps) {
  return t0_ns + static_cast<std::int64_t>(std::llround(static_cast<double>(i) * 1e9 / fps));
}

/// "SSSS.ssssss", the TUM timestamp text (microsecond resolution, halves
/// rounded away from zero); any int64 is formatted without overflow.
inline std::string format_tum_time(std::int64_t t_ns) {
  std::int64_t us = t_ns / 1000;
  const std::int64_t rest_ns = t_ns % 1000;  // same sign as t_ns
  if (rest_ns >= 500) ++us;
  if (rest_ns <= -500) --us;
  char buf[48];
  const std::int64_t s = us / 1000000;
  const std::int64_t frac = std::llabs(us % 1000000);
  std::snprintf(buf, sizeof buf, "%s%lld.%06lld", (us < 0 && s == 0) ? "-" : "",
                static_cast<long long>(s), static_cast<long long>(frac));
  return buf;
}

}  // namespace pvb::geom
