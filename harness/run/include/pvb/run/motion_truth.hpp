#pragma once
// The truth behind a recording's motion sensors (docs/sensors.md):
// imu0/truth.csv (noise-free readings and the biases in each reading),
// wheels_truth.csv (commanded and actual wheel speeds, ground speed and
// slip per wheel) and robot_truth.yaml (the robot as built against its
// description).
#include <string>
#include <vector>

#include "pvb/common/output_file.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/motion_sensors.hpp"
#include "pvb/sim/robot.hpp"

namespace pvb::run {

/// Writes the truth files frame by frame, flushed after each frame.
class MotionTruthWriter {
 public:
  /// Creates imu0/truth.csv (imu0/ must exist) and wheels_truth.csv in `dir`.
  explicit MotionTruthWriter(const std::string& dir);
  void write(const std::vector<sim::ImuTruth>& imu, const std::vector<sim::WheelTruth>& wheels);

 private:
  OutputFile imu_csv_, wheels_csv_;
};

/// Writes robot_truth.yaml: the robot as built, its effective radius and
/// track (`effective`: Simulator::kinematics), and its description's values.
void write_robot_truth(const std::string& dir, const scenes::Scenario& s, const sim::DriveKinematics& effective);

}  // namespace pvb::run
