#pragma once
// RGB-D frames from an OpenNI2 device (a real camera, the simulator's
// virtual device) or an .oni recording, as a sensor::FrameSource.
//
// Streams: depth in 1 mm units and RGB888 colour at the requested mode
// (640x480 at 30 Hz by default), depth registered to colour, mirroring off.
// Depth and colour are paired by nearest timestamp within half a frame.
// A Kinect v1 on freenect:// also gives its accelerometer (a device
// property, kinect_accelerometer.hpp): each frame carries the readings up
// to its time, in the colour camera's frame (no gyroscope: NaN rates).
// Intrinsics do not come from here: the driver's field of view is ignored,
// SLAM takes them from the settings file.
//
// Frames are read with waitForAnyStream and a time-out, never a blocking
// read: an .oni ends when both streams reached their frame count (OpenNI2's
// player blocks at the end with repeat off), a device ends when it reports
// the EOF state, and a device that stops delivering or is unplugged raises
// IoError.  Recordings (.oni playback, the simulator) are read in lockstep:
// the next frame is produced only when the previous one was read.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "pvb/sensor/frame_source.hpp"

namespace pvb::openni {

struct OpenniOptions {
  /// Device URI ("sim://scenes/pv_station.yaml", a PS1080 URI, ...); empty:
  /// the first device found.  Ignored when oni_path is set.
  std::string uri;
  /// An .oni recording to play back instead of a device.
  std::string oni_path;
  int width = 640;
  int height = 480;
  int fps = 30;
  /// When not empty, record both streams into this .oni while reading.
  std::string record_path;
  /// No frame for this long is an error (camera unplugged, file cut short).
  int timeout_ms = 10000;
  /// Polled while next() waits for frames (every 50 ms at most); when it
  /// returns true, next() returns nullopt at once, as at the end of a
  /// stream (Ctrl-C on a camera that has stopped sending).  May be empty.
  std::function<bool()> stop_requested;
};

/// What a finished recording holds.
struct RecordingSummary {
  std::string path;
  std::uint32_t depth_frames = 0;
  std::uint32_t colour_frames = 0;
};

class OpenniSource : public sensor::FrameSource {
 public:
  /// Opens the device or file, configures and starts both streams and the
  /// recorder.  Throws IoError (missing or truncated file, device that cannot
  /// be opened) or UnavailableError (no device, unsupported video mode).
  explicit OpenniSource(const OpenniOptions& options);
  ~OpenniSource() override;
  OpenniSource(const OpenniSource&) = delete;
  OpenniSource& operator=(const OpenniSource&) = delete;

  std::optional<sensor::RgbdFrame> next() override;
  /// Frame pairs in an .oni file; 0 for a device.
  std::size_t size_hint() const override;
  std::string describe() const override;

  /// Clean stop: finishes the recording (every frame read so far is in the
  /// file when this returns), stops the streams and closes the device.
  /// Idempotent; the destructor calls it.  Returns the recording's summary
  /// when one was made.
  std::optional<RecordingSummary> stop();

  /// Images dropped by pairing so far (colour, depth).
  std::size_t dropped_colour() const;
  std::size_t dropped_depth() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pvb::openni
