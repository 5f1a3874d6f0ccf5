#pragma once
// Pairs depth and colour images by nearest timestamp.  Independent of
// OpenNI2 so that the logic is tested on its own.
//
// A colour image c is paired with the queued depth image nearest in time,
// provided |t_d - t_c| <= tolerance (half a frame period).  The pair is
// decided once a depth image at or after t_c has arrived (no later depth can
// be nearer, the streams are time-ordered) or at the end of the stream.
// Images that can no longer be paired are dropped and counted.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <opencv2/core.hpp>
#include <optional>

namespace pvb::openni {

/// One image with its capture time.
struct TimedImage {
  std::int64_t t_ns = 0;
  cv::Mat image;
};

/// A colour image and the depth image paired with it.
struct ImagePair {
  TimedImage colour;
  TimedImage depth;
};

class FramePairer {
 public:
  /// tolerance_ns: the largest accepted |t_depth - t_colour| (half a period).
  /// max_queue: images kept per stream while waiting for a partner.
  explicit FramePairer(std::int64_t tolerance_ns, std::size_t max_queue = 8);

  /// Images must arrive in time order within each stream.
  void push_depth(TimedImage depth);
  void push_colour(TimedImage colour);

  /// The next decided pair, if any.  With end_of_stream no more images will
  /// come, so the nearest queued depth image is taken as final.
  std::optional<ImagePair> pop(bool end_of_stream = false);

  std::size_t dropped_colour() const { return dropped_colour_; }
  std::size_t dropped_depth() const { return dropped_depth_; }
  std::int64_t tolerance_ns() const { return tolerance_ns_; }

 private:
  std::int64_t tolerance_ns_;
  std::size_t max_queue_;
  std::deque<TimedImage> depth_;
  std::deque<TimedImage> colour_;
  std::size_t dropped_colour_ = 0;
  std::size_t dropped_depth_ = 0;
};

}  // namespace pvb::openni
