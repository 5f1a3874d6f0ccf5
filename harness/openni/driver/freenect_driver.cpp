// An OpenNI2 driver plug-in serving a Kinect v1 through Debian's libfreenect.
//
// URI: freenect://<index> (freenect://0 is the first Kinect).
//
// Two libraries answer to libfreenect.so.0.5, and the plug-in works with both:
// - libfreenect itself (a Kinect on USB): a thread runs libfreenect's event
//   loop; depth comes registered to colour in mm (FREENECT_DEPTH_REGISTERED,
//   libfreenect's registration with the device's factory calibration);
// - fakenect (LD_LIBRARY_PATH=<libdir>/fakenect, FAKENECT_PATH=<dump>), which
//   plays a dump.  Debian's fakenect (0.5.3) passes the raw 11-bit depth
//   through and has no registration, so the plug-in converts and registers
//   it with the same relations (sensor::kinect) and the dump's device.json.
//   Playback is lockstep, like the sim:// device: a frame pair is read only
//   when a reader waits, and each INDEX.txt entry is checked before fakenect
//   reads it (fakenect itself exits the process on a missing file).
// Which one is loaded is told by a symbol only libfreenect exports.
//
// Timestamps are the device's (60 MHz, 32 bits), unwrapped, in microseconds.
// The accelerometer (libfreenect's freenect_get_mks_accel) is served as a
// device property of our own (kinect_accelerometer.hpp): a dump's 'a'
// records at their time stamps; a live Kinect's, read through its motor
// sub-device every kAccelPeriodMs of the event loop, at the device time of
// the last frame plus the host time since.
// No Kinect, a busy Kinect and an unplugged one each end with one error line
// in OpenNI2's extended error (docs/openni.md, "Kinect v1").
#include <dlfcn.h>
#include <libfreenect.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "plugin.hpp"
#include "pvb/dataset/fakenect_dump.hpp"
#include "pvb/openni/kinect_accelerometer.hpp"
#include "pvb/sensor/kinect_v1.hpp"

namespace {

using oni::driver::DeviceBase;
using pvb::openni::FrameStream;
namespace kinect = pvb::sensor::kinect;

constexpr const char* kScheme = "freenect://";
constexpr double kNominalFocalPx = 525.0;  // only for the FOV properties; SLAM takes its own
constexpr int kAccelPeriodMs = 2;          // a live Kinect's accelerometer: at most 500 readings a second
constexpr std::size_t kMaxPendingAccel = 20000;  // readings kept unread (40 s at 500 Hz); older ones go

/// True when the loaded libfreenect is fakenect's playback library.
bool playback_library() {
  void* lib = dlopen("libfreenect.so.0.5", RTLD_LAZY | RTLD_NOLOAD);
  const bool real = lib && dlsym(lib, "freenect_copy_registration");
  if (lib) dlclose(lib);
  return !real;
}

/// 32-bit device ticks -> microseconds since the clock's zero, unwrapped.
class DeviceClock {
 public:
  std::uint64_t to_us(std::uint32_t ticks) {
    if (started_ && ticks < last_) wraps_ += std::uint64_t{1} << 32;
    started_ = true;
    last_ = ticks;
    return static_cast<std::uint64_t>(std::llround(static_cast<double>(wraps_ + ticks) / 60.0));
  }

 private:
  bool started_ = false;
  std::uint32_t last_ = 0;
  std::uint64_t wraps_ = 0;
};

class FreenectDriver;

/// One Kinect (or one fakenect dump): libfreenect's context and device, the
/// two streams, and the thread or lockstep that feeds them.
class FreenectDevice : public DeviceBase {
 public:
  FreenectDevice(FreenectDriver& driver, const OniDeviceInfo& info, freenect_context* ctx,
                 freenect_device* dev, bool playback, bool has_motor);
  ~FreenectDevice() override;

