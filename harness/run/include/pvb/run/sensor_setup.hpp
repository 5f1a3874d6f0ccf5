#pragma once
// The sensor setup of a run (sensor::SensorSetup) as the commands take it:
// the --sensors and --compare-sensors flags, and the IMU description the
// harness supplies when a TUM folder's accelerometer has none in the
// settings (docs/sensors.md, "The Kinect v1's accelerometer").
#include <string>
#include <utility>
#include <vector>

#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/slam/core/settings.hpp"

namespace pvb::run {

/// `text` as a sensor setup; ConfigError naming `option` and the accepted
/// values (sensor::sensor_setup_values()) otherwise.
sensor::SensorSetup parse_sensors_option(const std::string& text, const std::string& option);

/// "A,B" of --compare-sensors: two different setups, the reference A first.
std::pair<sensor::SensorSetup, sensor::SensorSetup> parse_sensor_pair_option(const std::string& text,
                                                                          const std::string& option);

/// Sets settings->sensors to `setup` and checks that the settings hold the
/// sections it needs (slam::MotionSensorSettings::check: ConfigError otherwise).
void apply_sensor_setup(slam::Settings* settings, sensor::SensorSetup setup);

/// The gravity metric's label of the map frame: "first_camera" for camera
/// alone, "gravity_aligned" for the setups with an accelerometer.
const char* gravity_map_frame(sensor::SensorSetup setup);

/// The Kinect v1's accelerometer as an IMU.* section: readings already in
/// the camera's optical frame (IMU.T_b_c1 the identity), noise from its
/// resolution (dataset/kinect_accelerometer.hpp), 500 Hz.  Sets
/// settings->motion.imu when the settings have no IMU.* keys and `sequence` holds
/// a Kinect accelerometer.txt; returns whether it did.  For camera+accel
/// only (the setups with a gyroscope still need the settings' IMU.*).
/// Settings with IMU.* keep them, but accelerometer.txt is read into the
/// camera's frame (dataset/tum_imu.hpp), so their IMU.T_b_c1 is replaced
/// by the identity for it.
bool supply_kinect_accelerometer(slam::Settings* settings, const std::string& sequence);

/// The same for a Kinect v1's accelerometer whatever the source
/// (freenect://): the description when the settings have no IMU.* keys
/// (returns true), else their IMU.T_b_c1 made the identity.  Callers use
/// it for camera+accel only.
bool supply_kinect_description(slam::Settings* settings);

/// The supplied description's rate and noise density for readings that come
/// at `rate_hz` (the Kinect's are irregular; TUM's come at about 500 Hz).
void kinect_accelerometer_at(double rate_hz, slam::ImuSettings* imu);

/// What `setup` reads of a folder's motion files (none for camera).
dataset::MotionNeeds motion_needs(sensor::SensorSetup setup);

/// Checks the motion readings `reader` holds against the frames a run
/// tracks (the first `max_frames`, 0: all) and `settings`, read from
/// `settings_file` (dataset::check_motion_readings).  `rate_from_data`: the
/// IMU's rate is the supplied description's, not the file's (not checked).
void check_sequence_motion(const dataset::TumSequenceReader& reader, std::size_t max_frames,
                           const slam::Settings& settings, const std::string& settings_file,
                           bool rate_from_data);

/// The mean rate of `imu`'s readings, Hz (0 for fewer than two).
double mean_rate_hz(const std::vector<sensor::ImuSample>& imu);

}  // namespace pvb::run
