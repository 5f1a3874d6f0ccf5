#pragma once
// Stamped trajectories and their file formats (TUM and KITTI).  This is the
// one place in the project that reads and writes trajectory files: the
// simulator writes ground truth with write_tum(), the SLAM apps write their
// estimates with it, and `pvbench eval` reads both back with read_tum().
#include <cstdint>
#include <string>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/geometry/stamped_pose.hpp"

namespace pvb::eval {

/// Raised when an evaluation cannot be carried out on the given data (too
/// few pairs, nothing associates, a degenerate point set).
class EvalError : public pvb::Error {
 public:
  using pvb::Error::Error;
};

/// A trajectory: poses T_w_c sorted by strictly increasing time t_ns.
struct Trajectory {
  std::vector<geom::StampedPose> poses;  ///< sorted by t_ns, no duplicates
  std::string source;                    ///< file it came from, for messages (may be empty)

  std::size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
  /// First and last time stamp, ns.  Precondition: !empty().
  std::int64_t t_begin_ns() const { return poses.front().t_ns; }
  std::int64_t t_end_ns() const { return poses.back().t_ns; }
};

/// Trajectory file formats understood by read_trajectory().
enum class TrajectoryFormat {
  kTum,    ///< "t tx ty tz qx qy qz qw" per line, t in seconds
  kKitti,  ///< 12 numbers per line (row-major 3x4 [R|t]); times in a separate file
};

/// Largest |coordinate| of a position accepted from a trajectory, metres:
/// beyond any map on Earth (ECEF coordinates stay below 6.4e6 m), and far
/// from where squared distances lose the millimetres ATE is made of.
constexpr double kMaxAbsCoordinateM = 1e8;

/// True when every coordinate is finite and within kMaxAbsCoordinateM.
bool plausible_position(const geom::Vec3d& p_m);

/// Parses a time in seconds written in decimal ("1305031102.175304",
/// "-0.5", "1e-3") into nanoseconds.  Plain decimals are converted exactly
/// (no double rounding); exponent forms go through double.  Returns false
/// when the text is not a number or |t| > geom::kMaxAbsTimeS.
bool parse_seconds_to_ns(const std::string& text, std::int64_t* t_ns);

/// Parses TUM trajectory text.  Fields are separated by spaces, tabs or
/// commas; lines starting with '#' and blank lines are skipped.  Quaternions
/// are normalised.  Throws pvb::IoError naming `source` and the 1-based line
/// for a malformed line (wrong field count, not a number, a time beyond
/// geom::kMaxAbsTimeS, a position beyond kMaxAbsCoordinateM, a zero or
/// overflowing quaternion, non-finite value, duplicate time), and when no
/// pose is found at all.
/// The result is sorted by time.
Trajectory parse_tum(const std::string& text, const std::string& source);

/// Reads a TUM trajectory file (see parse_tum()); throws pvb::IoError when the
/// file cannot be read or is a folder.
Trajectory read_tum(const std::string& path);

/// Reads a KITTI odometry pose file (12 numbers per line, the first three
/// rows of T_w_c row-major) with its timestamps file (one time in seconds per
/// line, '#' comments and blank lines skipped).  Throws pvb::IoError naming
/// the file and line for a malformed line, for empty files and when the two
/// files hold different numbers of entries.
Trajectory read_kitti(const std::string& poses_path, const std::string& timestamps_path);

/// Reads `path` in the given format; `timestamps_path` is required for KITTI
/// (pvb::ConfigError when missing) and ignored for TUM.
Trajectory read_trajectory(const std::string& path, TrajectoryFormat format,
                           const std::string& timestamps_path = {});

/// Formats a trajectory as TUM text: a '#' header line, then one pose per
/// line with microsecond time stamps and 9-decimal values.
std::string format_tum(const Trajectory& trajectory);

/// Writes format_tum(trajectory) to `path`; throws pvb::IoError on failure.
void write_tum(const std::string& path, const Trajectory& trajectory);

}  // namespace pvb::eval
