#pragma once
// What this project's OpenNI2 driver plug-ins (sim://, freenect://) share:
// the stream (one fixed video mode, no mirroring or cropping, frames raised
// from cv::Mat images) and the driver's error reports, device events and
// list of announced devices.  Header-only: each plug-in compiles its own.
#include <atomic>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <list>

#define XN_NEW(type, ...) new type(__VA_ARGS__)
#define XN_DELETE(p) delete (p)
#include <Driver/OniDriverAPI.h>
#include <opencv2/core.hpp>

namespace pvb::openni {

using oni::driver::StreamBase;

/// Appends one formatted message to OpenNI2's extended error.
/// DriverServices::errorLoggerAppend is variadic, so a va_list must be
/// formatted here first: passed on as an argument it prints garbage.
inline void append_error(oni::driver::DriverServices& services, const char* format, va_list args) {
  char text[1024];
  std::vsnprintf(text, sizeof text, format, args);
  services.errorLoggerAppend("%s", text);
}

/// One stream (depth or colour) of a camera served by a driver plug-in.
class FrameStream : public StreamBase {
 public:
  FrameStream(OniSensorType type, OniVideoMode mode, double fx_px, double fy_px, int max_depth_mm)
      : type_(type), mode_(mode), fx_px_(fx_px), fy_px_(fy_px), max_depth_mm_(max_depth_mm) {}

  OniStatus start() override {
    started_ = true;
    return ONI_STATUS_OK;
  }
  void stop() override { started_ = false; }
  bool started() const { return started_; }
  OniSensorType type() const { return type_; }

  int getRequiredFrameSize() override {
    return mode_.resolutionX * mode_.resolutionY * (type_ == ONI_SENSOR_DEPTH ? 2 : 3);
  }

  OniBool isPropertySupported(int id) override {
    switch (id) {
      case ONI_STREAM_PROPERTY_VIDEO_MODE:
      case ONI_STREAM_PROPERTY_MIRRORING:
      case ONI_STREAM_PROPERTY_CROPPING:
      case ONI_STREAM_PROPERTY_HORIZONTAL_FOV:
      case ONI_STREAM_PROPERTY_VERTICAL_FOV:
        return TRUE;
      case ONI_STREAM_PROPERTY_MAX_VALUE:
      case ONI_STREAM_PROPERTY_MIN_VALUE:
        return type_ == ONI_SENSOR_DEPTH;
      default:
        return FALSE;
    }
  }

  OniStatus getProperty(int id, void* data, int* size) override {
    switch (id) {
      case ONI_STREAM_PROPERTY_VIDEO_MODE:
        return put(data, size, mode_);
      case ONI_STREAM_PROPERTY_MIRRORING:
        return put(data, size, OniBool(FALSE));
      case ONI_STREAM_PROPERTY_CROPPING: {
        // The player drops every frame of a stream without this property.
        OniCropping c{};
        c.enabled = FALSE;
        c.originX = c.originY = 0;
        c.width = mode_.resolutionX;
        c.height = mode_.resolutionY;
        return put(data, size, c);
      }
      case ONI_STREAM_PROPERTY_HORIZONTAL_FOV:
        return put(data, size, static_cast<float>(2.0 * std::atan(0.5 * mode_.resolutionX / fx_px_)));
      case ONI_STREAM_PROPERTY_VERTICAL_FOV:
        return put(data, size, static_cast<float>(2.0 * std::atan(0.5 * mode_.resolutionY / fy_px_)));
      case ONI_STREAM_PROPERTY_MAX_VALUE:
        // The recorder's 16z codec only encodes values up to this one
        // exactly: report the largest value a frame can hold, not the
        // sensor's nominal range (noisy depth goes beyond it).
        if (type_ != ONI_SENSOR_DEPTH) return ONI_STATUS_NOT_SUPPORTED;
        return put(data, size, max_depth_mm_);
      case ONI_STREAM_PROPERTY_MIN_VALUE:
        if (type_ != ONI_SENSOR_DEPTH) return ONI_STATUS_NOT_SUPPORTED;
        return put(data, size, 0);
      default:
        return ONI_STATUS_NOT_SUPPORTED;
    }
  }

