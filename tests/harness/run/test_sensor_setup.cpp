// The sensor flags and the Kinect accelerometer's description (run/sensor_setup.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/run/sensor_setup.hpp"

using namespace pvb;

TEST(SensorSetup, FlagValuesAndOneErrorNamingTheFlag) {
  EXPECT_EQ(run::parse_sensors_option("camera+accel", "--sensors"), sensor::SensorSetup::kCameraAccel);
  try {
    run::parse_sensors_option("imu", "--sensors");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(),
                 "command line: --sensors: expected camera, camera+imu, camera+imu+wheels or camera+accel, got imu");
  }
  const auto pair = run::parse_sensor_pair_option("camera,camera+imu+wheels", "--compare-sensors");
  EXPECT_EQ(pair.first, sensor::SensorSetup::kCamera);
  EXPECT_EQ(pair.second, sensor::SensorSetup::kCameraImuWheels);
  for (const char* bad : {"camera", "camera,camera", "camera,gps", "camera,camera+imu,camera+accel", ""})
    EXPECT_THROW(run::parse_sensor_pair_option(bad, "--compare-sensors"), ConfigError) << bad;
}

TEST(SensorSetup, TheKinectAccelerometerIsSuppliedOnlyWhereItIsNeededAndThere) {
  const std::string dir = ::testing::TempDir() + "pvb_sensor_setup";
  std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str());
  slam::Settings s;
  s.source = "camera.yaml";
  EXPECT_FALSE(run::supply_kinect_accelerometer(&s, dir));  // no accelerometer.txt
  write_file(dir + "/accelerometer.txt", "1.0 0 -9.8 0\n");
  ASSERT_TRUE(run::supply_kinect_accelerometer(&s, dir));
  EXPECT_TRUE(s.motion.imu.present);
  EXPECT_NEAR(s.motion.imu.noise.accel_noise_density, 0.104 / std::sqrt(500.0), 1e-12);
  EXPECT_TRUE(s.motion.imu.T_b_c.isApprox(geom::SE3d::Identity()));
  run::apply_sensor_setup(&s, sensor::SensorSetup::kCameraAccel);  // passes the check now
  EXPECT_EQ(s.motion.setup, sensor::SensorSetup::kCameraAccel);
  EXPECT_FALSE(run::supply_kinect_accelerometer(&s, dir));  // the settings' own IMU.* stay
  EXPECT_THROW(run::apply_sensor_setup(&s, sensor::SensorSetup::kCameraImuWheels), ConfigError);  // no Robot.*
  EXPECT_STREQ(run::gravity_map_frame(sensor::SensorSetup::kCamera), "first_camera");
}
