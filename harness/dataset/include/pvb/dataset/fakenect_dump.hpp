#pragma once
// fakenect dumps: the folder libfreenect's fakenect-record writes and its
// fakenect library plays back (Debian libfreenect0.5, README.fakenect).
//
//   INDEX.txt           one file name per line, in playback order
//   r-<time>-<ts>.ppm   colour: "P6 640 480 255\n" + 640x480 RGB bytes
//   d-<time>-<ts>.pgm   depth: "P5 640 480 65535\n" + 640x480 raw 11-bit
//                       disparities, uint16 in the host's (little-endian) order
//   a-<time>-<ts>.dump  accelerometer: a freenect_raw_tilt_state (12 bytes), counts
//                       (819 a g) in the Kinect accelerometer's axes (tum_imu.hpp)
//
// <time> is the recording's wall clock in seconds (fakenect sleeps the
// differences), <ts> the device's 32-bit timestamp (60 MHz clock).
//
// pvbench adds files fakenect ignores: device.json (the depth calibration,
// sensor::kinect::Calibration), groundtruth.txt (TUM, stamped with the
// device clock), camera.yaml (ORB-SLAM2 settings, depth in mm).
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pvb/common/output_file.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/sensor/kinect_v1.hpp"

namespace pvb::dataset {

inline constexpr std::size_t kTiltStateBytes = 12;  ///< sizeof(freenect_raw_tilt_state) on x86-64 and arm64

/// The device clock's 32-bit tick count for a stream time (wraps after ~71.6 s).
std::uint32_t kinect_ticks(std::int64_t t_ns);

/// Writes a dump frame by frame; INDEX.txt and groundtruth.txt are flushed
/// as they grow, so an interrupted recording is a valid shorter dump.
class FakenectWriter {
 public:
  FakenectWriter(const std::string& dir, const sensor::kinect::Calibration& cal);
  /// rgb: CV_8UC3 RGB 640x480; raw_ir: CV_16UC1 640x480; gravity_c: the
  /// accelerometer's reading (specific force, m/s^2) in the colour camera's
  /// optical axes, written in the Kinect accelerometer's (x and y negated).
  void write(std::int64_t t_ns, const cv::Mat& rgb, const cv::Mat& raw_ir, const Eigen::Vector3d& gravity_c,
             const geom::SE3d& T_w_c);
  int frames_written() const { return frames_; }

 private:
  std::string add_file(char type, std::int64_t t_ns, const char* ext, const std::string& header,
                       const void* data, std::size_t n);

  std::string dir_;
  OutputFile index_, gt_;
  int frames_ = 0;
};

/// One INDEX.txt line, checked.
struct FakenectEntry {
  char type = 0;            ///< 'r', 'd' or 'a'
  double record_time_s = 0;
  std::uint32_t timestamp = 0;
  std::string path;         ///< the file, folder included
  int line = 0;             ///< in INDEX.txt
};

/// Reads INDEX.txt of `dir` and checks every line's name (type, time,
/// timestamp).  IoError naming INDEX.txt and the line otherwise.
std::vector<FakenectEntry> read_fakenect_index(const std::string& dir);

/// Checks the file of one entry the way fakenect will read it: it exists,
/// has a one-line PPM/PGM header of 640x480 (maxval 255 / 65535) and exactly
/// the bytes that header announces; an accelerometer record is 12 bytes.
/// IoError naming the file and what is wrong otherwise.
void check_fakenect_entry(const FakenectEntry& e);

/// Reads the depth calibration from device.json of `dir`; the defaults when
/// there is none.  IoError naming the file and field when it is malformed.
sensor::kinect::Calibration read_fakenect_calibration(const std::string& dir);

}  // namespace pvb::dataset
