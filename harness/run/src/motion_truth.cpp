#include "pvb/run/motion_truth.hpp"

#include <cstdio>

#include "pvb/common/text.hpp"

namespace pvb::run {
namespace {

std::string g(double v) { return format_g(v, 9); }

std::string csv3(const Eigen::Vector3d& v) { return "," + g(v.x()) + "," + g(v.y()) + "," + g(v.z()); }
std::string csv2(const Eigen::Vector2d& v) { return "," + g(v.x()) + "," + g(v.y()); }

std::string robot_truth_yaml(const scenes::Scenario& s, const sim::DriveKinematics& effective) {
  const sensor::DriveDescription nominal = sim::nominal_description(s);
  return "# The robot as built against its description (robot.yaml), written by pvbench.\n"
         "wheel_radius_m: " + format_real(s.robot.wheel_radius_m) + "  # both wheels, as built\n"
         "track_m: " + format_real(s.robot.track_m) + "  # between the wheels' contact points, as built\n"
         "effective_wheel_radius_m: " + format_real(effective.wheel_radius_m) + "  # measured rolling straight\n"
         "effective_track_m: " + format_real(effective.track_m) + "  # measured turning on the spot\n"
         "nominal_wheel_radius_m: " + format_real(nominal.wheel_radius_m) + "\n"
         "nominal_track_m: " + format_real(nominal.track_m) + "\n"
         "radius_error: " + format_real(nominal.wheel_radius_m / s.robot.wheel_radius_m - 1) + "  # nominal / built - 1\n"
         "track_error: " + format_real(nominal.track_m / s.robot.track_m - 1) + "\n" +
         (s.robot.radius_difference != 0
              ? "radius_difference: " + format_real(s.robot.radius_difference) +
                    "  # the right wheel's radius over the left's, less one, as built\n"
              : std::string());
}

}  // namespace

MotionTruthWriter::MotionTruthWriter(const std::string& dir)
    : imu_csv_(dir + "/imu0/truth.csv"), wheels_csv_(dir + "/wheels_truth.csv") {
  imu_csv_.append(
      "#timestamp [ns],w_x [rad s^-1],w_y [rad s^-1],w_z [rad s^-1],a_x [m s^-2],a_y [m s^-2],a_z [m s^-2],"
      "bw_x [rad s^-1],bw_y [rad s^-1],bw_z [rad s^-1],ba_x [m s^-2],ba_y [m s^-2],ba_z [m s^-2]\n");
  wheels_csv_.append(
      "#timestamp [ns],commanded_left [rad s^-1],commanded_right [rad s^-1],wheel_left [rad s^-1],"
      "wheel_right [rad s^-1],ground_left [m s^-1],ground_right [m s^-1],slip_left,slip_right,carried\n");
}

void write_robot_truth(const std::string& dir, const scenes::Scenario& s, const sim::DriveKinematics& effective) {
  write_file(dir + "/robot_truth.yaml", robot_truth_yaml(s, effective));
}

void MotionTruthWriter::write(const std::vector<sim::ImuTruth>& imu, const std::vector<sim::WheelTruth>& wheels) {
  std::string a, b;
  for (const sim::ImuTruth& t : imu)
    a += std::to_string(t.t_ns) + csv3(t.gyro_radps) + csv3(t.accel_mps2) + csv3(t.gyro_bias) +
         csv3(t.accel_bias) + "\n";
  for (const sim::WheelTruth& t : wheels)
    b += std::to_string(t.t_ns) + csv2(t.commanded_radps) + csv2(t.wheel_radps) + csv2(t.ground_mps) +
         csv2(t.slip) + (t.carried ? ",1\n" : ",0\n");
  imu_csv_.append(a);
  wheels_csv_.append(b);
}

}  // namespace pvb::run
