#pragma once
// TUM RGB-D sequence folders: rgb/*.png (8-bit), depth/*.png (16-bit,
// metres = value / factor, 0 = invalid), rgb.txt, depth.txt,
// groundtruth.txt, associations.txt.  The layout ORB-SLAM2 and the TUM tools
// read unchanged.
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "pvb/common/output_file.hpp"
#include "pvb/dataset/motion_files.hpp"
#include "pvb/dataset/tum_imu.hpp"
#include "pvb/geometry/pinhole.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/sensor/depth_encoding.hpp"
#include "pvb/sensor/frame_source.hpp"

namespace pvb::dataset {

/// ORB-SLAM2 RGB-D settings (the Camera.* / ThDepth / DepthMapFactor /
/// ORBextractor.* keys of its YAML files).
struct OrbSlamSettings {
  geom::PinholeIntrinsics K;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  double fps = 30;
  double bf = 40.0;        ///< baseline (m) x fx
  int rgb_order = 1;       ///< Camera.RGB: 1 = RGB, 0 = BGR
  double th_depth = 40.0;  ///< close/far threshold in baselines
  double depth_map_factor = sensor::kTumDepthFactor;
  int n_features = 1000;
  double scale_factor = 1.2;
  int n_levels = 8;
  int ini_th_fast = 20;
  int min_th_fast = 7;
  /// pvbench's KeyFrame.minTrackedClose; written only when set (ORB-SLAM2
  /// ignores keys it does not know).
  std::optional<int> kf_min_tracked_close;
  /// pvbench's KeyFrame.refOverlap; written only when set.
  std::optional<double> kf_ref_overlap;
  /// pvbench's System.Sensors; written only when set.
  std::optional<sensor::SensorSetup> sensors;
  /// The IMU (ORB-SLAM3's IMU.* keys) and the robot (pvbench's Robot.*
  /// keys); written only when set (ORB-SLAM2 ignores both).
  std::optional<RobotCalibration> robot;
};

/// The settings as the text of an OpenCV FileStorage YAML file ORB-SLAM2 reads.
std::string orbslam_settings_text(const OrbSlamSettings& s);
/// Writes that text to `path`.
void write_orbslam_settings(const std::string& path, const OrbSlamSettings& s);

/// Writes a sequence frame by frame; every text file is flushed after each
/// frame so an interrupted run keeps what it wrote.
class TumSequenceWriter {
 public:
  /// Creates `dir` (and parents), rgb/ and depth/.  Throws IoError when it cannot.
  TumSequenceWriter(const std::string& dir, double depth_factor = sensor::kTumDepthFactor,
                    const std::string& source = "pvbench");
  /// Writes one frame and its ground-truth camera pose.
  void write(const sensor::RgbdFrame& frame, const geom::SE3d& T_w_c);
  int frames_written() const { return frames_; }
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
  double depth_factor_;
  OutputFile rgb_txt_, depth_txt_, gt_txt_, assoc_txt_;
  int frames_ = 0;
};

/// Creates a folder and its parents; throws IoError naming it on failure.
void make_dirs(const std::string& dir);

/// Reads a TUM RGB-D folder as a frame source.  Pairs come from
/// associations.txt when present (rgb.txt and depth.txt are then not read),
/// else rgb.txt and depth.txt are associated one to one by nearest timestamp
/// within max_diff_s.  Every time stamp must be a number of seconds within
/// +-geom::kMaxAbsTimeS.  associations.txt is tracked in its own order, so
/// its colour time stamps must increase (IoError naming the line otherwise);
/// rgb.txt and depth.txt are sorted by time (a repeated stamp is an error).
/// The motion readings (imu0/data.csv, else a Kinect's accelerometer.txt:
/// tum_imu.hpp; and wheels.csv) are read by the constructor; next() attaches to each frame
/// those since the frame it returned before (up to and with its t_ns; the
/// first frame gets every reading up to its time, a skipped frame's go to
/// the next one).
class TumSequenceReader : public sensor::FrameSource {
 public:
  struct Entry {
    std::int64_t t_ns = 0;  ///< rgb time stamp
    std::string rgb;        ///< path relative to the folder
    std::int64_t depth_t_ns = 0;
    std::string depth;
  };
  /// `motion`: the motion files a run needs (read_motion_readings: only
  /// those, each refused when missing or empty); without it, every motion
  /// file the folder holds.
  explicit TumSequenceReader(const std::string& dir, double depth_factor = sensor::kTumDepthFactor,
                             double max_diff_s = 0.02,
                             const std::optional<MotionNeeds>& motion = std::nullopt);
  /// The next frame whose images load; a frame whose image is missing or
  /// damaged is skipped with one warning line on stderr.  nullopt at the
  /// end, and once more than max_skipped() frames were skipped
  /// (skip_limit_reached() tells the two apart).
  std::optional<sensor::RgbdFrame> next() override;
  /// Frames next() may skip before it stops; default max(10, frames / 10).
  std::size_t max_skipped() const { return max_skipped_; }
  void set_max_skipped(std::size_t n) { max_skipped_ = n; }
  /// True once more than max_skipped() frames were skipped.
  bool skip_limit_reached() const { return skipped_ > max_skipped_; }
  std::size_t size_hint() const override { return entries_.size(); }
  std::string describe() const override { return "tum:" + dir_; }
  const std::vector<Entry>& entries() const { return entries_; }
  /// Loads frame i (throws IoError for a missing, damaged or unreadable
  /// image), with the motion readings since frame i - 1.
  sensor::RgbdFrame load(std::size_t i) const;
  /// Number of frames skipped because an image was missing or corrupt.
  std::size_t skipped() const { return skipped_; }
  /// Every motion reading of the folder, by time (empty without any).
  const MotionReadings& motion() const { return motion_; }

 private:
  std::string dir_;
  double depth_factor_;
  std::vector<Entry> entries_;
  MotionReadings motion_;             ///< the IMU's (tum_imu.hpp) and the encoders' readings, when there
  std::int64_t last_delivered_t_ns_;  ///< the last frame next() returned (readings up to it went with it)
  std::size_t pos_ = 0;
  std::size_t skipped_ = 0;
  std::size_t max_skipped_ = 0;
};

/// The files of a TUM RGB-D folder that a reader of it may read: its lists
/// (associations.txt, rgb.txt, depth.txt, groundtruth.txt), meta.json,
/// camera.yaml, the motion readings (imu0/data.csv, else accelerometer.txt;
/// wheels.csv) and the images in rgb/ and depth/.  Other files in the
/// folder (a map saved beside the sequence) are not among them.
std::vector<std::string> sequence_files(const std::string& dir);

/// Parses a TUM list file (rgb.txt / depth.txt): "t path" lines, # comments.
/// The result is sorted by time.  Throws IoError naming the file and line for
/// a malformed line, a time stamp that is not a number of seconds within
/// +-geom::kMaxAbsTimeS, and a repeated time stamp.
std::vector<std::pair<std::int64_t, std::string>> read_tum_list(const std::string& path);

}  // namespace pvb::dataset
