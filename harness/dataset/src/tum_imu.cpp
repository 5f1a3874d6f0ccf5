#include "pvb/dataset/tum_imu.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/geometry/time.hpp"

namespace pvb::dataset {
namespace {

/// A finite number, or nullopt.
std::optional<double> number(const std::string& field) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(field.c_str(), &end);
  if (end == field.c_str() || *end != '\0' || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// Data lines of a text file: (1-based line number, the line); '#' comments and blank lines skipped.
std::vector<std::pair<int, std::string>> data_lines(const std::string& path) {
  std::vector<std::pair<int, std::string>> out;
  std::istringstream in(read_file(path));
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') out.emplace_back(n, line);
  }
  return out;
}

/// A whole number within int64, or nullopt (strtoll's overflow included).
std::optional<std::int64_t> whole_number(const std::string& field) {
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(field.c_str(), &end, 10);
  if (end == field.c_str() || *end != '\0' || errno == ERANGE) return std::nullopt;
  return static_cast<std::int64_t>(v);
}

/// IoError unless every value is within `bound` (each axis).
void check_bound(const Eigen::Vector3d& v, double bound, const char* what, const std::string& path, int n) {
  for (int k = 0; k < 3; ++k)
    if (!(std::abs(v[k]) <= bound))
      throw IoError(path,
                    std::string(what) + " " + "xyz"[k] + " = " + format_g(v[k]) + ": expected at most " +
                        format_g(bound) + " in size (no IMU reads more: a damaged line?)",
                    n);
}

/// IoError unless `t_ns` comes after the reading before (line `prev_line`).
void check_after(std::int64_t t_ns, const std::vector<sensor::ImuSample>& before, int prev_line,
                 const std::string& path, int n, const std::string& stamp) {
  if (before.empty() || t_ns > before.back().t_ns) return;
  throw IoError(path,
                "time stamp " + printable(stamp) + " is not after line " + std::to_string(prev_line) +
                    "'s: readings must be in time order, each once (" +
                    (t_ns == before.back().t_ns ? "a repeated" : "an earlier") + " time)",
                n);
}

bool readable(const std::string& path) { return ::access(path.c_str(), R_OK) == 0; }

}  // namespace

Eigen::Matrix3d kinect_accel_to_optical() { return Eigen::Vector3d(-1, -1, 1).asDiagonal(); }

Eigen::Vector3d tum_world_up() { return Eigen::Vector3d(0.0245, -0.0420, 0.9988).normalized(); }

std::vector<sensor::ImuSample> read_tum_accelerometer(const std::string& path, std::vector<int>* lines) {
  static const char* kExpected = "expected 'timestamp ax ay az': a time stamp in seconds and three numbers (m/s^2)";
  const Eigen::Matrix3d R_c_a = kinect_accel_to_optical();
  std::vector<sensor::ImuSample> out;
  int prev_line = 0;
  for (const auto& [n, line] : data_lines(path)) {
    const std::vector<std::string> f = split_ws(line, " \t\r");
    if (f.size() != 4) throw IoError(path, std::string(kExpected) + ", got " + std::to_string(f.size()) + " fields", n);
    const std::optional<double> t_s = number(f[0]);
    const std::optional<std::int64_t> t_ns = t_s ? geom::checked_seconds_to_ns(*t_s) : std::nullopt;
    const std::optional<double> ax = number(f[1]), ay = number(f[2]), az = number(f[3]);
    if (!t_ns || !ax || !ay || !az) throw IoError(path, std::string(kExpected) + ", got '" + printable(line) + "'", n);
    const Eigen::Vector3d a(*ax, *ay, *az);
    check_bound(a, kMaxAccelMps2, "acceleration", path, n);
    check_after(*t_ns, out, prev_line, path, n, f[0]);
    sensor::ImuSample s;
    s.t_ns = *t_ns;
    s.gyro_radps = sensor::no_gyro();
    s.accel_mps2 = R_c_a * a;
    out.push_back(s);
    if (lines) lines->push_back(n);
    prev_line = n;
  }
  return out;
}

std::vector<sensor::ImuSample> read_euroc_imu(const std::string& path, std::vector<int>* lines) {
  static const char* kExpected =
      "expected 't_ns,wx,wy,wz,ax,ay,az': a whole time stamp in ns (within int64) and six numbers";
  std::vector<sensor::ImuSample> out;
  int prev_line = 0;
  for (const auto& [n, line] : data_lines(path)) {
    const std::vector<std::string> f = split_ws(line, ", \t\r");
    std::optional<double> v[6];
    for (int k = 0; k < 6 && f.size() == 7; ++k) v[k] = number(f[k + 1]);
    const std::optional<std::int64_t> t_ns = f.empty() ? std::nullopt : whole_number(f[0]);
    const bool ok = f.size() == 7 && t_ns &&
                    std::all_of(std::begin(v), std::end(v), [](const auto& x) { return x.has_value(); });
    if (!ok) throw IoError(path, std::string(kExpected) + ", got '" + printable(line) + "'", n);
    sensor::ImuSample s;
    s.t_ns = *t_ns;
    s.gyro_radps = Eigen::Vector3d(*v[0], *v[1], *v[2]);
    s.accel_mps2 = Eigen::Vector3d(*v[3], *v[4], *v[5]);
    check_bound(s.gyro_radps, kMaxGyroRadps, "angular rate", path, n);
    check_bound(s.accel_mps2, kMaxAccelMps2, "acceleration", path, n);
    check_after(s.t_ns, out, prev_line, path, n, f[0]);
    out.push_back(s);
    if (lines) lines->push_back(n);
    prev_line = n;
  }
  return out;
}

TumImuSource tum_imu_source(const std::string& dir) {
  if (readable(dir + "/imu0/data.csv")) return TumImuSource::kEurocImu;
  if (readable(dir + "/accelerometer.txt")) return TumImuSource::kKinectAccelerometer;
  return TumImuSource::kNone;
}

std::vector<sensor::ImuSample> read_tum_imu(const std::string& dir) {
  switch (tum_imu_source(dir)) {
    case TumImuSource::kEurocImu:
      return read_euroc_imu(dir + "/imu0/data.csv");
    case TumImuSource::kKinectAccelerometer:
      return read_tum_accelerometer(dir + "/accelerometer.txt");
    case TumImuSource::kNone:
      break;
  }
  return {};
}

}  // namespace pvb::dataset
