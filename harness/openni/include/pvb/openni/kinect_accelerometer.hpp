#pragma once
// The Kinect v1's accelerometer, from the freenect:// driver plug-in to
// OpenniSource.  OpenNI2 has no stream for it, so the plug-in serves it as a
// device property of its own: reading the property takes the readings
// gathered since the last read (docs/openni.md, "The accelerometer").
// Header-only and free of OpenNI2: the plug-in and the source share it.
#include <cstdint>

namespace pvb::openni {

/// The device property ("PVB" and 1, clear of OpenNI2's own ids).
inline constexpr int kAccelerometerProperty = 0x50564201;

/// One reading as libfreenect gives it (freenect_get_mks_accel: counts /
/// 819 x 9.80665), in the Kinect accelerometer's axes, which are TUM's
/// (dataset::kinect_accel_to_optical), stamped on the device's clock.
struct AccelerometerReading {
  std::uint64_t t_us = 0;  ///< microseconds, as the frames' time stamps
  double x_mps2 = 0, y_mps2 = 0, z_mps2 = 0;
};

/// At most this many readings travel in one read of the property.
inline constexpr int kMaxAccelerometerReadings = 512;

}  // namespace pvb::openni
