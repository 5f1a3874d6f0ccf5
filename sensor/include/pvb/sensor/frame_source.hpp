#pragma once
#include <optional>
#include <string>

#include "pvb/sensor/rgbd_frame.hpp"

namespace pvb::sensor {

/// A stream of RGB-D frames.  Implementations: TUM folders (harness), the
/// live simulator (sim) and OpenNI2 devices (harness).  Ground truth never
/// travels through this interface.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame, or nullopt at the end of the stream.  Throws IoError for
  /// a stream that cannot continue (unplugged camera, corrupt file).
  virtual std::optional<RgbdFrame> next() = 0;
  /// Frames in the stream when known in advance, else 0.
  virtual std::size_t size_hint() const { return 0; }
  /// Short human-readable description ("tum:/data/seq", "sim:pv_station").
  virtual std::string describe() const = 0;
};

}  // namespace pvb::sensor