  OniStatus getSensorInfoList(OniSensorInfo** infos, int* count) override {
    *infos = sensors_;
    *count = 2;
    return ONI_STATUS_OK;
  }
  oni::driver::StreamBase* createStream(OniSensorType type) override;
  void destroyStream(oni::driver::StreamBase* stream) override;
  OniBool isImageRegistrationModeSupported(OniImageRegistrationMode mode) override {
    return mode == ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR;
  }
  OniBool isPropertySupported(int id) override {
    return id == ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION || id == pvb::openni::kAccelerometerProperty;
  }
  OniStatus getProperty(int id, void* data, int* size) override;
  OniStatus setProperty(int id, const void* data, int size) override;
  OniStatus tryManualTrigger() override;

  void on_depth(const void* data, std::uint32_t ticks);
  void on_video(const void* data, std::uint32_t ticks);

 private:
  void start_streaming();
  void event_loop();
  void fail(const std::string& message);
  /// Queues libfreenect's current accelerometer reading, stamped t_us.
  void take_accelerometer(std::uint64_t t_us);
  /// Moves the queued readings into `data` (at most *size bytes); *size
  /// becomes the bytes written.
  OniStatus read_accelerometer(void* data, int* size);

  FreenectDriver& driver_;
  OniDeviceInfo info_;
  freenect_context* ctx_;
  freenect_device* dev_;
  bool playback_;
  OniVideoMode depth_mode_{ONI_PIXEL_FORMAT_DEPTH_1_MM, kinect::kWidth, kinect::kHeight, 30};
  OniVideoMode colour_mode_{ONI_PIXEL_FORMAT_RGB888, kinect::kWidth, kinect::kHeight, 30};
  OniSensorInfo sensors_[2] = {{ONI_SENSOR_DEPTH, 1, &depth_mode_}, {ONI_SENSOR_COLOR, 1, &colour_mode_}};
  FrameStream depth_{ONI_SENSOR_DEPTH, depth_mode_, kNominalFocalPx, kNominalFocalPx, kinect::kMaxMetricMm};
  FrameStream colour_{ONI_SENSOR_COLOR, colour_mode_, kNominalFocalPx, kNominalFocalPx, 0};
  std::vector<std::uint16_t> depth_buf_ = std::vector<std::uint16_t>(kinect::kWidth * kinect::kHeight);
  std::vector<std::uint8_t> video_buf_ = std::vector<std::uint8_t>(kinect::kWidth * kinect::kHeight * 3);
  DeviceClock depth_clock_, video_clock_, accel_clock_;
  std::mutex accel_mutex_;
  std::deque<pvb::openni::AccelerometerReading> accel_;  ///< not read yet
  bool has_motor_ = false;  ///< a live Kinect whose motor sub-device (the accelerometer) is open
  std::atomic<std::uint64_t> last_frame_us_{0};      ///< a live Kinect: the last depth frame's device time
  std::atomic<std::int64_t> last_frame_host_us_{0};  ///< and when it came (steady clock)
  int depth_index_ = 0, video_index_ = 0;
  bool streaming_ = false;
  bool finished_ = false;
  // playback
  std::vector<pvb::dataset::FakenectEntry> entries_;
  std::size_t next_entry_ = 0;
  std::optional<kinect::DepthRegistration> registration_;
  // live
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

class FreenectDriver : public pvb::openni::PluginDriver {
 public:
  explicit FreenectDriver(OniDriverServices* services) : PluginDriver(services) {}

  OniStatus tryDevice(const char* uri) override;
  DeviceBase* deviceOpen(const char* uri, const char* mode) override;
  void deviceClose(DeviceBase* device) override { delete static_cast<FreenectDevice*>(device); }
  void shutdown() override {
    if (ctx_) freenect_shutdown(ctx_);
    ctx_ = nullptr;
  }

 private:
  /// libfreenect's context, made on the first freenect:// URI; an error line otherwise.
  std::optional<std::string> open_context();
  static std::optional<int> parse_index(const char* uri);

