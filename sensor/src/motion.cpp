#include "pvb/sensor/motion.hpp"

namespace pvb::sensor {

const char* to_string(SensorSetup s) {
  switch (s) {
    case SensorSetup::kCamera: return "camera";
    case SensorSetup::kCameraImu: return "camera+imu";
    case SensorSetup::kCameraImuWheels: return "camera+imu+wheels";
    case SensorSetup::kCameraAccel: return "camera+accel";
  }
  return "?";
}

std::optional<SensorSetup> parse_sensor_setup(std::string_view text) {
  for (SensorSetup s : kSensorSetups)
    if (text == to_string(s)) return s;
  return std::nullopt;
}

std::string sensor_setup_values() {
  std::string out;
  for (std::size_t i = 0; i < kSensorSetups.size(); ++i)
    out += (i == 0 ? "" : i + 1 == kSensorSetups.size() ? " or " : ", ") + std::string(to_string(kSensorSetups[i]));
  return out;
}

bool uses_imu(SensorSetup s) { return s == SensorSetup::kCameraImu || s == SensorSetup::kCameraImuWheels; }
bool uses_accel(SensorSetup s) { return s != SensorSetup::kCamera; }
bool uses_wheels(SensorSetup s) { return s == SensorSetup::kCameraImuWheels; }

}  // namespace pvb::sensor
