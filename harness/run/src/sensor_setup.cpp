#include "pvb/run/sensor_setup.hpp"

#include <optional>

#include "pvb/common/error.hpp"
#include "pvb/dataset/tum_imu.hpp"

namespace pvb::run {

slam::SensorSetup parse_sensors_option(const std::string& text, const std::string& option) {
  const std::optional<slam::SensorSetup> setup = slam::parse_sensor_setup(text);
  if (!setup) throw ConfigError("command line", option, kSensorSetupValues, text);
  return *setup;
}

std::pair<slam::SensorSetup, slam::SensorSetup> parse_sensor_pair_option(const std::string& text,
                                                                          const std::string& option) {
  const std::string expected = std::string("two different sensor setups A,B, each ") + kSensorSetupValues;
  const std::size_t comma = text.find(',');
  if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos)
    throw ConfigError("command line", option, expected, text);
  const std::optional<slam::SensorSetup> a = slam::parse_sensor_setup(text.substr(0, comma));
  const std::optional<slam::SensorSetup> b = slam::parse_sensor_setup(text.substr(comma + 1));
  if (!a || !b || *a == *b) throw ConfigError("command line", option, expected, text);
  return {*a, *b};
}

void apply_sensor_setup(slam::Settings* settings, slam::SensorSetup setup) {
  settings->sensors = setup;
  slam::check_sensor_setup(*settings, setup);
}

const char* gravity_map_frame(slam::SensorSetup setup) {
  return slam::uses_accel(setup) ? "gravity_aligned" : "first_camera";
}

bool supply_kinect_accelerometer(slam::Settings* settings, const std::string& sequence) {
  if (settings->imu.present || dataset::tum_imu_source(sequence) != dataset::TumImuSource::kKinectAccelerometer)
    return false;
  using K = dataset::KinectAccelerometer;
  slam::ImuSettings imu;  // NoiseGyro and GyroWalk keep their defaults: there is no gyroscope
  imu.present = true;
  imu.noise.accel_noise_density = K::noise_density();
  imu.noise.accel_random_walk = K::kRandomWalk;
  imu.rate_hz = K::kRateHz;
  imu.T_b_c = geom::SE3d::Identity();  // the readings are already in the camera's optical frame
  settings->imu = imu;
  return true;
}

}  // namespace pvb::run
