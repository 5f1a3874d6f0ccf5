#include "pvb/dataset/tum_sequence.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <tuple>

#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/image_file.hpp"
#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/sensor/image_codec.hpp"

namespace pvb::dataset {

void make_dirs(const std::string& dir) {
  std::string path;
  std::stringstream ss(dir);
  std::string part;
  if (!dir.empty() && dir[0] == '/') path = "/";
  while (std::getline(ss, part, '/')) {
    if (part.empty()) continue;
    path += part;
    if (::mkdir(path.c_str(), 0755) != 0 && errno != EEXIST)
      throw IoError(dir, std::string("cannot create folder: ") + std::strerror(errno));
    path += "/";
  }
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) throw IoError(dir, "not a folder");
  if (::access(dir.c_str(), W_OK) != 0)
    throw IoError(dir, std::string("folder is not writable: ") + std::strerror(errno));
}

namespace {

/// A transform as an OpenCV matrix node (4 x 4 floats, row by row).
std::string opencv_matrix(const std::string& key, const geom::SE3d& T) {
  std::string out = key + ": !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: f\n   data: [";
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      out += (r + c ? ", " : "") + format_real(T.matrix()(r, c));
    }
  return out + "]\n";
}

std::string robot_settings_text(const RobotCalibration& c) {
  std::string text =
      "\n# IMU (ORB-SLAM3's keys; Kalibr's continuous-time noise: rad/s/sqrt(Hz), m/s^2/sqrt(Hz),\n"
      "# rad/s^2/sqrt(Hz), m/s^3/sqrt(Hz)).  T_b_c1: the camera in the IMU frame (ORB-SLAM3's body).\n"
      "IMU.NoiseGyro: " + format_real(c.imu.gyro_noise_density) + "\nIMU.NoiseAcc: " + format_real(c.imu.accel_noise_density) +
      "\nIMU.GyroWalk: " + format_real(c.imu.gyro_random_walk) + "\nIMU.AccWalk: " + format_real(c.imu.accel_random_walk) +
      "\nIMU.Frequency: " + format_real(c.imu_rate_hz) + "\n";
  text += opencv_matrix("IMU.T_b_c1", c.T_b_i.inverse() * c.T_b_c);
  text += "\n# The robot (pvbench's own keys): nominal drive, encoders, the camera in the base frame\n"
          "# (axle centre, x forward, z up) and the IMU in it.\n"
          "Robot.WheelRadius: " + format_real(c.drive.wheel_radius_m) + "\nRobot.Track: " + format_real(c.drive.track_m) +
          "\nRobot.TicksPerRev: " + std::to_string(c.drive.ticks_per_rev) +
          "\nRobot.EncoderFrequency: " + format_real(c.encoder_rate_hz) + "\n";
  text += opencv_matrix("Robot.T_base_c1", c.T_b_c);
  text += opencv_matrix("Robot.T_base_imu", c.T_b_i);
  return text;
}

}  // namespace