  freenect_context* ctx_ = nullptr;
  bool playback_ = false;
};

// ---- the driver ------------------------------------------------------------

std::optional<int> FreenectDriver::parse_index(const char* uri) {
  const std::string s(uri ? uri : "");
  if (s.rfind(kScheme, 0) != 0) return std::nullopt;
  const std::string rest = s.substr(std::strlen(kScheme));
  if (rest.empty() || rest.size() > 3 || rest.find_first_not_of("0123456789") != std::string::npos)
    return -1;
  return std::stoi(rest);
}

std::optional<std::string> FreenectDriver::open_context() {
  if (ctx_) return std::nullopt;
  playback_ = playback_library();
  if (playback_) {
    const char* path = std::getenv("FAKENECT_PATH");
    if (!path || !*path)
      return std::string("fakenect's playback libfreenect is loaded but FAKENECT_PATH does not name a dump");
    try {
      pvb::dataset::read_fakenect_index(path);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
  }
  if (freenect_init(&ctx_, nullptr) < 0) {
    ctx_ = nullptr;
    return std::string("no Kinect found: libfreenect cannot open USB (no USB bus, or no permission)");
  }
  freenect_set_log_level(ctx_, FREENECT_LOG_FATAL);
  // The motor sub-device holds the accelerometer (deviceOpen falls back to the camera alone).
  freenect_select_subdevices(ctx_, static_cast<freenect_device_flags>(
                                       FREENECT_DEVICE_CAMERA | (playback_ ? 0 : FREENECT_DEVICE_MOTOR)));
  return std::nullopt;
}

OniStatus FreenectDriver::tryDevice(const char* uri) {
  const std::optional<int> index = parse_index(uri);
  if (!index) return ONI_STATUS_ERROR;  // another driver's URI
  if (*index < 0) {
    report("freenect device: '%s' is not freenect://<index>", uri);
    return ONI_STATUS_ERROR;
  }
  if (const std::optional<std::string> error = open_context()) {
    report("freenect device: %s", error->c_str());
    return ONI_STATUS_ERROR;
  }
  const int count = freenect_num_devices(ctx_);
  if (count <= 0) {
    report("freenect device: no Kinect found (libfreenect sees no Kinect v1 on USB: plugged in, powered, "
           "and readable by this user? docs/openni.md)");
    return ONI_STATUS_ERROR;
  }
  if (*index >= count) {
    report("freenect device: no Kinect %d (libfreenect sees %d)", *index, count);
    return ONI_STATUS_ERROR;
  }
  announce(uri, "Microsoft", playback_ ? "Kinect v1 (fakenect playback)" : "Kinect v1", 0x045e, 0x02ae);
  return ONI_STATUS_OK;
}

DeviceBase* FreenectDriver::deviceOpen(const char* uri, const char* /*mode*/) {
  const OniDeviceInfo* info = announced(uri);
  if (!info) {
    report("freenect device: unknown URI %s", uri);
    return nullptr;
  }
  freenect_device* dev = nullptr;
  bool has_motor = !playback_;
  if (freenect_open_device(ctx_, &dev, *parse_index(uri)) < 0 || !dev) {
    dev = nullptr;
    if (has_motor) {  // a Kinect whose motor will not open still has its camera: no accelerometer then
      has_motor = false;
      freenect_select_subdevices(ctx_, FREENECT_DEVICE_CAMERA);
      if (freenect_open_device(ctx_, &dev, *parse_index(uri)) < 0) dev = nullptr;
    }
  }
  if (!dev) {
    report("freenect device: Kinect %s is busy or cannot be opened (does another program hold it?)", uri);
    return nullptr;
  }
  try {
    return new FreenectDevice(*this, *info, ctx_, dev, playback_, has_motor);
  } catch (const std::exception& e) {
    freenect_close_device(dev);
    report("freenect device: %s", e.what());
    return nullptr;
  }
}

// ---- the device ------------------------------------------------------------

void depth_callback(freenect_device* dev, void* data, std::uint32_t ticks) {
  static_cast<FreenectDevice*>(freenect_get_user(dev))->on_depth(data, ticks);
}
void video_callback(freenect_device* dev, void* data, std::uint32_t ticks) {
  static_cast<FreenectDevice*>(freenect_get_user(dev))->on_video(data, ticks);
}

FreenectDevice::FreenectDevice(FreenectDriver& driver, const OniDeviceInfo& info, freenect_context* ctx,
                               freenect_device* dev, bool playback, bool has_motor)
    : driver_(driver), info_(info), ctx_(ctx), dev_(dev), playback_(playback), has_motor_(has_motor) {
  if (playback_) {
    const std::string dump = std::getenv("FAKENECT_PATH");  // checked by the driver's open_context()
    entries_ = pvb::dataset::read_fakenect_index(dump);
    registration_.emplace(pvb::dataset::read_fakenect_calibration(dump));
  }
  freenect_set_user(dev_, this);
  freenect_set_depth_callback(dev_, depth_callback);
  freenect_set_video_callback(dev_, video_callback);
  // fakenect passes whatever the dump holds: ask it for exactly that.
  const freenect_depth_format depth_format = playback_ ? FREENECT_DEPTH_11BIT : FREENECT_DEPTH_REGISTERED;
  if (freenect_set_depth_mode(dev_, freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, depth_format)) < 0 ||
      freenect_set_video_mode(dev_, freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB)) < 0)
    throw std::runtime_error("the Kinect refused 640x480 depth and RGB at 30 Hz");
  freenect_set_depth_buffer(dev_, depth_buf_.data());
  freenect_set_video_buffer(dev_, video_buf_.data());
}

FreenectDevice::~FreenectDevice() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (streaming_) {
    freenect_stop_depth(dev_);
    freenect_stop_video(dev_);
  }
  freenect_close_device(dev_);
}

