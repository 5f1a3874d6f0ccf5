#include "pvb/dataset/motion_files.hpp"

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_imu.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/time.hpp"

namespace pvb::dataset {
namespace {

std::string g(double v) { return format_g(v, 9); }
std::string r(double v) { return format_real(v); }

/// A 4 x 4 transform as a YAML flow list of its 16 numbers, row by row.
std::string matrix_row_major(const geom::SE3d& T) {
  std::string out = "[";
  for (int row = 0; row < 4; ++row)
    for (int c = 0; c < 4; ++c) out += (row + c ? ", " : "") + format_real(T.matrix()(row, c));
  return out + "]";
}

OutputFile open_with(const std::string& path, const std::string& header) {
  OutputFile f(path);
  f.append(header);
  return f;
}

}  // namespace

std::string kalibr_imu_yaml(const ImuCalibration& c) {
  return "# Kalibr IMU noise model (continuous time), written by pvbench\n"
         "rostopic: /imu0\n"
         "update_rate: " + r(c.rate_hz) + "\n"
         "accelerometer_noise_density: " + r(c.accel_noise_density) + "  # m/s^2/sqrt(Hz)\n"
         "accelerometer_random_walk: " + r(c.accel_random_walk) + "  # m/s^3/sqrt(Hz)\n"
         "gyroscope_noise_density: " + r(c.gyro_noise_density) + "  # rad/s/sqrt(Hz)\n"
         "gyroscope_random_walk: " + r(c.gyro_random_walk) + "  # rad/s^2/sqrt(Hz)\n";
}

std::string robot_yaml(const RobotCalibration& c) {
  return "# The robot's description (nominal values), written by pvbench.  Base frame b: the middle\n"
         "# of the wheel axle, x forward, z up; camera c: optical (x right, y down, z forward);\n"
         "# IMU i.  T_b_x maps points of frame x into the base (4 x 4, row by row).\n"
         "wheel_radius_m: " + r(c.drive.wheel_radius_m) + "\n"
         "track_m: " + r(c.drive.track_m) + "\n"
         "ticks_per_rev: " + std::to_string(c.drive.ticks_per_rev) + "\n"
         "encoder_rate_hz: " + r(c.encoder_rate_hz) + "\n"
         "imu_rate_hz: " + r(c.imu.rate_hz) + "\n"
         "T_b_c: " + matrix_row_major(c.T_b_c) + "\n"
         "T_b_i: " + matrix_row_major(c.T_b_i) + "\n";
}

MotionFilesWriter::MotionFilesWriter(const std::string& dir, const RobotCalibration& c)
    : odometry_(c.drive) {
  make_dirs(dir + "/imu0");
  imu_csv_ = open_with(dir + "/imu0/data.csv",
                       "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
                       "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n");
  accel_txt_ = open_with(dir + "/accelerometer.txt",
                         "# accelerometer data\n# file: 'pvbench'\n# timestamp ax ay az\n");
  wheels_csv_ = open_with(dir + "/wheels.csv", "#timestamp [ns],left [ticks],right [ticks]\n");
  odom_txt_ = open_with(dir + "/odom.txt", "# wheel odometry of the base in the odometry frame\n"
                                           "# timestamp tx ty tz qx qy qz qw vx vy vz wx wy wz\n");
  write_file(dir + "/imu.yaml", kalibr_imu_yaml(c.imu));
  write_file(dir + "/robot.yaml", robot_yaml(c));
}

void MotionFilesWriter::write(const std::vector<sensor::ImuSample>& imu_samples,
                              const std::vector<sensor::WheelTicks>& ticks) {
  std::string imu, accel, wheels, odom;
  for (const sensor::ImuSample& s : imu_samples) {
    const Eigen::Vector3d& w = s.gyro_radps;
    const Eigen::Vector3d& a = s.accel_mps2;
    imu += std::to_string(s.t_ns) + "," + g(w.x()) + "," + g(w.y()) + "," + g(w.z()) + "," + g(a.x()) + "," +
           g(a.y()) + "," + g(a.z()) + "\n";
    accel += geom::format_tum_time(s.t_ns) + " " + g(a.x()) + " " + g(a.y()) + " " + g(a.z()) + "\n";
  }
  for (const sensor::WheelTicks& t : ticks) {
    wheels += std::to_string(t.t_ns) + "," + std::to_string(t.left) + "," + std::to_string(t.right) + "\n";
    odometry_.add(t);
    const sensor::OdometryState& o = odometry_.state();
    const Eigen::Quaterniond q(Eigen::AngleAxisd(o.yaw_rad, Eigen::Vector3d::UnitZ()));
    odom += geom::format_tum_time(t.t_ns) + " " + g(o.x_m) + " " + g(o.y_m) + " 0 " + g(q.x()) + " " + g(q.y()) +
            " " + g(q.z()) + " " + g(q.w()) + " " + g(o.v_mps) + " 0 0 0 0 " + g(o.w_radps) + "\n";
  }
  imu_csv_.append(imu);
  accel_txt_.append(accel);
  wheels_csv_.append(wheels);
  odom_txt_.append(odom);
}

namespace {

/// The comma-separated numbers of one line, or an IoError naming it.
std::vector<double> csv_numbers(const std::string& line, std::size_t count, const std::string& file, int n,
                                const char* expected) {
  std::vector<double> v;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) {
    char* end = nullptr;
    const double x = std::strtod(cell.c_str(), &end);
    if (end == cell.c_str() || !std::isfinite(x)) throw IoError(file, std::string("expected ") + expected, n);
    v.push_back(x);
  }
  if (v.size() != count) throw IoError(file, std::string("expected ") + expected, n);
  return v;
}

/// Calls f(numbers, line number) for each data line of a CSV file with a '#' header.
template <typename F>
void for_each_csv_line(const std::string& file, std::size_t count, const char* expected, F&& f) {
  std::ifstream in(file);
  if (!in) throw IoError(file, "cannot open");
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    f(csv_numbers(line, count, file, n, expected), n);
  }
}

}  // namespace