std::string orbslam_settings_text(const OrbSlamSettings& s) {
  char buf[4096];
  std::snprintf(
      buf, sizeof buf,
      "%%YAML:1.0\n"
      "# ORB-SLAM2 RGB-D settings written by pvbench\n"
      "\n"
      "# Camera calibration and distortion parameters (OpenCV)\n"
      "Camera.fx: %.6f\nCamera.fy: %.6f\nCamera.cx: %.6f\nCamera.cy: %.6f\n\n"
      "Camera.k1: %.6f\nCamera.k2: %.6f\nCamera.p1: %.6f\nCamera.p2: %.6f\nCamera.k3: %.6f\n\n"
      "Camera.width: %d\nCamera.height: %d\n\n"
      "# Camera frames per second\nCamera.fps: %.1f\n\n"
      "# depth baseline (a Kinect's projector to camera, a stereo camera's imagers) times fx\nCamera.bf: %.6f\n\n"
      "# Color order of the images (0: BGR, 1: RGB. It is ignored if images are grayscale)\n"
      "Camera.RGB: %d\n\n"
      "# Close/Far threshold. Baseline times.\nThDepth: %.1f\n\n"
      "# Depthmap values factor\nDepthMapFactor: %.1f\n\n"
      "# ORB Parameters\n"
      "ORBextractor.nFeatures: %d\nORBextractor.scaleFactor: %.2f\nORBextractor.nLevels: %d\n"
      "ORBextractor.iniThFAST: %d\nORBextractor.minThFAST: %d\n\n"
      "# Viewer Parameters (ORB-SLAM2 reads these too)\n"
      "Viewer.KeyFrameSize: 0.05\nViewer.KeyFrameLineWidth: 1\nViewer.GraphLineWidth: 0.9\n"
      "Viewer.PointSize: 2\nViewer.CameraSize: 0.08\nViewer.CameraLineWidth: 3\n"
      "Viewer.ViewpointX: 0\nViewer.ViewpointY: -0.7\nViewer.ViewpointZ: -1.8\nViewer.ViewpointF: 500\n",
      s.K.fx, s.K.fy, s.K.cx, s.K.cy, s.k1, s.k2, s.p1, s.p2, s.k3, s.K.width, s.K.height, s.fps, s.bf,
      s.rgb_order, s.th_depth, s.depth_map_factor, s.n_features, s.scale_factor, s.n_levels, s.ini_th_fast,
      s.min_th_fast);
  std::string text = buf;
  if (s.kf_min_tracked_close || s.kf_ref_overlap)
    text += "\n# Keyframe decision (pvbench's own keys; ORB-SLAM2 ignores them)\n";
  if (s.kf_min_tracked_close)
    text += "KeyFrame.minTrackedClose: " + std::to_string(*s.kf_min_tracked_close) + "\n";
  if (s.kf_ref_overlap) {
    char ov[32];
    std::snprintf(ov, sizeof ov, "%.6g", *s.kf_ref_overlap);  // as given, not rounded to a grid
    text += std::string("KeyFrame.refOverlap: ") + ov + "\n";
  }
  if (s.sensors)
    text += "\n# The sensors the SLAM core fuses (pvbench's own key)\nSystem.Sensors: \"" +
            std::string(sensor::to_string(*s.sensors)) + "\"\n";
  if (s.robot) text += robot_settings_text(*s.robot);
  return text;
}

void write_orbslam_settings(const std::string& path, const OrbSlamSettings& s) {
  write_file(path, orbslam_settings_text(s));
}

namespace {
OutputFile open_list(const std::string& path, const std::string& header) {
  OutputFile f(path);
  f.append(header);
  return f;
}

/// Writes an image; a failed write (disk full) leaves no partial file.
void write_image(const std::string& path, const cv::Mat& image) {
  bool ok = false;
  note_output(path);
  try {
    ok = sensor::imwrite(path, image);
  } catch (const cv::Exception& e) {
    std::remove(path.c_str());
    throw IoError(path, "cannot write image: " + e.msg);
  }
  if (!ok) {
    std::remove(path.c_str());
    throw IoError(path, "cannot write image (disk full?)");
  }
}
}  // namespace

TumSequenceWriter::TumSequenceWriter(const std::string& dir, double depth_factor, const std::string& source)
    : dir_(dir), depth_factor_(depth_factor) {
  make_dirs(dir_);
  make_dirs(dir_ + "/rgb");
  make_dirs(dir_ + "/depth");
  const std::string tag = "# written by " + source + "\n";
  rgb_txt_ = open_list(dir_ + "/rgb.txt", "# color images\n" + tag + "# timestamp filename\n");
  depth_txt_ = open_list(dir_ + "/depth.txt", "# depth maps\n" + tag + "# timestamp filename\n");
  gt_txt_ =
      open_list(dir_ + "/groundtruth.txt", "# ground truth trajectory: camera optical frame in the world\n" +
                                               tag + "# timestamp tx ty tz qx qy qz qw\n");
  assoc_txt_ = open_list(dir_ + "/associations.txt", "");
}

void TumSequenceWriter::write(const sensor::RgbdFrame& frame, const geom::SE3d& T_w_c) {
  const std::string t = geom::format_tum_time(frame.t_ns);
  const std::string rgb_rel = "rgb/" + t + ".png", depth_rel = "depth/" + t + ".png";
  cv::Mat bgr;
  cv::cvtColor(frame.rgb, bgr, cv::COLOR_RGB2BGR);
  write_image(dir_ + "/" + rgb_rel, bgr);
  write_image(dir_ + "/" + depth_rel, sensor::depth_to_u16(frame.depth_m, depth_factor_));
  // associations.txt last: a frame it lists is in every other list.
  rgb_txt_.append(t + " " + rgb_rel + "\n");
  depth_txt_.append(t + " " + depth_rel + "\n");
  gt_txt_.append(geom::format_tum_line({frame.t_ns, T_w_c}) + "\n");
  assoc_txt_.append(t + " " + rgb_rel + " " + t + " " + depth_rel + "\n");
  ++frames_;
}

