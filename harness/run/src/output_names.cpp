#include "pvb/run/output_names.hpp"

namespace pvb::run {

const std::vector<std::string>& motion_output_names() {
  static const std::vector<std::string> names = {"imu0/",    "accelerometer.txt", "wheels.csv",       "odom.txt",
                                                 "imu.yaml", "robot.yaml",        "wheels_truth.csv", "robot_truth.yaml"};
  return names;
}

const std::vector<std::string>& run_output_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {"metrics.json",     "index.html",          "run.log",
                                  "groundtruth.txt",  "CameraTrajectory.txt", "CameraTrajectoryRefined.txt",
                                  "KeyFrameTrajectory.txt", "timing.csv",     "costs.csv", "camera.yaml",
                                  "PointCloud*.ply",  "map_errors.ply",       "*.png",
                                  "*.svg",            "baseline/"};
    n.insert(n.end(), motion_output_names().begin(), motion_output_names().end());
    return n;
  }();
  return names;
}

const std::vector<std::string>& offline_slam_output_names() {
  static const std::vector<std::string> names = {
      "CameraTrajectory.txt", "CameraTrajectoryRefined.txt", "KeyFrameTrajectory.txt", "timing.csv", "costs.csv", "stats.json",
      "Map.txt",              "motion_matches.csv",          "PointCloud*.ply"};
  return names;
}

}  // namespace pvb::run
