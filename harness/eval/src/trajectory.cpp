#include "pvb/eval/trajectory.hpp"

#include <sys/stat.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>

#include "pvb/common/text.hpp"
#include "pvb/geometry/time.hpp"

namespace pvb::eval {
namespace {

bool parse_double(const std::string& s, double* out) {
  if (s.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

/// Splits text into lines, keeping 1-based line numbers; skips blank lines and
/// '#' comments.
struct Line {
  int number;
  std::vector<std::string> fields;
};
std::vector<Line> data_lines(const std::string& text) {
  std::vector<Line> out;
  int number = 0;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    ++number;
    const std::string line = text.substr(pos, nl - pos);
    pos = nl + 1;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    out.push_back({number, split_ws(line)});
  }
  return out;
}

void sort_and_check(Trajectory* traj, const std::vector<int>& line_of_pose) {
  std::vector<std::size_t> order(traj->poses.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return traj->poses[a].t_ns < traj->poses[b].t_ns;
  });
  std::vector<geom::StampedPose> sorted;
  sorted.reserve(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k > 0 && traj->poses[order[k]].t_ns == traj->poses[order[k - 1]].t_ns)
      throw IoError(traj->source,
                    "duplicate time stamp " + geom::format_tum_time(traj->poses[order[k]].t_ns) +
                        " (also on line " + std::to_string(line_of_pose[order[k - 1]]) + ")",
                    line_of_pose[order[k]]);
    sorted.push_back(traj->poses[order[k]]);
  }
  traj->poses = std::move(sorted);
}

std::string bad_time(const std::string& field) {
  char range[32];
  std::snprintf(range, sizeof range, "%g", geom::kMaxAbsTimeS);
  return "time stamp '" + field + "' is not a number of seconds in [-" + range + ", " + range + "]";
}

/// "position (X Y Z) is beyond 1e+08 m" from the three fields at `first`.
std::string bad_position(const std::vector<std::string>& fields, std::size_t first, std::size_t step = 1) {
  char limit[32];
  std::snprintf(limit, sizeof limit, "%g", kMaxAbsCoordinateM);
  return "position (" + fields[first] + " " + fields[first + step] + " " + fields[first + 2 * step] +
         ") is beyond " + limit + " m";
}

/// Reads a whole trajectory file; a folder is an error of its own (reading
/// one gives no text, which would read as an empty trajectory).
std::string read_text_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) throw IoError(path, "is a folder, not a file");
  return read_file(path);
}

std::vector<std::int64_t> read_timestamps(const std::string& path) {
  std::vector<std::int64_t> out;
  for (const Line& l : data_lines(read_text_file(path))) {
    std::int64_t t_ns = 0;
    if (l.fields.size() != 1) throw IoError(path, "expected one time stamp in seconds per line", l.number);
    if (!parse_seconds_to_ns(l.fields[0], &t_ns)) throw IoError(path, bad_time(l.fields[0]), l.number);
    out.push_back(t_ns);
  }
  if (out.empty()) throw IoError(path, "empty timestamps file: no time stamps found");
  return out;
}

}  // namespace

bool plausible_position(const geom::Vec3d& p_m) {
  return std::fabs(p_m.x()) <= kMaxAbsCoordinateM && std::fabs(p_m.y()) <= kMaxAbsCoordinateM &&
         std::fabs(p_m.z()) <= kMaxAbsCoordinateM;  // false for NaN too
}

bool parse_seconds_to_ns(const std::string& text, std::int64_t* t_ns) {
  if (text.empty()) return false;
  std::size_t i = 0;
  bool negative = false;
  if (text[i] == '+' || text[i] == '-') negative = text[i++] == '-';
  std::int64_t whole = 0;
  std::int64_t frac_ns = 0;
  int int_digits = 0, frac_digits = 0;
  bool exact = true;
  for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i, ++int_digits) {
    if (int_digits >= 10)
      exact = false;  // beyond ~300 years: leave it to strtod (whole stays < 1e10)
    else
      whole = whole * 10 + (text[i] - '0');
  }
  if (i < text.size() && text[i] == '.') {
    ++i;
    for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i, ++frac_digits) {
      if (frac_digits < 9) frac_ns = frac_ns * 10 + (text[i] - '0');
      else if (frac_digits == 9 && text[i] >= '5') frac_ns += 1;  // round half up at 1 ns
    }
  }
  if (int_digits + frac_digits == 0) return false;
  if (i == text.size() && exact) {
    if (static_cast<double>(whole) > geom::kMaxAbsTimeS) return false;  // whole * 1e9 would leave int64
    for (int d = std::min(frac_digits, 9); d < 9; ++d) frac_ns *= 10;
    const std::int64_t v = whole * 1000000000LL + frac_ns;
    *t_ns = negative ? -v : v;
    return true;
  }
  double t_s = 0.0;
  if (!parse_double(text, &t_s)) return false;
  const std::optional<std::int64_t> checked = geom::checked_seconds_to_ns(t_s);
  if (!checked) return false;
  *t_ns = *checked;
  return true;
}

