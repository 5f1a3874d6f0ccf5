#pragma once
// Degrees and radians, for the code that reads and writes angles in degrees
// (scenario files, the sun and trackers, reports).
#include <cmath>

namespace pvb::geom {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;

inline double sin_deg(double a) { return std::sin(a * kDegToRad); }
inline double cos_deg(double a) { return std::cos(a * kDegToRad); }

}  // namespace pvb::geom
