// The motion sensors' vocabulary: the setups' names both ways, the list a
// message gives, and which sensors each setup reads.
#include <gtest/gtest.h>

#include "pvb/sensor/motion.hpp"

namespace pvb::sensor {
namespace {

TEST(SensorSetup, NamesReadBackAndTheListIsTheOneMessagesGive) {
  for (const char* name : {"camera", "camera+imu", "camera+imu+wheels", "camera+accel"})
    EXPECT_STREQ(to_string(*parse_sensor_setup(name)), name);
  for (SensorSetup s : kSensorSetups) EXPECT_EQ(parse_sensor_setup(to_string(s)), s);
  EXPECT_FALSE(parse_sensor_setup("imu"));
  EXPECT_FALSE(parse_sensor_setup("Camera"));
  EXPECT_FALSE(parse_sensor_setup(""));
  EXPECT_EQ(sensor_setup_values(), "camera, camera+imu, camera+imu+wheels or camera+accel");
}

TEST(SensorSetup, WhatEachSetupReads) {
  EXPECT_FALSE(uses_accel(SensorSetup::kCamera));
  EXPECT_FALSE(uses_imu(SensorSetup::kCamera));
  EXPECT_TRUE(uses_accel(SensorSetup::kCameraAccel));
  EXPECT_FALSE(uses_imu(SensorSetup::kCameraAccel));  // no gyroscope
  EXPECT_TRUE(uses_imu(SensorSetup::kCameraImu));
  EXPECT_FALSE(uses_wheels(SensorSetup::kCameraImu));
  EXPECT_TRUE(uses_imu(SensorSetup::kCameraImuWheels));
  EXPECT_TRUE(uses_wheels(SensorSetup::kCameraImuWheels));
}

}  // namespace
}  // namespace pvb::sensor