  OniStatus setProperty(int id, const void* data, int size) override {
    switch (id) {
      case ONI_STREAM_PROPERTY_VIDEO_MODE: {
        if (size != static_cast<int>(sizeof(OniVideoMode))) return ONI_STATUS_BAD_PARAMETER;
        OniVideoMode m;
        std::memcpy(&m, data, sizeof m);
        const bool same = m.pixelFormat == mode_.pixelFormat && m.resolutionX == mode_.resolutionX &&
                          m.resolutionY == mode_.resolutionY && m.fps == mode_.fps;
        return same ? ONI_STATUS_OK : ONI_STATUS_NOT_SUPPORTED;
      }
      case ONI_STREAM_PROPERTY_MIRRORING: {
        if (size != static_cast<int>(sizeof(OniBool))) return ONI_STATUS_BAD_PARAMETER;
        OniBool on;
        std::memcpy(&on, data, sizeof on);
        return on ? ONI_STATUS_NOT_SUPPORTED : ONI_STATUS_OK;
      }
      case ONI_STREAM_PROPERTY_CROPPING: {
        if (size != static_cast<int>(sizeof(OniCropping))) return ONI_STATUS_BAD_PARAMETER;
        OniCropping c;
        std::memcpy(&c, data, sizeof c);
        return c.enabled ? ONI_STATUS_NOT_SUPPORTED : ONI_STATUS_OK;
      }
      default:
        return ONI_STATUS_NOT_SUPPORTED;
    }
  }

  /// Raises one frame holding `image` (CV_16UC1 depth in mm or CV_8UC3 RGB).
  void deliver(const cv::Mat& image, std::uint64_t t_us, int index) {
    OniFrame* frame = getServices().acquireFrame();
    if (!frame) return;
    const int bpp = type_ == ONI_SENSOR_DEPTH ? 2 : 3;
    const int row_bytes = mode_.resolutionX * bpp;
    auto* dst = static_cast<unsigned char*>(frame->data);
    for (int y = 0; y < mode_.resolutionY; ++y)
      std::memcpy(dst + static_cast<std::size_t>(y) * row_bytes, image.ptr(y),
                  static_cast<std::size_t>(row_bytes));
    frame->dataSize = row_bytes * mode_.resolutionY;
    frame->sensorType = type_;
    frame->timestamp = t_us;
    frame->frameIndex = index;
    frame->videoMode = mode_;
    frame->width = mode_.resolutionX;
    frame->height = mode_.resolutionY;
    frame->croppingEnabled = FALSE;
    frame->cropOriginX = frame->cropOriginY = 0;
    frame->stride = row_bytes;
    raiseNewFrame(frame);
    getServices().releaseFrame(frame);
  }

 private:
  template <typename T>
  static OniStatus put(void* data, int* size, const T& value) {
    if (*size != static_cast<int>(sizeof(T))) return ONI_STATUS_BAD_PARAMETER;
    std::memcpy(data, &value, sizeof(T));
    return ONI_STATUS_OK;
  }

  OniSensorType type_;
  OniVideoMode mode_;
  double fx_px_, fy_px_;
  int max_depth_mm_;
  std::atomic<bool> started_{false};  // read by a live driver's event thread
};

/// The driver half: reports go to OpenNI2's extended error, device events
/// to its listeners; announced devices keep stable addresses (OpenNI2 keeps
/// pointers to their info).
class PluginDriver : public oni::driver::DriverBase {
 public:
  using DriverBase::DriverBase;

  void report(const char* format, ...) {
    va_list args;
    va_start(args, format);
    append_error(getServices(), format, args);
    va_end(args);
  }
  void state_changed(const OniDeviceInfo& info, OniDeviceState state) { deviceStateChanged(&info, state); }
  void disconnected(const OniDeviceInfo& info) { deviceDisconnected(&info); }

 protected:
  /// The announced device with this URI, or null.
  const OniDeviceInfo* announced(const char* uri) const {
    for (const OniDeviceInfo& info : infos_)
      if (std::strcmp(info.uri, uri) == 0) return &info;
    return nullptr;
  }
  /// Tells OpenNI2 of a device (once per URI).
  void announce(const char* uri, const char* vendor, const char* name, std::uint16_t usb_vendor = 0,
                std::uint16_t usb_product = 0) {
    if (announced(uri)) return;
    OniDeviceInfo info{};
    std::snprintf(info.uri, sizeof info.uri, "%s", uri);
    std::snprintf(info.vendor, sizeof info.vendor, "%s", vendor);
    std::snprintf(info.name, sizeof info.name, "%s", name);
    info.usbVendorId = usb_vendor;
    info.usbProductId = usb_product;
    infos_.push_back(info);
    deviceConnected(&infos_.back());
  }

 private:
  std::list<OniDeviceInfo> infos_;
};

}  // namespace pvb::openni