oni::driver::StreamBase* FreenectDevice::createStream(OniSensorType type) {
  if (!playback_) start_streaming();  // live frames flow from now on; unstarted streams drop them
  if (type == ONI_SENSOR_DEPTH) return &depth_;
  if (type == ONI_SENSOR_COLOR) return &colour_;
  return nullptr;
}

void FreenectDevice::destroyStream(oni::driver::StreamBase* stream) { static_cast<FrameStream*>(stream)->stop(); }

OniStatus FreenectDevice::getProperty(int id, void* data, int* size) {
  if (id == pvb::openni::kAccelerometerProperty) return read_accelerometer(data, size);
  if (id != ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION) return ONI_STATUS_NOT_SUPPORTED;
  if (*size != static_cast<int>(sizeof(OniImageRegistrationMode))) return ONI_STATUS_BAD_PARAMETER;
  const OniImageRegistrationMode mode = ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR;
  std::memcpy(data, &mode, sizeof mode);
  return ONI_STATUS_OK;
}

OniStatus FreenectDevice::setProperty(int id, const void* data, int size) {
  if (id != ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION) return ONI_STATUS_NOT_SUPPORTED;
  if (size != static_cast<int>(sizeof(OniImageRegistrationMode))) return ONI_STATUS_BAD_PARAMETER;
  OniImageRegistrationMode mode;
  std::memcpy(&mode, data, sizeof mode);
  return isImageRegistrationModeSupported(mode) ? ONI_STATUS_OK : ONI_STATUS_NOT_SUPPORTED;
}

void FreenectDevice::start_streaming() {
  if (streaming_) return;
  streaming_ = true;
  if (freenect_start_depth(dev_) < 0 || freenect_start_video(dev_) < 0) {
    fail("the Kinect would not start streaming (unplugged?)");
    return;
  }
  if (!playback_) thread_ = std::thread([this] { event_loop(); });
}

void FreenectDevice::fail(const std::string& message) {
  finished_ = true;
  driver_.report("freenect device: %s", message.c_str());
  driver_.state_changed(info_, ONI_DEVICE_STATE_ERROR);
}

std::int64_t steady_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void FreenectDevice::take_accelerometer(std::uint64_t t_us) {
  pvb::openni::AccelerometerReading r;
  r.t_us = t_us;
  freenect_get_mks_accel(freenect_get_tilt_state(dev_), &r.x_mps2, &r.y_mps2, &r.z_mps2);
  std::lock_guard<std::mutex> lock(accel_mutex_);
  accel_.push_back(r);
  if (accel_.size() > kMaxPendingAccel) accel_.pop_front();
}

