#include "pvb/openni/openni_source.hpp"

#include <OpenNI.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/dataset/tum_imu.hpp"
#include "pvb/openni/frame_pairer.hpp"
#include "pvb/openni/kinect_accelerometer.hpp"
#include "pvb/openni/oni_file.hpp"
#include "pvb/openni/record_target.hpp"

namespace pvb::openni {
namespace {

/// OpenNI2's extended error as one line.
std::string oni_error() {
  std::string e = ::openni::OpenNI::getExtendedError();
  std::string out;
  for (char c : e) {
    if (c == '\n' || c == '\t' || c == '\r') {
      if (!out.empty() && out.back() != ' ') out += "; ";
    } else {
      out += c;
    }
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
  return out.empty() ? "no details from OpenNI2" : out;
}

const char* pixel_format_name(::openni::PixelFormat f) {
  switch (f) {
    case ::openni::PIXEL_FORMAT_DEPTH_1_MM:
      return "depth 1 mm";
    case ::openni::PIXEL_FORMAT_DEPTH_100_UM:
      return "depth 100 um";
    case ::openni::PIXEL_FORMAT_RGB888:
      return "RGB888";
    case ::openni::PIXEL_FORMAT_YUV422:
      return "YUV422";
    case ::openni::PIXEL_FORMAT_GRAY8:
      return "gray8";
    case ::openni::PIXEL_FORMAT_GRAY16:
      return "gray16";
    case ::openni::PIXEL_FORMAT_JPEG:
      return "JPEG";
    default:
      return "other";
  }
}

/// Sets the mode width x height @ fps with `format` on a live stream.
void set_video_mode(::openni::VideoStream& stream, ::openni::PixelFormat format, const OpenniOptions& o,
                    const std::string& what, const std::string& uri) {
  const ::openni::Array<::openni::VideoMode>& modes = stream.getSensorInfo().getSupportedVideoModes();
  std::string offered;
  for (int i = 0; i < modes.getSize(); ++i) {
    const ::openni::VideoMode& m = modes[i];
    if (m.getResolutionX() == o.width && m.getResolutionY() == o.height && m.getFps() == o.fps &&
        m.getPixelFormat() == format) {
      if (stream.setVideoMode(m) != ::openni::STATUS_OK)
        throw UnavailableError("OpenNI2 device '" + uri + "': cannot set the " + what +
                               " mode: " + oni_error());
      return;
    }
    offered += (offered.empty() ? "" : ", ") + std::to_string(m.getResolutionX()) + "x" +
               std::to_string(m.getResolutionY()) + "@" + std::to_string(m.getFps()) + " " +
               pixel_format_name(m.getPixelFormat());
  }
  throw UnavailableError("OpenNI2 device '" + uri + "': no " + what + " mode " + std::to_string(o.width) +
                         "x" + std::to_string(o.height) + "@" + std::to_string(o.fps) + " " +
                         pixel_format_name(format) + " (offered: " + offered + ")");
}

}  // namespace

struct OpenniSource::Impl : ::openni::OpenNI::DeviceDisconnectedListener,
                            ::openni::OpenNI::DeviceStateChangedListener {
  OpenniOptions options;
  bool initialized = false;
  bool listening = false;
  bool stopped = false;
  bool is_file = false;
  std::string uri;          ///< as OpenNI2 reports it
  std::string source_name;  ///< for messages: the file or the URI
  ::openni::Device device;
  ::openni::VideoStream depth, colour;
  ::openni::Recorder recorder;
  bool recording = false;
  int depth_total = 0, colour_total = 0;  ///< frames in a file
  int depth_read = 0, colour_read = 0;
  std::uint64_t next_index = 0;
  std::atomic<bool> unplugged{false};
  std::atomic<bool> end_of_stream{false};
  std::unique_ptr<FramePairer> pairer;
  bool has_accelerometer = false;             ///< a Kinect v1 on freenect:// (kinect_accelerometer.hpp)
  std::deque<sensor::ImuSample> accel_ahead;  ///< readings after the last frame returned

  std::mutex reason_mutex;
  std::string device_reason;  ///< what the driver said when it gave up (its thread's extended error)

  /// Listeners run on the thread that raised the event, where the driver's
  /// report is still OpenNI2's (thread-local) extended error.
  void keep_reason() {
    std::lock_guard<std::mutex> lock(reason_mutex);
    if (device_reason.empty()) device_reason = oni_error();
  }
  void onDeviceDisconnected(const ::openni::DeviceInfo* info) override {
    if (!info || uri != info->getUri()) return;
    keep_reason();
    unplugged = true;
  }
  void onDeviceStateChanged(const ::openni::DeviceInfo* info, ::openni::DeviceState state) override {
    if (!info || uri != info->getUri()) return;
    if (state == ::openni::DEVICE_STATE_EOF) end_of_stream = true;
    if (state == ::openni::DEVICE_STATE_ERROR || state == ::openni::DEVICE_STATE_NOT_READY) {
      keep_reason();
      unplugged = true;
    }
  }

  void open();
  /// A recording: played in lockstep (a frame when asked for one), its
  /// frame counts and pixel formats checked; returns its colour stream's
  /// frame rate (0 when it gives none).
  int start_playback();
  /// A live camera: the video modes of options, depth registered to colour
  /// where it can be, mirroring off.
  void set_up_camera();
  void start_recorder();
  /// The accelerometer's readings up to and with the frame's time, put into
  /// the colour camera's optical frame as the TUM reader puts them.
  void attach_accelerometer(sensor::RgbdFrame* f);
  std::optional<sensor::RgbdFrame> next();
  std::optional<RecordingSummary> stop();
  bool file_done() const { return is_file && depth_read >= depth_total && colour_read >= colour_total; }
};

void OpenniSource::Impl::open() {
  is_file = !options.oni_path.empty();
  source_name =
      is_file ? options.oni_path : (options.uri.empty() ? std::string("first OpenNI2 device") : options.uri);
  if (is_file) {
    std::ifstream probe(options.oni_path);
    if (!probe) throw IoError(options.oni_path, "no such file (or it cannot be read)");
    check_oni_complete(options.oni_path, scan_oni_file(options.oni_path));
  }
  if (::openni::OpenNI::initialize() != ::openni::STATUS_OK)
    throw UnavailableError("OpenNI2 initialisation failed: " + oni_error());
  initialized = true;
  ::openni::OpenNI::addDeviceDisconnectedListener(this);
  ::openni::OpenNI::addDeviceStateChangedListener(this);
  listening = true;

  const char* open_uri =
      is_file ? options.oni_path.c_str() : (options.uri.empty() ? ::openni::ANY_DEVICE : options.uri.c_str());
  if (device.open(open_uri) != ::openni::STATUS_OK) {
    if (is_file) throw IoError(options.oni_path, "OpenNI2 cannot play it back: " + oni_error());
    throw UnavailableError("cannot open OpenNI2 device '" + source_name + "': " + oni_error());
  }
  uri = device.getDeviceInfo().getUri();

  if (depth.create(device, ::openni::SENSOR_DEPTH) != ::openni::STATUS_OK)
    throw UnavailableError("OpenNI2 device '" + source_name + "' has no depth stream: " + oni_error());
  if (colour.create(device, ::openni::SENSOR_COLOR) != ::openni::STATUS_OK)
    throw UnavailableError("OpenNI2 device '" + source_name + "' has no colour stream: " + oni_error());

  int fps = options.fps;
  if (is_file) {
    const int file_fps = start_playback();
    if (file_fps > 0) fps = file_fps;
  } else {
    set_up_camera();
  }
  pairer = std::make_unique<FramePairer>(500'000'000LL / std::max(1, fps));
  has_accelerometer = !is_file && device.isPropertySupported(kAccelerometerProperty);

  // The recorder first: a live camera starts delivering as soon as its
  // streams start, and every frame read must be in the recording.
  if (!options.record_path.empty()) start_recorder();
  if (depth.start() != ::openni::STATUS_OK)
    throw UnavailableError("OpenNI2 '" + source_name + "': cannot start the depth stream: " + oni_error());
  if (colour.start() != ::openni::STATUS_OK)
    throw UnavailableError("OpenNI2 '" + source_name + "': cannot start the colour stream: " + oni_error());
}

int OpenniSource::Impl::start_playback() {
  ::openni::PlaybackControl* playback = device.getPlaybackControl();
  if (!playback) throw IoError(options.oni_path, "OpenNI2 opened it, but not as a recording");
  // Lockstep: speed -1 makes the player produce a frame only when asked for one.
  playback->setSpeed(-1.0f);
  playback->setRepeatEnabled(false);
  depth_total = playback->getNumberOfFrames(depth);
  colour_total = playback->getNumberOfFrames(colour);
  if (depth_total <= 0 || colour_total <= 0)
    throw IoError(options.oni_path, "the recording reports no frames (depth " +
                                        std::to_string(depth_total) + ", colour " +
                                        std::to_string(colour_total) + ")");
  const ::openni::VideoMode dm = depth.getVideoMode(), cm = colour.getVideoMode();
  if (dm.getPixelFormat() != ::openni::PIXEL_FORMAT_DEPTH_1_MM &&
      dm.getPixelFormat() != ::openni::PIXEL_FORMAT_DEPTH_100_UM)
    throw IoError(options.oni_path, std::string("depth stream is ") +
                                        pixel_format_name(dm.getPixelFormat()) +
                                        ", expected depth in 1 mm or 100 um units");
  if (cm.getPixelFormat() != ::openni::PIXEL_FORMAT_RGB888)
    throw IoError(options.oni_path, std::string("colour stream is ") +
                                        pixel_format_name(cm.getPixelFormat()) + ", expected RGB888");
  return cm.getFps();
}

void OpenniSource::Impl::set_up_camera() {
  set_video_mode(depth, ::openni::PIXEL_FORMAT_DEPTH_1_MM, options, "depth", source_name);
  set_video_mode(colour, ::openni::PIXEL_FORMAT_RGB888, options, "colour", source_name);
  if (device.isImageRegistrationModeSupported(::openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR)) {
    if (device.setImageRegistrationMode(::openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR) != ::openni::STATUS_OK)
      throw UnavailableError("OpenNI2 device '" + source_name +
                             "': cannot register depth to colour: " + oni_error());
  } else {
    std::fprintf(
        stderr,
        "pvbench: warning: %s cannot register depth to colour; depth and colour pixels will not line up\n",
        source_name.c_str());
  }
  for (::openni::VideoStream* s : {&depth, &colour})
    if (s->getMirroringEnabled() && s->setMirroringEnabled(false) != ::openni::STATUS_OK)
      throw UnavailableError("OpenNI2 device '" + source_name +
                             "': cannot turn mirroring off: " + oni_error());
}

void OpenniSource::Impl::start_recorder() {
  const std::string& path = options.record_path;
  // OpenNI2 truncates what is there and crashes when it cannot create the
  // file: it only ever gets a new, empty file that we created.
  check_record_not_on(path, {{options.oni_path, "the recording played back"}});
  create_new_recording_file(path);
  if (recorder.create(path.c_str()) != ::openni::STATUS_OK) {
    std::error_code ec;
    std::filesystem::remove(path, ec);  // still the empty file made above
    throw IoError(path, "cannot record: " + oni_error());
  }
  // Lossless: depth goes through 16z, colour uncompressed, so a replay feeds
  // SLAM the very same pixels.
  if (recorder.attach(depth, false) != ::openni::STATUS_OK ||
      recorder.attach(colour, false) != ::openni::STATUS_OK)
    throw IoError(path, "cannot attach the streams to the recorder: " + oni_error());
  if (recorder.start() != ::openni::STATUS_OK) throw IoError(path, "cannot start recording: " + oni_error());
  recording = true;
  // Recorder::start only queues a message to the recorder's thread; frames
  // arriving before that thread handled it are dropped.  The thread writes a
  // NODE_DATA_BEGIN record per stream when it does, so wait for both before
  // the first frame is produced (frames are produced on demand, see next()).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(options.timeout_ms);
  for (;;) {
    try {
      if (scan_oni_file(path).nodes_begun() >= 2) break;
    } catch (const IoError&) {
      // the recorder's thread has not written the file header yet
    }
    if (std::chrono::steady_clock::now() > deadline)
      throw IoError(
          path, "the OpenNI2 recorder did not start within " + std::to_string(options.timeout_ms) + " ms");
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

void OpenniSource::Impl::attach_accelerometer(sensor::RgbdFrame* f) {
  if (!has_accelerometer) return;
  const Eigen::Matrix3d R_c_k = dataset::kinect_accel_to_optical();
  std::vector<AccelerometerReading> buf(kMaxAccelerometerReadings);
  for (;;) {
    int size = static_cast<int>(buf.size() * sizeof(AccelerometerReading));
    if (device.getProperty(kAccelerometerProperty, buf.data(), &size) != ::openni::STATUS_OK) break;
    const std::size_t n = static_cast<std::size_t>(size) / sizeof(AccelerometerReading);
    for (std::size_t k = 0; k < n; ++k) {
      sensor::ImuSample s;
      s.t_ns = static_cast<std::int64_t>(buf[k].t_us) * 1000;
      s.gyro_radps = sensor::no_gyro();
      s.accel_mps2 = R_c_k * Eigen::Vector3d(buf[k].x_mps2, buf[k].y_mps2, buf[k].z_mps2);
      if (accel_ahead.empty() || s.t_ns > accel_ahead.back().t_ns) accel_ahead.push_back(s);  // in time order
    }
    if (n < buf.size()) break;
  }
  while (!accel_ahead.empty() && accel_ahead.front().t_ns <= f->t_ns) {
    f->imu.push_back(accel_ahead.front());
    accel_ahead.pop_front();
  }
}

std::optional<sensor::RgbdFrame> OpenniSource::Impl::next() {
  if (stopped) return std::nullopt;
  constexpr int kSliceMs = 50;
  int waited_ms = 0;
  for (;;) {
    std::optional<ImagePair> pair = pairer->pop(false);
    if (!pair && (file_done() || end_of_stream)) pair = pairer->pop(true);
    if (pair) {
      sensor::RgbdFrame f;
      f.t_ns = pair->colour.t_ns;
      f.rgb = std::move(pair->colour.image);
      f.depth_m = std::move(pair->depth.image);
      f.index = next_index++;
      f.rgb_name = "frame " + std::to_string(f.index);
      attach_accelerometer(&f);
      return f;
    }
    if (file_done() || end_of_stream) return std::nullopt;
    if (unplugged) {
      std::lock_guard<std::mutex> lock(reason_mutex);
      throw IoError(source_name, "the camera was disconnected after " + std::to_string(next_index) + " frames" +
                                     (device_reason.empty() ? "" : ": " + device_reason));
    }

    if (options.stop_requested && options.stop_requested()) return std::nullopt;  // e.g. Ctrl-C while waiting
    std::vector<::openni::VideoStream*> wait;
    if (!is_file || depth_read < depth_total) wait.push_back(&depth);
    if (!is_file || colour_read < colour_total) wait.push_back(&colour);
    int ready = -1;
    const ::openni::Status rc =
        ::openni::OpenNI::waitForAnyStream(wait.data(), static_cast<int>(wait.size()), &ready, kSliceMs);
    if (rc == ::openni::STATUS_TIME_OUT) {
      waited_ms += kSliceMs;
      if (waited_ms >= options.timeout_ms && !end_of_stream && !unplugged) {
        const std::string what =
            is_file ? "the recording stopped delivering frames (depth " + std::to_string(depth_read) + "/" +
                          std::to_string(depth_total) + ", colour " + std::to_string(colour_read) + "/" +
                          std::to_string(colour_total) + ")"
                    : "no frame for " + std::to_string(options.timeout_ms) + " ms after " +
                          std::to_string(next_index) + " frames (unplugged?)";
        throw IoError(source_name, what);
      }
      continue;
    }
    if (rc != ::openni::STATUS_OK) throw IoError(source_name, "waiting for frames failed: " + oni_error());
    waited_ms = 0;
    ::openni::VideoStream& stream = *wait[static_cast<std::size_t>(ready)];
    ::openni::VideoFrameRef ref;
    if (stream.readFrame(&ref) != ::openni::STATUS_OK || !ref.isValid())
      throw IoError(source_name, "reading a frame failed: " + oni_error());
    const int w = ref.getWidth(), h = ref.getHeight();
    const std::int64_t t_ns = static_cast<std::int64_t>(ref.getTimestamp()) * 1000;
    const auto* data = static_cast<const unsigned char*>(ref.getData());
    const int stride = ref.getStrideInBytes();
    if (&stream == &depth) {
      ++depth_read;
      const ::openni::PixelFormat fmt = ref.getVideoMode().getPixelFormat();
      const float scale_m = fmt == ::openni::PIXEL_FORMAT_DEPTH_100_UM ? 1e-4f : 1e-3f;
      cv::Mat depth_m(h, w, CV_32FC1);
      for (int y = 0; y < h; ++y) {
        const auto* row = reinterpret_cast<const std::uint16_t*>(data + static_cast<std::size_t>(y) * stride);
        float* out = depth_m.ptr<float>(y);
        for (int x = 0; x < w; ++x) out[x] = static_cast<float>(row[x]) * scale_m;
      }
      pairer->push_depth({t_ns, depth_m});
    } else {
      ++colour_read;
      cv::Mat rgb(h, w, CV_8UC3);
      for (int y = 0; y < h; ++y)
        std::memcpy(rgb.ptr(y), data + static_cast<std::size_t>(y) * stride, static_cast<std::size_t>(w) * 3);
      pairer->push_colour({t_ns, rgb});
    }
  }
}

std::optional<RecordingSummary> OpenniSource::Impl::stop() {
  if (stopped) return std::nullopt;
  stopped = true;
  std::optional<RecordingSummary> summary;
  if (recording) {
    // Destroying the recorder stops it, detaches the streams and joins its
    // thread after it wrote every queued frame, the seek tables and the end record.
    recorder.stop();
    recorder.destroy();
    recording = false;
    OniFileSummary s = scan_oni_file(options.record_path);
    // Debian's OpenNI2 2.2 recorder leaves the file about twice as long as
    // its records, the rest zeros (its final truncate extends the file).
    // Trim it, so that a cut-short copy is recognisably truncated.
    if (s.has_end && s.end_bytes < s.size_bytes) {
      std::error_code ec;
      std::filesystem::resize_file(options.record_path, s.end_bytes, ec);
      if (ec) throw IoError(options.record_path, "cannot trim the recording: " + ec.message());
      s = scan_oni_file(options.record_path);
    }
    summary = RecordingSummary{options.record_path, s.frames_of(kOniNodeDepth), s.frames_of(kOniNodeImage)};
  }
  // Colour (created last) goes first, while depth still runs.  Debian's
  // OniFile player thread walks its stream list without a lock until it
  // finds a started stream, and destroying a stream unlinks and deletes it
  // without one: with the first stream still started the walk never reaches
  // the one being deleted.  (Destroying depth first crashed about one .oni
  // replay in ten, at this point, in the player thread.)
  if (colour.isValid()) {
    colour.stop();
    colour.destroy();
  }
  if (depth.isValid()) {
    depth.stop();
    depth.destroy();
  }
  if (device.isValid()) device.close();
  if (listening) {
    ::openni::OpenNI::removeDeviceDisconnectedListener(this);
    ::openni::OpenNI::removeDeviceStateChangedListener(this);
    listening = false;
  }
  if (initialized) {
    ::openni::OpenNI::shutdown();
    initialized = false;
  }
  return summary;
}

OpenniSource::OpenniSource(const OpenniOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  try {
    impl_->open();
  } catch (...) {
    impl_->stop();
    throw;
  }
}

OpenniSource::~OpenniSource() {
  try {
    impl_->stop();
  } catch (...) {
    // a destructor must not throw; stop() explicitly to see errors
  }
}

std::optional<sensor::RgbdFrame> OpenniSource::next() { return impl_->next(); }

std::size_t OpenniSource::size_hint() const {
  return impl_->is_file ? static_cast<std::size_t>(std::min(impl_->depth_total, impl_->colour_total)) : 0;
}

std::string OpenniSource::describe() const {
  return (impl_->is_file ? "oni:" : "openni:") + impl_->source_name;
}

std::optional<RecordingSummary> OpenniSource::stop() { return impl_->stop(); }

std::size_t OpenniSource::dropped_colour() const {
  return impl_->pairer ? impl_->pairer->dropped_colour() : 0;
}
std::size_t OpenniSource::dropped_depth() const { return impl_->pairer ? impl_->pairer->dropped_depth() : 0; }

}  // namespace pvb::openni