namespace {

/// A time stamp field of a list file in ns; IoError naming the file and line
/// when it is not a number of seconds within +-geom::kMaxAbsTimeS.
std::int64_t parse_stamp_ns(const std::string& field, const std::string& path, int line) {
  char* end = nullptr;
  const double t_s = std::strtod(field.c_str(), &end);
  const std::optional<std::int64_t> t_ns = geom::checked_seconds_to_ns(t_s);
  if (end == field.c_str() || *end != '\0' || !t_ns) {
    char range[32];
    std::snprintf(range, sizeof range, "%g", geom::kMaxAbsTimeS);
    throw IoError(path,
                  "time stamp '" + field + "' is not a number of seconds in [-" + range + ", " + range + "]",
                  line);
  }
  return *t_ns;
}

/// Data lines of a list file: (1-based line number, fields); '#' comments
/// and blank lines skipped.
std::vector<std::pair<int, std::vector<std::string>>> list_lines(const std::string& path) {
  std::vector<std::pair<int, std::vector<std::string>>> out;
  std::istringstream in(read_file(path));
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    std::vector<std::string> fields = split_ws(line, " \t\r");
    if (!fields.empty() && fields[0][0] != '#') out.emplace_back(n, std::move(fields));
  }
  return out;
}

}  // namespace

std::vector<std::string> sequence_files(const std::string& dir) {
  std::vector<std::string> out;
  for (const char* name :
       {"associations.txt", "rgb.txt", "depth.txt", "groundtruth.txt", "meta.json", "camera.yaml",
        "accelerometer.txt", "imu0/data.csv", "wheels.csv"})
    out.push_back(dir + "/" + name);
  for (const char* images : {"rgb", "depth"}) {
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir + "/" + images, ec))
      if (e.is_regular_file(ec)) out.push_back(e.path().string());
  }
  return out;
}

namespace {

/// associations.txt: "t_rgb rgb t_depth depth" lines with increasing t_rgb
/// (the order frames are tracked in).
std::vector<TumSequenceReader::Entry> read_associations(const std::string& path) {
  std::vector<TumSequenceReader::Entry> entries;
  int last_line = 0;
  for (const auto& [n, f] : list_lines(path)) {
    if (f.size() < 4)
      throw IoError(
          path, "expected 't_rgb rgb_file t_depth depth_file', got " + std::to_string(f.size()) + " fields",
          n);
    const std::int64_t t_rgb_ns = parse_stamp_ns(f[0], path, n), t_depth_ns = parse_stamp_ns(f[2], path, n);
    if (!entries.empty() && t_rgb_ns <= entries.back().t_ns)
      throw IoError(path,
                    "time stamps must increase: " + f[0] + " is not after " +
                        geom::format_tum_time(entries.back().t_ns) + " (line " + std::to_string(last_line) +
                        ")",
                    n);
    entries.push_back({t_rgb_ns, f[1], t_depth_ns, f[3]});
    last_line = n;
  }
  return entries;
}

/// One-to-one nearest-time association of rgb.txt and depth.txt, closest
/// pairs first; the result is sorted by rgb time.
std::vector<TumSequenceReader::Entry> associate_lists(const std::string& dir, double max_diff_s) {
  const auto rgb = read_tum_list(dir + "/rgb.txt");
  const auto depth = read_tum_list(dir + "/depth.txt");  // sorted: lower_bound below needs it
  const std::optional<std::int64_t> max_diff_ns = geom::checked_seconds_to_ns(max_diff_s);
  if (!max_diff_ns || *max_diff_ns < 0) throw IoError(dir, "association window out of range");
  std::vector<std::tuple<std::int64_t, std::size_t, std::size_t>> cand;
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    auto it = std::lower_bound(depth.begin(), depth.end(), rgb[i].first - *max_diff_ns,
                               [](const auto& a, std::int64_t t) { return a.first < t; });
    for (; it != depth.end() && it->first <= rgb[i].first + *max_diff_ns; ++it)
      cand.emplace_back(std::llabs(it->first - rgb[i].first), i,
                        static_cast<std::size_t>(it - depth.begin()));
  }
  std::sort(cand.begin(), cand.end());
  std::vector<bool> used_r(rgb.size()), used_d(depth.size());
  std::vector<TumSequenceReader::Entry> entries;
  for (const auto& [d, i, j] : cand) {
    if (used_r[i] || used_d[j]) continue;
    used_r[i] = used_d[j] = true;
    entries.push_back({rgb[i].first, rgb[i].second, depth[j].first, depth[j].second});
  }
  std::sort(
      entries.begin(), entries.end(),
      [](const TumSequenceReader::Entry& a, const TumSequenceReader::Entry& b) { return a.t_ns < b.t_ns; });
  if (entries.empty())
    throw IoError(dir + "/rgb.txt",
                  "no colour image has a depth image within " + std::to_string(max_diff_s) + " s");
  return entries;
}

}  // namespace