MotionReadings read_motion_readings(const std::string& dir) {
  MotionReadings m;
  const std::string wheels_file = dir + "/wheels.csv";
  m.imu = read_tum_imu(dir);
  if (::access(wheels_file.c_str(), R_OK) == 0)
    for_each_csv_line(wheels_file, 3, "t_ns,left,right (3 integers)", [&](const std::vector<double>& v, int n) {
      sensor::WheelTicks t;
      t.t_ns = static_cast<std::int64_t>(v[0]);
      if (!m.ticks.empty() && t.t_ns <= m.ticks.back().t_ns)
        throw IoError(wheels_file, "expected a time after the line before", n);
      t.left = static_cast<std::int64_t>(v[1]);
      t.right = static_cast<std::int64_t>(v[2]);
      m.ticks.push_back(t);
    });
  return m;
}

void round_as_written(sensor::RgbdFrame* frame) {
  const auto round = [](Eigen::Vector3d* v) {
    for (int k = 0; k < 3; ++k) (*v)[k] = std::strtod(g((*v)[k]).c_str(), nullptr);
  };
  for (sensor::ImuSample& s : frame->imu) {
    round(&s.gyro_radps);
    round(&s.accel_mps2);
  }
}

void attach_readings(const MotionReadings& m, std::int64_t t0_ns, std::int64_t t1_ns, sensor::RgbdFrame* frame) {
  const auto in_range = [&](const auto& v, auto* out) {
    auto it = std::upper_bound(v.begin(), v.end(), t0_ns, [](std::int64_t t, const auto& r) { return t < r.t_ns; });
    for (; it != v.end() && it->t_ns <= t1_ns; ++it) out->push_back(*it);
  };
  in_range(m.imu, &frame->imu);
  in_range(m.ticks, &frame->wheel_ticks);
}

}  // namespace pvb::dataset
