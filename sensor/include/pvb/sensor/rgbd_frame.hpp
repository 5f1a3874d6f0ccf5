#pragma once
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pvb/sensor/motion.hpp"

namespace pvb::sensor {

/// One registered RGB-D image pair.  A value type: copying shares the pixel
/// buffers (cv::Mat semantics); call clone() on the mats for a deep copy.
struct RgbdFrame {
  std::int64_t t_ns = 0;     ///< capture time of the colour image
  cv::Mat rgb;               ///< CV_8UC3, channel order R, G, B
  cv::Mat depth_m;           ///< CV_32FC1 metres along the optical axis, 0 = invalid
  std::uint64_t index = 0;   ///< position in the stream, from 0
  std::string rgb_name;      ///< file or stream name, for messages (may be empty)
  /// The motion sensors' readings since the previous frame, up to and with
  /// t_ns, oldest first (empty for a source without them).
  std::vector<ImuSample> imu;
  std::vector<WheelTicks> wheel_ticks;
};

}  // namespace pvb::sensor