OniStatus FreenectDevice::read_accelerometer(void* data, int* size) {
  constexpr int kBytes = static_cast<int>(sizeof(pvb::openni::AccelerometerReading));
  if (!data || !size || *size < 0) return ONI_STATUS_BAD_PARAMETER;
  std::lock_guard<std::mutex> lock(accel_mutex_);
  int n = 0;
  for (; n < *size / kBytes && !accel_.empty(); ++n) {
    std::memcpy(static_cast<char*>(data) + static_cast<std::size_t>(n) * kBytes, &accel_.front(), kBytes);
    accel_.pop_front();
  }
  *size = n * kBytes;
  return ONI_STATUS_OK;
}

/// Live: libfreenect's events until stopped; an error there is an unplug.
/// Between them, the accelerometer once a kAccelPeriodMs, once frames come
/// (its readings are stamped from theirs).
void FreenectDevice::event_loop() {
  std::int64_t last_accel_us = 0;
  while (!stop_) {
    timeval timeout{0, has_motor_ ? kAccelPeriodMs * 1000 : 100000};  // no accelerometer: no need to wake
    if (freenect_process_events_timeout(ctx_, &timeout) < 0) {
      finished_ = true;
      driver_.report("freenect device: the Kinect stopped answering (unplugged?)");
      driver_.disconnected(info_);
      return;
    }
    const std::int64_t now_us = steady_us();
    if (!has_motor_ || last_frame_host_us_ == 0 || now_us - last_accel_us < kAccelPeriodMs * 1000) continue;
    last_accel_us = now_us;
    if (freenect_update_tilt_state(dev_) < 0) continue;  // one lost reading, not an unplug
    take_accelerometer(last_frame_us_ + static_cast<std::uint64_t>(now_us - last_frame_host_us_));
  }
}

/// Playback, lockstep: reads dump entries until a new depth and colour frame
/// were raised, checking each entry before fakenect reads it.
OniStatus FreenectDevice::tryManualTrigger() {
  if (!playback_ || finished_ || (!depth_.started() && !colour_.started())) return ONI_STATUS_OK;
  start_streaming();
  const int depth_before = depth_index_, video_before = video_index_;
  while (!finished_ && (depth_index_ == depth_before || video_index_ == video_before)) {
    if (next_entry_ == entries_.size()) {
      finished_ = true;
      driver_.state_changed(info_, ONI_DEVICE_STATE_EOF);
      return ONI_STATUS_OK;
    }
    try {
      pvb::dataset::check_fakenect_entry(entries_[next_entry_]);
    } catch (const std::exception& e) {
      fail(e.what());
      return ONI_STATUS_ERROR;
    }
    const pvb::dataset::FakenectEntry& entry = entries_[next_entry_++];
    if (freenect_process_events(ctx_) < 0) {
      fail("fakenect could not play " + entry.path);
      return ONI_STATUS_ERROR;
    }
    if (entry.type == 'a') take_accelerometer(accel_clock_.to_us(entry.timestamp));
  }
  return ONI_STATUS_OK;
}

void FreenectDevice::on_depth(const void* data, std::uint32_t ticks) {
  const std::uint64_t t_us = depth_clock_.to_us(ticks);
  last_frame_us_ = t_us;
  last_frame_host_us_ = steady_us();
  cv::Mat depth_mm;
  if (registration_) {
    const cv::Mat raw(kinect::kHeight, kinect::kWidth, CV_16UC1, const_cast<void*>(data));
    depth_mm = registration_->register_to_colour_mm(raw);
  } else {
    depth_mm = cv::Mat(kinect::kHeight, kinect::kWidth, CV_16UC1, const_cast<void*>(data));
  }
  if (depth_.started()) depth_.deliver(depth_mm, t_us, depth_index_);
  ++depth_index_;
}

void FreenectDevice::on_video(const void* data, std::uint32_t ticks) {
  const std::uint64_t t_us = video_clock_.to_us(ticks);
  const cv::Mat rgb(kinect::kHeight, kinect::kWidth, CV_8UC3, const_cast<void*>(data));
  if (colour_.started()) colour_.deliver(rgb, t_us, video_index_);
  ++video_index_;
}

}  // namespace

ONI_EXPORT_DRIVER(FreenectDriver)
