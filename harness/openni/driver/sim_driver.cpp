// An OpenNI2 driver plug-in serving the simulator as an RGB-D camera.
//
// URI: sim://<scenario file>[?seed=S&frames=N&gl=egl|osmesa|auto&unplug_after=K&stall_after=K]
//
// Frames are produced on demand (lockstep): OpenNI2 calls the device's
// tryManualTrigger() whenever a reader waits on streams that hold no frame,
// and the device then renders the next frame and raises it on every started
// stream.  So each read gets the next frame, nothing is ever skipped, and a
// run is as deterministic as the simulator.  After the last frame the device
// reports DEVICE_STATE_EOF; with unplug_after=K it reports itself
// disconnected after K frames instead, with stall_after=K it serves nothing
// more after K frames but stays connected (both for testing the harness).
//
// Depth is served in 1 mm units (rounded), colour as RGB888.  The simulator
// renders depth from the colour camera, so the streams are registered by
// construction; both registration modes are accepted.  Ground truth is not
// served: the harness re-derives it from the same scenario (docs/openni.md).
//
// Loaded by OpenNI2 from <folder of libOpenNI2.so.0>/OpenNI2/Drivers, which
// the build stages under build/lib/openni2 (harness/openni/CMakeLists.txt).
#include <cmath>
#include <cstring>
#include <exception>
#include <memory>
#include <string>

#include "plugin.hpp"
#include "pvb/openni/sim_uri.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/sim_frame_source.hpp"

namespace {

using oni::driver::DeviceBase;
using oni::driver::StreamBase;
using pvb::openni::FrameStream;

class SimDriver;

/// The simulated camera: the simulator, its renderer and the two streams.
class SimDevice : public DeviceBase {
 public:
  SimDevice(SimDriver& driver, const OniDeviceInfo& info, const pvb::openni::SimUri& uri);

  OniStatus getSensorInfoList(OniSensorInfo** infos, int* count) override {
    *infos = sensors_;
    *count = 2;
    return ONI_STATUS_OK;
  }

  StreamBase* createStream(OniSensorType type) override {
    if (type == ONI_SENSOR_DEPTH) return &depth_;
    if (type == ONI_SENSOR_COLOR) return &colour_;
    return nullptr;
  }
  void destroyStream(StreamBase* stream) override { static_cast<FrameStream*>(stream)->stop(); }

  OniBool isImageRegistrationModeSupported(OniImageRegistrationMode mode) override {
    return mode == ONI_IMAGE_REGISTRATION_OFF || mode == ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR;
  }
  OniBool isPropertySupported(int id) override { return id == ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION; }
  OniStatus getProperty(int id, void* data, int* size) override {
    if (id != ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION) return ONI_STATUS_NOT_SUPPORTED;
    if (*size != static_cast<int>(sizeof(OniImageRegistrationMode))) return ONI_STATUS_BAD_PARAMETER;
    std::memcpy(data, &registration_, sizeof registration_);
    return ONI_STATUS_OK;
  }
  OniStatus setProperty(int id, const void* data, int size) override {
    if (id != ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION) return ONI_STATUS_NOT_SUPPORTED;
    if (size != static_cast<int>(sizeof(OniImageRegistrationMode))) return ONI_STATUS_BAD_PARAMETER;
    OniImageRegistrationMode m;
    std::memcpy(&m, data, sizeof m);
    if (!isImageRegistrationModeSupported(m)) return ONI_STATUS_NOT_SUPPORTED;
    registration_ = m;
    return ONI_STATUS_OK;
  }

  /// Lockstep: called by OpenNI2 when a reader waits and no frame is queued.
  OniStatus tryManualTrigger() override;

 private:
  SimDriver& driver_;
  OniDeviceInfo info_;
  pvb::openni::SimUri uri_;
  pvb::sim::SimFrameSource source_;
  OniVideoMode depth_mode_, colour_mode_;
  OniSensorInfo sensors_[2];
  FrameStream depth_, colour_;
  OniImageRegistrationMode registration_ = ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR;
  int served_ = 0;
  bool finished_ = false;
};

class SimDriver : public pvb::openni::PluginDriver {
 public:
  explicit SimDriver(OniDriverServices* services) : PluginDriver(services) {}

