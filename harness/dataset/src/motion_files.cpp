#include "pvb/dataset/motion_files.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
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

std::string kalibr_imu_yaml(const sensor::ImuNoise& c, double rate_hz) {
  return "# Kalibr IMU noise model (continuous time), written by pvbench\n"
         "rostopic: /imu0\n"
         "update_rate: " + r(rate_hz) + "\n"
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
         "imu_rate_hz: " + r(c.imu_rate_hz) + "\n"
         "T_b_c: " + matrix_row_major(c.T_b_c) + "\n"
         "T_b_i: " + matrix_row_major(c.T_b_i) + "\n";
}

MotionFilesWriter::MotionFilesWriter(const std::string& dir, const RobotCalibration& c)
    : odometry_(c.drive),
      R_kinect_i_(kinect_accel_to_optical().transpose() * c.T_b_c.linear().transpose() * c.T_b_i.linear()) {
  make_dirs(dir + "/imu0");
  imu_csv_ = open_with(dir + "/imu0/data.csv",
                       "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
                       "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n");
  accel_txt_ = open_with(dir + "/accelerometer.txt",
                         "# accelerometer data\n# file: 'pvbench' (the IMU's specific force in the Kinect v1 "
                         "accelerometer's axes, as TUM's)\n# timestamp ax ay az\n");
  wheels_csv_ = open_with(dir + "/wheels.csv", "#timestamp [ns],left [ticks],right [ticks]\n");
  odom_txt_ = open_with(dir + "/odom.txt", "# wheel odometry of the base in the odometry frame\n"
                                           "# timestamp tx ty tz qx qy qz qw vx vy vz wx wy wz\n");
  write_file(dir + "/imu.yaml", kalibr_imu_yaml(c.imu, c.imu_rate_hz));
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
    const Eigen::Vector3d k = R_kinect_i_ * a;
    accel += geom::format_tum_time(s.t_ns) + " " + g(k.x()) + " " + g(k.y()) + " " + g(k.z()) + "\n";
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

/// A whole number within int64 (no fraction, no exponent), or nullopt.
std::optional<std::int64_t> whole_count(const std::string& cell) {
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(cell.c_str(), &end, 10);
  if (end == cell.c_str() || *end != '\0' || errno == ERANGE) return std::nullopt;
  return static_cast<std::int64_t>(v);
}

bool path_exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

bool path_is_folder(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

/// The IMU's file a run needing `needs` reads in `dir`; IoError when it is
/// not there or not a file.
std::string imu_file_for(const std::string& dir, const MotionNeeds& needs) {
  const std::string imu0 = dir + "/imu0", csv = imu0 + "/data.csv", txt = dir + "/accelerometer.txt";
  if (path_exists(imu0) && !path_is_folder(imu0))
    throw IoError(imu0,
                  "is not a folder; " + needs.who + " reads the IMU from imu0/data.csv (EuRoC's layout)");
  if (path_exists(csv)) {
    require_regular_file(csv);
    return csv;
  }
  if (needs.gyroscope)
    throw IoError(csv,
                  std::string("missing; ") + needs.who + " needs the gyroscope's readings" +
                      (path_exists(txt) ? " (accelerometer.txt holds an accelerometer's only: use --sensors "
                                          "camera+accel)"
                                        : ""));
  if (!path_exists(txt))
    throw IoError(dir, "holds no accelerometer readings (neither imu0/data.csv nor accelerometer.txt); " +
                           needs.who + " needs them");
  require_regular_file(txt);
  return txt;
}

}  // namespace

std::vector<sensor::WheelTicks> read_wheel_ticks(const std::string& path, std::vector<int>* lines) {
  static const char* kExpected =
      "expected 't_ns,left,right': three whole numbers (ns, ticks, ticks) within int64";
  std::vector<sensor::WheelTicks> out;
  std::istringstream in(read_file(path));
  std::string line;
  int prev_line = 0;
  for (int n = 1; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::optional<std::int64_t>> v;
    std::stringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) v.push_back(whole_count(cell));
    if (v.size() != 3 || !v[0] || !v[1] || !v[2])
      throw IoError(path, std::string(kExpected) + ", got '" + printable(line) + "'", n);
    if (!out.empty() && *v[0] <= out.back().t_ns)
      throw IoError(path,
                    "time stamp " + std::to_string(*v[0]) + " is not after line " +
                        std::to_string(prev_line) + "'s: readings must be in time order, each once",
                    n);
    out.push_back({*v[0], *v[1], *v[2]});
    if (lines) lines->push_back(n);
    prev_line = n;
  }
  return out;
}

MotionReadings read_motion_readings(const std::string& dir) {
  MotionReadings m;
  const std::string wheels_file = dir + "/wheels.csv";
  switch (tum_imu_source(dir)) {
    case TumImuSource::kEurocImu:
      m.imu_file = dir + "/imu0/data.csv";
      m.imu = read_euroc_imu(m.imu_file, &m.imu_line);
      break;
    case TumImuSource::kKinectAccelerometer:
      m.imu_file = dir + "/accelerometer.txt";
      m.imu = read_tum_accelerometer(m.imu_file, &m.imu_line);
      break;
    case TumImuSource::kNone:
      break;
  }
  if (::access(wheels_file.c_str(), R_OK) == 0) {
    m.ticks_file = wheels_file;
    m.ticks = read_wheel_ticks(wheels_file, &m.tick_line);
  }
  return m;
}

MotionReadings read_motion_readings(const std::string& dir, const MotionNeeds& needs) {
  MotionReadings m;
  if (needs.accelerometer || needs.gyroscope) {
    m.imu_file = imu_file_for(dir, needs);
    const bool csv = m.imu_file.size() >= 8 && m.imu_file.compare(m.imu_file.size() - 8, 8, "data.csv") == 0;
    m.imu = csv ? read_euroc_imu(m.imu_file, &m.imu_line) : read_tum_accelerometer(m.imu_file, &m.imu_line);
    if (m.imu.empty())
      throw IoError(m.imu_file, "holds no readings (a header only?); " + needs.who + " needs them");
  }
  if (needs.wheels) {
    m.ticks_file = dir + "/wheels.csv";
    if (!path_exists(m.ticks_file))
      throw IoError(m.ticks_file, "missing; " + needs.who + " needs the encoders' readings");
    require_regular_file(m.ticks_file);
    m.ticks = read_wheel_ticks(m.ticks_file, &m.tick_line);
    if (m.ticks.empty())
      throw IoError(m.ticks_file, "holds no readings (a header only?); " + needs.who + " needs them");
  }
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
