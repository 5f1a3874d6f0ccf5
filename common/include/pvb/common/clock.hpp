#pragma once
// Elapsed wall time on the steady clock, for the timings in stats and
// reports.
#include <chrono>

namespace pvb {

using SteadyClock = std::chrono::steady_clock;

/// Milliseconds from t0 to now.
inline double ms_since(SteadyClock::time_point t0) {
  return std::chrono::duration<double, std::milli>(SteadyClock::now() - t0).count();
}

/// Seconds from t0 to now.
inline double seconds_since(SteadyClock::time_point t0) {
  return std::chrono::duration<double>(SteadyClock::now() - t0).count();
}

}  // namespace pvb
