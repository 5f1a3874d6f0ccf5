#pragma once
// The motion readings a run is about to fuse, checked against its frames
// and its settings before any work (docs/inputs.md, "Motion streams"): a
// stream must cover the frames without a long gap, come at the rate the
// settings say, and read what a sensor can read.  Each problem is one
// error naming the file and line (or the settings file and key).
#include <cstdint>
#include <optional>
#include <string>

#include "pvb/dataset/motion_files.hpp"

namespace pvb::dataset {

/// Longest stretch without a reading inside the frames' span, and how far
/// a stream may start after the first frame or end before the last one.
inline constexpr double kMaxMotionGapS = 0.5;
/// A stream's mean rate may differ from its setting by this share.
inline constexpr double kMotionRateTolerance = 0.2;
/// No reading comes faster than this (IMU.Frequency's upper bound).
inline constexpr double kMaxMotionRateHz = 10000;
/// A wheel's rim faster than this between two readings is a damaged count.
inline constexpr double kMaxWheelSpeedMps = 20.0;

/// What the readings must agree with.
struct MotionExpectations {
  std::int64_t first_frame_t_ns = 0;  ///< the first and last frame the run tracks
  std::int64_t last_frame_t_ns = 0;
  std::string settings_file;              ///< named with the keys below
  std::optional<double> imu_rate_hz;      ///< IMU.Frequency
  std::optional<double> encoder_rate_hz;  ///< Robot.EncoderFrequency
  int ticks_per_rev = 0;                  ///< Robot.TicksPerRev and
  double wheel_radius_m = 0;              ///< Robot.WheelRadius: the rims' speed (0: not checked)
};

/// Checks the streams `m` holds (an empty one is not checked: reading
/// decides what must be there).  IoError naming the file and line, or
/// ConfigError naming the settings' key, for the first problem found.
void check_motion_readings(const MotionReadings& m, const MotionExpectations& e);

}  // namespace pvb::dataset
