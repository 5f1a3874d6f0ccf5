#include "pvb/run/sensor_setup.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "pvb/common/error.hpp"
#include "pvb/dataset/motion_checks.hpp"
#include "pvb/dataset/tum_imu.hpp"

namespace pvb::run {

sensor::SensorSetup parse_sensors_option(const std::string& text, const std::string& option) {
  const std::optional<sensor::SensorSetup> setup = sensor::parse_sensor_setup(text);
  if (!setup) throw ConfigError("command line", option, sensor::sensor_setup_values(), text);
  return *setup;
}

std::pair<sensor::SensorSetup, sensor::SensorSetup> parse_sensor_pair_option(const std::string& text,
                                                                          const std::string& option) {
  const std::string expected = std::string("two different sensor setups A,B, each ") + sensor::sensor_setup_values();
  const std::size_t comma = text.find(',');
  if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos)
    throw ConfigError("command line", option, expected, text);
  const std::optional<sensor::SensorSetup> a = sensor::parse_sensor_setup(text.substr(0, comma));
  const std::optional<sensor::SensorSetup> b = sensor::parse_sensor_setup(text.substr(comma + 1));
  if (!a || !b || *a == *b) throw ConfigError("command line", option, expected, text);
  return {*a, *b};
}

void apply_sensor_setup(slam::Settings* settings, sensor::SensorSetup setup) {
  settings->motion.setup = setup;
  settings->motion.check(settings->source);
}

const char* gravity_map_frame(sensor::SensorSetup setup) {
  return sensor::uses_accel(setup) ? "gravity_aligned" : "first_camera";
}

bool supply_kinect_accelerometer(slam::Settings* settings, const std::string& sequence) {
  if (dataset::tum_imu_source(sequence) != dataset::TumImuSource::kKinectAccelerometer) return false;
  return supply_kinect_description(settings);
}

bool supply_kinect_description(slam::Settings* settings) {
  if (settings->motion.imu.present) {
    settings->motion.imu.T_b_c = geom::SE3d::Identity();  // the Kinect's readings are read into the camera's frame
    return false;
  }
  slam::ImuSettings imu;  // NoiseGyro and GyroWalk keep their defaults: there is no gyroscope
  imu.present = true;
  kinect_accelerometer_at(dataset::KinectAccelerometer::kRateHz, &imu);
  imu.noise.accel_random_walk = dataset::KinectAccelerometer::kRandomWalk;
  imu.T_b_c = geom::SE3d::Identity();  // the readings are already in the camera's optical frame
  settings->motion.imu = imu;
  return true;
}

void kinect_accelerometer_at(double rate_hz, slam::ImuSettings* imu) {
  imu->rate_hz = rate_hz;
  imu->noise.accel_noise_density = dataset::KinectAccelerometer::kReadingNoiseMps2 / std::sqrt(rate_hz);
}

dataset::MotionNeeds motion_needs(sensor::SensorSetup setup) {
  dataset::MotionNeeds n;
  n.accelerometer = sensor::uses_accel(setup);
  n.gyroscope = sensor::uses_imu(setup);
  n.wheels = sensor::uses_wheels(setup);
  n.who = std::string("--sensors ") + sensor::to_string(setup);
  return n;
}

double mean_rate_hz(const std::vector<sensor::ImuSample>& imu) {
  if (imu.size() < 2) return 0.0;
  return static_cast<double>(imu.size() - 1) /
         (static_cast<double>(imu.back().t_ns - imu.front().t_ns) * 1e-9);
}

void check_sequence_motion(const dataset::TumSequenceReader& reader, std::size_t max_frames,
                           const slam::Settings& settings, const std::string& settings_file,
                           bool rate_from_data) {
  const auto& entries = reader.entries();
  if (entries.empty() || reader.motion().empty()) return;
  const std::size_t n = max_frames > 0 ? std::min(max_frames, entries.size()) : entries.size();
  dataset::MotionExpectations e;
  e.first_frame_t_ns = entries.front().t_ns;
  e.last_frame_t_ns = entries[n - 1].t_ns;
  e.settings_file = settings_file;
  if (!rate_from_data) e.imu_rate_hz = settings.motion.imu.rate_hz;
  if (sensor::uses_wheels(settings.motion.setup)) {
    e.encoder_rate_hz = settings.motion.robot.encoder_rate_hz;
    e.ticks_per_rev = settings.motion.robot.drive.ticks_per_rev;
    e.wheel_radius_m = settings.motion.robot.drive.wheel_radius_m;
  }
  dataset::check_motion_readings(reader.motion(), e);
}

}  // namespace pvb::run