  OniStatus tryDevice(const char* uri) override {
    if (!uri || !pvb::openni::is_sim_uri(uri)) return ONI_STATUS_ERROR;
    try {
      const pvb::openni::SimUri parsed = pvb::openni::parse_sim_uri(uri);
      pvb::scenes::load_scenario(parsed.scenario_path);  // a bad file fails here, with its line
    } catch (const std::exception& e) {
      report("sim device: %s", e.what());
      return ONI_STATUS_ERROR;
    }
    announce(uri, "PE-SLAM Bench", "simulated RGB-D camera");
    return ONI_STATUS_OK;
  }

  DeviceBase* deviceOpen(const char* uri, const char* /*mode*/) override {
    const OniDeviceInfo* info = announced(uri);
    if (!info) {
      report("sim device: unknown URI %s", uri);
      return nullptr;
    }
    try {
      return new SimDevice(*this, *info, pvb::openni::parse_sim_uri(uri));
    } catch (const std::exception& e) {
      report("sim device: %s", e.what());
      return nullptr;
    }
  }

  void deviceClose(DeviceBase* device) override { delete static_cast<SimDevice*>(device); }
  void shutdown() override {}
};

pvb::scenes::Scenario scenario_for(const pvb::openni::SimUri& uri) {
  pvb::scenes::Scenario s = pvb::scenes::load_scenario(uri.scenario_path);
  if (uri.seed) s.seed = *uri.seed;
  return s;
}

SimDevice::SimDevice(SimDriver& driver, const OniDeviceInfo& info, const pvb::openni::SimUri& uri)
    : driver_(driver),
      info_(info),
      uri_(uri),
      source_(scenario_for(uri), pvb::sim::parse_gl_backend(uri.gl, "gl"), uri.frames),
      depth_mode_{ONI_PIXEL_FORMAT_DEPTH_1_MM, source_.simulator().scenario().camera.width,
                  source_.simulator().scenario().camera.height,
                  static_cast<int>(std::lround(source_.simulator().scenario().camera.fps))},
      colour_mode_{ONI_PIXEL_FORMAT_RGB888, depth_mode_.resolutionX, depth_mode_.resolutionY,
                   depth_mode_.fps},
      sensors_{{ONI_SENSOR_DEPTH, 1, &depth_mode_}, {ONI_SENSOR_COLOR, 1, &colour_mode_}},
      depth_(ONI_SENSOR_DEPTH, depth_mode_, source_.simulator().scenario().camera.fx,
             source_.simulator().scenario().camera.fy, 0xFFFF),
      colour_(ONI_SENSOR_COLOR, colour_mode_, source_.simulator().scenario().camera.fx,
              source_.simulator().scenario().camera.fy, 0) {}

OniStatus SimDevice::tryManualTrigger() {
  if (finished_ || (!depth_.started() && !colour_.started())) return ONI_STATUS_OK;
  if (uri_.unplug_after > 0 && served_ >= uri_.unplug_after) {
    finished_ = true;
    driver_.disconnected(info_);
    return ONI_STATUS_OK;
  }
  if (uri_.stall_after > 0 && served_ >= uri_.stall_after) return ONI_STATUS_OK;  // hung, not gone
  try {
    std::optional<pvb::sensor::RgbdFrame> frame = source_.next();
    if (!frame) {
      finished_ = true;
      driver_.state_changed(info_, ONI_DEVICE_STATE_EOF);
      return ONI_STATUS_OK;
    }
    const std::uint64_t t_us = static_cast<std::uint64_t>((frame->t_ns + 500) / 1000);
    if (depth_.started()) {
      cv::Mat depth_mm;
      frame->depth_m.convertTo(depth_mm, CV_16UC1, 1000.0);  // rounds to the nearest millimetre
      depth_.deliver(depth_mm, t_us, served_);
    }
    if (colour_.started()) colour_.deliver(frame->rgb, t_us, served_);
    ++served_;
  } catch (const std::exception& e) {
    finished_ = true;
    driver_.report("sim device: %s", e.what());
    driver_.state_changed(info_, ONI_DEVICE_STATE_ERROR);
    return ONI_STATUS_ERROR;
  }
  return ONI_STATUS_OK;
}

}  // namespace

ONI_EXPORT_DRIVER(SimDriver)