Trajectory parse_tum(const std::string& text, const std::string& source) {
  Trajectory traj;
  traj.source = source;
  std::vector<int> line_of_pose;
  for (const Line& l : data_lines(text)) {
    if (l.fields.size() != 8)
      throw IoError(source,
                    "expected 8 fields 't tx ty tz qx qy qz qw', got " + std::to_string(l.fields.size()),
                    l.number);
    geom::StampedPose p;
    if (!parse_seconds_to_ns(l.fields[0], &p.t_ns)) throw IoError(source, bad_time(l.fields[0]), l.number);
    double v[7];
    for (int k = 0; k < 7; ++k)
      if (!parse_double(l.fields[k + 1], &v[k]))
        throw IoError(source, "field " + std::to_string(k + 2) + " '" + l.fields[k + 1] +
                                  "' is not a finite number", l.number);
    const geom::Vec3d t(v[0], v[1], v[2]);
    if (!plausible_position(t)) throw IoError(source, bad_position(l.fields, 1), l.number);
    const geom::Quatd q(v[6], v[3], v[4], v[5]);  // (w, x, y, z)
    const double q_norm2 = q.squaredNorm();
    if (!(q_norm2 >= 1e-18 && std::isfinite(q_norm2)))
      throw IoError(source,
                    "quaternion (" + l.fields[4] + " " + l.fields[5] + " " + l.fields[6] + " " + l.fields[7] +
                        ") is zero or too large to normalise",
                    l.number);
    p.T_w_c = geom::make_se3(q, t);
    traj.poses.push_back(p);
    line_of_pose.push_back(l.number);
  }
  if (traj.poses.empty()) throw IoError(source, "empty trajectory: no poses found (only comments or blank lines)");
  sort_and_check(&traj, line_of_pose);
  return traj;
}

Trajectory read_tum(const std::string& path) { return parse_tum(read_text_file(path), path); }

Trajectory read_kitti(const std::string& poses_path, const std::string& timestamps_path) {
  const std::vector<std::int64_t> times_ns = read_timestamps(timestamps_path);
  Trajectory traj;
  traj.source = poses_path;
  std::vector<int> line_of_pose;
  for (const Line& l : data_lines(read_text_file(poses_path))) {
    if (l.fields.size() != 12)
      throw IoError(poses_path, "expected 12 numbers (3x4 [R|t] row-major), got " +
                                    std::to_string(l.fields.size()), l.number);
    double v[12];
    for (int k = 0; k < 12; ++k)
      if (!parse_double(l.fields[k], &v[k]))
        throw IoError(poses_path, "field " + std::to_string(k + 1) + " '" + l.fields[k] +
                                      "' is not a finite number", l.number);
    if (!plausible_position(geom::Vec3d(v[3], v[7], v[11])))
      throw IoError(poses_path, bad_position(l.fields, 3, 4), l.number);
    geom::Mat3d R;
    R << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
    if (std::fabs(R.determinant() - 1.0) > 1e-3 || !(R.transpose() * R).isIdentity(1e-3))
      throw IoError(poses_path, "rotation part is not a rotation matrix", l.number);
    // Project onto SO(3) so 6-decimal files give exact rotations.
    const Eigen::JacobiSVD<geom::Mat3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    R = svd.matrixU() * svd.matrixV().transpose();
    const std::size_t idx = traj.poses.size();
    if (idx >= times_ns.size())
      throw IoError(poses_path, "more poses than time stamps in " + timestamps_path + " (" +
                                    std::to_string(times_ns.size()) + ")", l.number);
    geom::StampedPose p;
    p.t_ns = times_ns[idx];
    p.T_w_c = geom::make_se3(R, geom::Vec3d(v[3], v[7], v[11]));
    traj.poses.push_back(p);
    line_of_pose.push_back(l.number);
  }
  if (traj.poses.empty()) throw IoError(poses_path, "empty trajectory: no poses found");
  if (traj.poses.size() != times_ns.size())
    throw IoError(poses_path, std::to_string(traj.poses.size()) + " poses but " +
                                  std::to_string(times_ns.size()) + " time stamps in " + timestamps_path);
  sort_and_check(&traj, line_of_pose);
  return traj;
}

Trajectory read_trajectory(const std::string& path, TrajectoryFormat format,
                           const std::string& timestamps_path) {
  if (format == TrajectoryFormat::kTum) return read_tum(path);
  if (timestamps_path.empty())
    throw ConfigError("command line", "--timestamps", "a timestamps file for KITTI poses " + path);
  return read_kitti(path, timestamps_path);
}

std::string format_tum(const Trajectory& trajectory) {
  return geom::format_tum(trajectory.poses, "# timestamp tx ty tz qx qy qz qw\n");
}

void write_tum(const std::string& path, const Trajectory& trajectory) {
  write_file(path, format_tum(trajectory));
}

}  // namespace pvb::eval