std::vector<std::pair<std::int64_t, std::string>> read_tum_list(const std::string& path) {
  std::vector<std::pair<std::int64_t, std::string>> out;
  std::vector<int> line_of;
  for (const auto& [n, fields] : list_lines(path)) {
    if (fields.size() < 2) throw IoError(path, "expected 'timestamp filename', got '" + fields[0] + "'", n);
    out.emplace_back(parse_stamp_ns(fields[0], path, n), fields[1]);
    line_of.push_back(n);
  }
  if (out.empty()) throw IoError(path, "no entries");
  // Sorted by time (stable: equal stamps keep their order, and are an error).
  std::vector<std::size_t> order(out.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return out[a].first < out[b].first; });
  std::vector<std::pair<std::int64_t, std::string>> sorted;
  sorted.reserve(out.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k > 0 && out[order[k]].first == out[order[k - 1]].first)
      throw IoError(path,
                    "duplicate time stamp " + geom::format_tum_time(out[order[k]].first) + " (also on line " +
                        std::to_string(line_of[order[k - 1]]) + ")",
                    line_of[order[k]]);
    sorted.push_back(std::move(out[order[k]]));
  }
  return sorted;
}

TumSequenceReader::TumSequenceReader(const std::string& dir, double depth_factor, double max_diff_s,
                                     const std::optional<MotionNeeds>& motion)
    : dir_(dir), depth_factor_(depth_factor) {
  const std::string assoc = dir + "/associations.txt";
  if (::access(assoc.c_str(), R_OK) == 0) entries_ = read_associations(assoc);
  if (entries_.empty()) entries_ = associate_lists(dir, max_diff_s);
  max_skipped_ = std::max<std::size_t>(10, entries_.size() / 10);
  motion_ = motion ? read_motion_readings(dir, *motion) : read_motion_readings(dir);
  last_delivered_t_ns_ = std::numeric_limits<std::int64_t>::min();
}

sensor::RgbdFrame TumSequenceReader::load(std::size_t i) const {
  const Entry& e = entries_.at(i);
  sensor::RgbdFrame f;
  f.t_ns = e.t_ns;
  f.index = i;
  f.rgb_name = e.rgb;
  const std::string rgb_path = dir_ + "/" + e.rgb, depth_path = dir_ + "/" + e.depth;
  const cv::Mat bgr = read_image(rgb_path, cv::IMREAD_COLOR, "colour image");
  cv::cvtColor(bgr, f.rgb, cv::COLOR_BGR2RGB);
  const cv::Mat d16 = read_image(depth_path, cv::IMREAD_ANYDEPTH, "depth image");
  if (d16.type() != CV_16UC1) throw IoError(depth_path, "expected a 16-bit single-channel depth image");
  if (d16.size() != f.rgb.size()) throw IoError(depth_path, "depth and colour images differ in size");
  f.depth_m = sensor::depth_from_u16(d16, depth_factor_);
  const std::int64_t t0_ns = i > 0 ? entries_[i - 1].t_ns : std::numeric_limits<std::int64_t>::min();
  attach_readings(motion_, t0_ns, e.t_ns, &f);
  return f;
}

std::optional<sensor::RgbdFrame> TumSequenceReader::next() {
  while (pos_ < entries_.size() && !skip_limit_reached()) {
    const std::size_t i = pos_++;
    try {
      sensor::RgbdFrame f = load(i);
      // The readings of frames skipped before this one go with it.
      f.imu.clear();
      f.wheel_ticks.clear();
      attach_readings(motion_, last_delivered_t_ns_, f.t_ns, &f);
      last_delivered_t_ns_ = f.t_ns;
      return f;
    } catch (const IoError& e) {
      ++skipped_;
      std::fprintf(stderr, "pvbench: warning: skipping frame %zu: %s\n", i, e.what());
    }
  }
  return std::nullopt;
}

}  // namespace pvb::dataset
