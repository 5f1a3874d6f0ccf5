#include "pvb/slam/core/settings.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

namespace pvb::slam {
namespace {

/// An interval of accepted values; NaN is in none.
struct Range {
  double lo, hi;
  bool lo_open = false;  ///< (lo, ... instead of [lo, ...
  bool hi_open = false;  ///< ..., hi) instead of ..., hi]
  bool contains(double v) const { return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi); }
  std::string text() const {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%c%g, %g%c", lo_open ? '(' : '[', lo, hi, hi_open ? ')' : ']');
    return buf;
  }
};
Range closed(double lo, double hi) { return {lo, hi, false, false}; }
Range above(double lo, double hi) { return {lo, hi, true, false}; }  ///< (lo, hi]

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// Integer literals beyond int's range, by key: OpenCV's YAML parser wraps
/// them (4294967297 reads as 1), so the reader reports them itself.
std::map<std::string, std::string> wide_integer_literals(const std::string& text) {
  static const std::regex key_int(R"(^\s*([A-Za-z][\w.]*)\s*:\s*([-+]?\d+)\s*(#.*)?\r?$)");
  std::map<std::string, std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_match(line, m, key_int)) continue;
    errno = 0;
    const long long v = std::strtoll(m[2].str().c_str(), nullptr, 10);
    if (errno == ERANGE || v < INT_MIN || v > INT_MAX) out[m[1].str()] = m[2].str();
  }
  return out;
}

/// Reads typed, range-checked values of one settings file and remembers the
/// keys it was asked for.  A value outside its range is a ConfigError naming
/// the key and the range, before any cast (a double outside int's range must
/// not be converted).
class Reader {
 public:
  Reader(const cv::FileStorage& fs, std::string path, const std::string& text)
      : fs_(fs), path_(std::move(path)), wide_literals_(wide_integer_literals(text)) {}

  /// A number in `range`; `fallback` when the key is absent and not required.
  double real(const std::string& key, bool required, double fallback, const Range& range,
              const std::string& what = "a number") {
    const double v = raw(key, required, fallback, what + " in " + range.text());
    if (!range.contains(v)) throw ConfigError(path_, key, what + " in " + range.text(), number_text(v));
    return v;
  }
  /// An integer in [lo, hi].
  int integer(const std::string& key, bool required, int fallback, int lo, int hi,
              const std::string& what = "an integer") {
    return integral(key, required, fallback, lo, hi,
                    what + " in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  bool flag(const std::string& key, bool required, bool fallback) {
    return integral(key, required, fallback ? 1 : 0, 0, 1, "0 or 1") == 1;
  }
  /// A string; `fallback` when the key is absent.  `expected` says what
  /// the key takes, for the error when it is no string.
  std::string text(const std::string& key, const std::string& fallback, const std::string& expected) {
    seen_.insert(key);
    const cv::FileNode n = fs_[key];
    if (n.empty()) return fallback;
    if (!n.isString()) throw ConfigError(path_, key, expected, shown(n));
    return static_cast<std::string>(n);
  }
  /// A 4x4 rigid transform written as an opencv-matrix (ORB-SLAM3's
  /// IMU.T_b_c1); `fallback` when absent.  Its rotation must be orthonormal
  /// to 1e-3 and its last row 0 0 0 1.
  geom::SE3d pose(const std::string& key, bool required, const geom::SE3d& fallback) {
    seen_.insert(key);
    const cv::FileNode n = fs_[key];
    const std::string expected = "a 4x4 rigid transform (opencv-matrix, rows 4, cols 4)";
    if (n.empty()) {
      if (required) throw ConfigError(path_, key, expected + " (required key is missing)");
      return fallback;
    }
    cv::Mat m;
    try {
      n >> m;
    } catch (const cv::Exception&) {
      throw ConfigError(path_, key, expected);
    }
    if (m.rows != 4 || m.cols != 4 || m.channels() != 1) throw ConfigError(path_, key, expected);
    m.convertTo(m, CV_64F);
    Eigen::Matrix4d T;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) T(r, c) = m.at<double>(r, c);
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    const bool finite = T.allFinite();
    if (!finite || (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-3 ||
        R.determinant() < 0 || (T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9 ||
        T.topRightCorner<3, 1>().norm() > 10)
      throw ConfigError(path_, key, expected + " with an orthonormal rotation and a translation under 10 m");
    const Eigen::Quaterniond q(R);
    return geom::make_se3(q, Eigen::Vector3d(T.topRightCorner<3, 1>()));
  }
  /// Checks a value read before against a range known only later.
  void check(const std::string& key, double v, const Range& range, const std::string& what) const {
    if (!range.contains(v)) throw ConfigError(path_, key, what + " in " + range.text(), number_text(v));
  }
  const std::string& path() const { return path_; }
  const std::set<std::string>& seen() const { return seen_; }

 private:
  int integral(const std::string& key, bool required, int fallback, int lo, int hi,
               const std::string& expected) {
    const double v = raw(key, required, fallback, expected);
    if (!(v >= lo && v <= hi && v == std::floor(v))) throw ConfigError(path_, key, expected, number_text(v));
    return static_cast<int>(v);  // in [lo, hi]: representable
  }
  double raw(const std::string& key, bool required, double fallback, const std::string& expected) {
    seen_.insert(key);
    const cv::FileNode n = fs_[key];
    if (n.empty()) {
      if (required) throw ConfigError(path_, key, expected + " (required key is missing)");
      return fallback;
    }
    if (!n.isReal() && !n.isInt()) throw ConfigError(path_, key, expected);
    const auto wide = wide_literals_.find(key);
    if (n.isInt() && wide != wide_literals_.end()) throw ConfigError(path_, key, expected, wide->second);
    return static_cast<double>(n);
  }

  /// A value that is not what was expected, as an error shows it.
  static std::string shown(const cv::FileNode& n) {
    if (n.isInt() || n.isReal()) return number_text(static_cast<double>(n));
    if (n.isSeq()) return "a list";
    if (n.isMap()) return "a mapping";
    return "a value that is no string";
  }

  const cv::FileStorage& fs_;
  std::string path_;
  std::map<std::string, std::string> wide_literals_;
  std::set<std::string> seen_;
};

// Keys ORB-SLAM2 files carry that the RGB-D core does not use.
bool ignored_key(const std::string& key) {
  return key.rfind("Viewer.", 0) == 0 || key == "Camera.type" || key == "Camera.bFishEye";
}

/// IMU.* (ORB-SLAM3's keys): noise densities, rate and the camera's pose
/// in the IMU frame.  All or none.
void read_imu(Reader& r, const cv::FileStorage& fs, ImuSettings* imu) {
  imu->present = !fs["IMU.NoiseGyro"].empty() || !fs["IMU.T_b_c1"].empty();
  const bool req = imu->present;
  sensor::ImuNoise& n = imu->noise;
  n.gyro_noise_density = r.real("IMU.NoiseGyro", req, n.gyro_noise_density, above(0, 1), "rad/s/sqrt(Hz)");
  n.accel_noise_density = r.real("IMU.NoiseAcc", req, n.accel_noise_density, above(0, 10), "m/s^2/sqrt(Hz)");
  n.gyro_random_walk = r.real("IMU.GyroWalk", req, n.gyro_random_walk, above(0, 1), "rad/s^2/sqrt(Hz)");
  n.accel_random_walk = r.real("IMU.AccWalk", req, n.accel_random_walk, above(0, 10), "m/s^3/sqrt(Hz)");
  imu->rate_hz = r.real("IMU.Frequency", req, imu->rate_hz, closed(1, 10000), "readings per second");
  imu->T_b_c = r.pose("IMU.T_b_c1", req, imu->T_b_c);
  imu->accel_noise_inflation =
      r.real("IMU.AccNoiseInflation", false, imu->accel_noise_inflation, closed(1, 100), "a factor from 1 to 100");
  imu->accel_walk_inflation =
      r.real("IMU.AccWalkInflation", false, imu->accel_walk_inflation, closed(1, 1000), "a factor from 1 to 1000");
}

/// Robot.* (ours): the wheel drive and the camera's and IMU's poses on the base.
void read_robot(Reader& r, const cv::FileStorage& fs, RobotSettings* robot) {
  robot->present = !fs["Robot.WheelRadius"].empty();
  const bool req = robot->present;
  sensor::DriveDescription& d = robot->drive;
  d.wheel_radius_m = r.real("Robot.WheelRadius", req, d.wheel_radius_m, above(0, 5), "metres");
  d.track_m = r.real("Robot.Track", req, d.track_m, above(0, 10), "metres");
  d.ticks_per_rev = r.integer("Robot.TicksPerRev", req, d.ticks_per_rev, 1, 1 << 24);
  robot->encoder_rate_hz = r.real("Robot.EncoderFrequency", req, robot->encoder_rate_hz, closed(1, 10000), "readings per second");
  robot->T_base_c = r.pose("Robot.T_base_c1", req, robot->T_base_c);
  robot->T_base_imu = r.pose("Robot.T_base_imu", req, robot->T_base_imu);
  WheelNoise& n = robot->wheel_noise;
  n.translation_per_sqrt_m =
      r.real("Robot.WheelNoiseTranslation", false, n.translation_per_sqrt_m, above(0, 1), "m/sqrt(m)");
  n.yaw_per_sqrt_m = r.real("Robot.WheelNoiseYaw", false, n.yaw_per_sqrt_m, above(0, 1), "rad/sqrt(m)");
  n.yaw_per_sqrt_rad = r.real("Robot.WheelNoiseYawTurn", false, n.yaw_per_sqrt_rad, above(0, 1), "rad/sqrt(rad)");
  robot->wheel_calibration.enabled = r.flag("Robot.CalibrateWheels", false, robot->wheel_calibration.enabled);
}

/// System.Sensors (checked against the sections it needs by the caller).
sensor::SensorSetup read_sensors(Reader& r) {
  const std::string expected = sensor::sensor_setup_values();
  const std::string text = r.text("System.Sensors", "camera", expected);
  const std::optional<sensor::SensorSetup> setup = sensor::parse_sensor_setup(text);
  if (!setup) throw ConfigError(r.path(), "System.Sensors", expected, text);
  return *setup;
}

/// Smallest side, in pixels, of the coarsest ORB pyramid level.
constexpr double kMinLevelSidePx = 8;

/// Camera.*, ThDepth, DepthMapFactor (ORB-SLAM2's keys, all required but k3).
void read_camera(Reader& r, Settings* s) {
  s->K.fx = r.real("Camera.fx", true, 0, closed(1, 1e6), "a focal length in pixels");
  s->K.fy = r.real("Camera.fy", true, 0, closed(1, 1e6), "a focal length in pixels");
  s->K.cx = r.real("Camera.cx", true, 0, closed(0, 16384), "a pixel column");
  s->K.cy = r.real("Camera.cy", true, 0, closed(0, 16384), "a pixel row");
  const Range distortion = closed(-100, 100);
  s->k1 = r.real("Camera.k1", true, 0, distortion);
  s->k2 = r.real("Camera.k2", true, 0, distortion);
  s->p1 = r.real("Camera.p1", true, 0, distortion);
  s->p2 = r.real("Camera.p2", true, 0, distortion);
  s->k3 = r.real("Camera.k3", false, 0, distortion);  // optional in ORB-SLAM2 too
  s->K.width = r.integer("Camera.width", true, 0, 16, 16384, "an image width in pixels");
  s->K.height = r.integer("Camera.height", true, 0, 16, 16384, "an image height in pixels");
  r.check("Camera.cx", s->K.cx, closed(0, s->K.width), "a pixel column inside the image (Camera.width)");
  r.check("Camera.cy", s->K.cy, closed(0, s->K.height), "a pixel row inside the image (Camera.height)");
  s->fps = r.real("Camera.fps", true, 30, closed(1, 1000), "frames per second");
  s->bf = r.real("Camera.bf", true, 0, above(0, 1e7), "baseline (m) x fx");
  s->rgb_order = r.flag("Camera.RGB", true, true);
  s->th_depth = r.real("ThDepth", true, 0, above(0, 1e4), "a depth threshold in baselines");
  s->depth_map_factor = r.real("DepthMapFactor", true, 0, above(0, 1e6), "raw depth units per metre");
}

/// ORBextractor.* (ORB-SLAM2's keys, required, plus our subPixel).  The
/// pyramid's coarsest level must keep kMinLevelSidePx on the image's shorter
/// side.
void read_orb(Reader& r, Settings* s) {
  OrbParams& orb = s->orb;
  orb.num_features = r.integer("ORBextractor.nFeatures", true, 0, 1, 100000);
  orb.scale_factor =
      r.real("ORBextractor.scaleFactor", true, 0, above(1, 2), "a scale between pyramid levels");
  int max_levels = 1;
  for (double side = std::min(s->K.width, s->K.height);
       max_levels < 32 && side / orb.scale_factor >= kMinLevelSidePx; side /= orb.scale_factor)
    ++max_levels;
  orb.num_levels =
      r.integer("ORBextractor.nLevels", true, 0, 1, max_levels,
                "a number of pyramid levels (the smallest at least 8 px at Camera.width/height and "
                "ORBextractor.scaleFactor)");
  orb.ini_fast_threshold = r.integer("ORBextractor.iniThFAST", true, 0, 1, 255, "a FAST threshold");
  orb.min_fast_threshold = r.integer("ORBextractor.minThFAST", true, 0, 1, 255, "a FAST threshold");
  orb.sub_pixel = r.flag("ORBextractor.subPixel", false, orb.sub_pixel);  // ours, optional
}

void read_pe_match(Reader& r, PeMatchSettings* pe) {
  pe->enabled = r.flag("PEMatch.enabled", false, pe->enabled);
  pe->population = r.integer("PEMatch.population", false, pe->population, 2, 1000);
  pe->num_fitness_samples = r.integer("PEMatch.j", false, pe->num_fitness_samples, 1, 100000);
  pe->stall_iterations = r.integer("PEMatch.stallIterations", false, pe->stall_iterations, 1, 10000);
  pe->threshold_px =
      r.real("PEMatch.threshold", false, pe->threshold_px, above(0, 1000), "a distance in pixels");
  pe->refine = r.flag("PEMatch.refine", false, pe->refine);
  pe->sampson = r.flag("PEMatch.sampson", false, pe->sampson);
  pe->skip_low_parallax = r.flag("PEMatch.skipLowParallax", false, pe->skip_low_parallax);
}

void read_keyframe(Reader& r, KeyFrameSettings* kfs) {
  kfs->min_tracked_close = r.integer("KeyFrame.minTrackedClose", false, kfs->min_tracked_close, 1, 100000);
  kfs->min_untracked_close =
      r.integer("KeyFrame.minUntrackedClose", false, kfs->min_untracked_close, 1, 100000);
  kfs->ref_overlap = r.real("KeyFrame.refOverlap", false, kfs->ref_overlap, {0, 1, false, true},
                            "a share (0: ORB-SLAM2's rule)");
}

void read_point_cloud(Reader& r, PointCloudMappingSettings* pc) {
  pc->enabled = r.flag("PointCloudMapping.Enabled", false, pc->enabled);
  pc->resolution_m =
      r.real("PointCloudMapping.Resolution", false, pc->resolution_m, closed(1e-4, 100), "metres");
  pc->stride_px = r.integer("PointCloudMapping.Stride", false, pc->stride_px, 1, 1000, "pixels");
  pc->min_depth_m = r.real("PointCloudMapping.MinDepth", false, pc->min_depth_m, closed(0, 1000), "metres");
  pc->max_depth_m = r.real("PointCloudMapping.MaxDepth", false, pc->max_depth_m, above(pc->min_depth_m, 1000),
                           "metres beyond PointCloudMapping.MinDepth");
  pc->reassemble = r.flag("PointCloudMapping.Reassemble", false, pc->reassemble);
  pc->memory_budget_mb = r.real("PointCloudMapping.MemoryBudget", false, pc->memory_budget_mb, closed(0, 1e7),
                                "megabytes (0: no bound)");
}

void read_loop_closing(Reader& r, LoopClosingOptions* lc) {
  lc->enabled = r.flag("LoopClosing.enabled", false, lc->enabled);
  lc->search_radius_m =
      r.real("LoopClosing.searchRadius", false, lc->search_radius_m, above(0, 1e4), "metres");
  lc->max_angle_deg = r.real("LoopClosing.maxAngle", false, lc->max_angle_deg, above(0, 180), "degrees");
  lc->min_keyframe_gap = r.integer("LoopClosing.minKeyFrameGap", false, lc->min_keyframe_gap, 1, 1000000);
  lc->max_candidates = r.integer("LoopClosing.maxCandidates", false, lc->max_candidates, 1, 1000);
  lc->min_matches = r.integer("LoopClosing.minMatches", false, lc->min_matches, 6, 100000);
  lc->consistency = r.integer("LoopClosing.consistency", false, lc->consistency, 0, 1000);
  lc->min_inliers = r.integer("LoopClosing.minInliers", false, lc->min_inliers, 6, 100000);
  lc->max_correction_m =
      r.real("LoopClosing.maxCorrection", false, lc->max_correction_m, above(0, 1e4), "metres");
  lc->max_correction_deg =
      r.real("LoopClosing.maxCorrectionAngle", false, lc->max_correction_deg, above(0, 180), "degrees");
  lc->max_correction_deg_per_km = r.real("LoopClosing.maxCorrectionAnglePerKm", false, lc->max_correction_deg_per_km,
                                         Range{0, 180}, "degrees a kilometre");
  lc->lookalike_check_above_m = r.real("LoopClosing.lookalikeCheckAbove", false, lc->lookalike_check_above_m,
                                       above(0, 1e4), "metres");
  lc->essential_weight = r.integer("LoopClosing.essentialWeight", false, lc->essential_weight, 1, 1000000);
  lc->global_ba = r.flag("LoopClosing.globalBA", false, lc->global_ba);
  lc->rotation_weight = r.real("LoopClosing.rotationWeight", false, lc->rotation_weight, above(0, 1e6));
  lc->pose_proximity = r.flag("LoopClosing.poseProximity", false, lc->pose_proximity);
  lc->max_drift_rate = r.real("LoopClosing.maxDriftRate", false, lc->max_drift_rate, Range{0, 1}, "a share of the path");
  lc->drift_floor_m = r.real("LoopClosing.driftFloor", false, lc->drift_floor_m, Range{0, 1e4}, "metres");
  lc->ambiguity_check = r.flag("LoopClosing.ambiguityCheck", false, lc->ambiguity_check);
  lc->ambiguity_distance_m =
      r.real("LoopClosing.ambiguityDistance", false, lc->ambiguity_distance_m, above(0, 1e4), "metres");
  lc->ambiguity_inlier_share = r.real("LoopClosing.ambiguityInlierShare", false, lc->ambiguity_inlier_share,
                                      Range{0, 1}, "a share of the best candidate's inliers");
  lc->merge_confirmations =
      r.integer("LoopClosing.mergeConfirmations", false, lc->merge_confirmations, 1, 1000);
}

/// "FILE(LINE): REASON" from a cv::FileStorage parse error.  OpenCV 4.6
/// passes its function name as the error text and the message as the
/// function name, so both fields are searched.
IoError parse_error(const std::string& path, const cv::Exception& e) {
  static const std::regex located(R"(\((\d+)\): (.*)$)");
  for (const std::string& field : {e.func, e.err}) {
    std::smatch m;
    if (std::regex_search(field, m, located))
      return IoError(path, "cannot parse settings file: " + m[2].str(), std::stoi(m[1].str()));
  }
  return IoError(path, "cannot parse settings file: " + e.err + (e.func.empty() ? "" : " (" + e.func + ")"));
}

}  // namespace

/// Vocabulary.path: "" the default vocabulary, "none" none, else the file,
/// a relative path taken from the settings file's folder.
std::string vocabulary_path(const std::string& settings_path, const std::string& value) {
  if (value.empty()) return kDefaultVocabularyPath;
  if (value == "none" || value.front() == '/') return value;
  const std::size_t slash = settings_path.rfind('/');
  return slash == std::string::npos ? value : settings_path.substr(0, slash + 1) + value;
}

/// Lines OpenCV's YAML parser cannot read: it loops for ever on a line that
/// starts with "----" and goes on (found by fuzz_settings), so a line that
/// starts with "---" must be the document marker alone.
void check_document_markers(const std::string& text, const std::string& path) {
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.rfind("---", 0) != 0) continue;
    const std::size_t rest = line.find_first_not_of(" \t\r", 3);
    if (rest != std::string::npos && line[rest] != '#')
      throw IoError(path, "expected the document marker '---' alone on its line, got '" + line + "'", n);
  }
}

/// OpenCV's parser keeps the first of two equal keys in one map and never
/// looks at the second; a key given twice is an error naming both lines.
/// Keys are compared within their map: a nested map (an !!opencv-matrix)
/// opens a new scope at a deeper indentation.
void check_duplicate_keys(const std::string& text, const std::string& path) {
  static const std::regex key_line(R"(^( *)([A-Za-z_][\w.\-]*)\s*:(\s|$))");
  std::vector<std::pair<std::size_t, std::map<std::string, int>>> scopes{{0, {}}};  // (indent, key -> line)
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    std::smatch m;
    if (!std::regex_search(line, m, key_line)) continue;
    const std::size_t indent = m[1].length();
    while (scopes.size() > 1 && indent < scopes.back().first) scopes.pop_back();
    if (indent > scopes.back().first) scopes.push_back({indent, {}});
    const auto [at, fresh] = scopes.back().second.emplace(m[2].str(), n);
    if (!fresh)
      throw IoError(path, "key '" + m[2].str() + "' given twice (first at line " + std::to_string(at->second) +
                              "); OpenCV would read the first and ignore this one", n);
  }
}

namespace {

/// The settings of an opened document whose text is `text`.
Settings settings_from(const cv::FileStorage& fs, const std::string& text, const std::string& path) {
  // cv::FileStorage asserts (an internal error) when a key is looked up
  // in a root that is a list or a scalar (found by fuzz_settings).
  if (!fs.root().isMap())
    throw IoError(path, "expected ORB-SLAM2 settings: keys and values (a YAML map) at the top level");
  Settings s;
  s.source = path;
  Reader r(fs, path, text);
  read_camera(r, &s);
  read_orb(r, &s);
  s.align_patches = r.flag("Tracking.alignPatches", false, s.align_patches);  // ours, optional
  s.spill_features = r.flag("Map.spillFeatures", false, s.spill_features);  // ours, optional
  s.reloc_lookalikes = r.integer("Tracking.relocLookalikes", false, s.reloc_lookalikes, 0, 1000);  // ours, optional
  s.max_observing_keyframes =
      r.integer("Tracking.maxObservingKeyFrames", false, s.max_observing_keyframes, 0, 100000);  // ours, optional
  s.two_view_start = r.flag("Tracking.twoViewStart", false, s.two_view_start);  // ours, optional
  s.new_map_after_lost = r.integer("Tracking.newMapAfter", false, s.new_map_after_lost, 0, 100000);  // ours, optional
  s.merge_reloc_every = r.integer("Tracking.mergeRelocEvery", false, s.merge_reloc_every, 0, 100000);  // ours, optional
  s.reloc_odometry_floor_m =
      r.real("Tracking.relocOdometryFloor", false, s.reloc_odometry_floor_m, above(0, 1000), "metres");  // ours
  s.reloc_odometry_rate =
      r.real("Tracking.relocOdometryRate", false, s.reloc_odometry_rate, closed(0, 10), "metres per metre");  // ours
  s.carried_restart_after =
      r.integer("Tracking.carriedRestartAfter", false, s.carried_restart_after, 0, 100000);  // ours, optional
  read_pe_match(r, &s.pe_match);
  read_keyframe(r, &s.keyframe);
  read_point_cloud(r, &s.dense);
  read_loop_closing(r, &s.loop);
  read_imu(r, fs, &s.motion.imu);
  read_robot(r, fs, &s.motion.robot);
  s.motion.setup = read_sensors(r);
  s.motion.check(path);
  s.vocabulary_path = vocabulary_path(path, r.text("Vocabulary.path", "", "a string (a file path, or none)"));
  const cv::FileNode root = fs.root();
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string key = (*it).name();
    if (!r.seen().count(key) && !ignored_key(key))
      s.warnings.push_back(path + ": unknown key '" + key + "' ignored");
  }
  return s;
}

}  // namespace

Settings read_settings(const std::string& path) {
  require_regular_file(path);  // before any open: a FIFO would block
  const std::string text = read_file(path);
  check_document_markers(text, path);
  check_duplicate_keys(text, path);
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ)) throw IoError(path, "cannot open settings file");
  } catch (const cv::Exception& e) {
    throw parse_error(path, e);
  }
  return settings_from(fs, text, path);
}

Settings read_settings_text(const std::string& text, const std::string& name) {
  check_document_markers(text, name);
  check_duplicate_keys(text, name);
  cv::FileStorage fs;
  try {
    if (!fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY))
      throw IoError(name, "cannot parse settings text");
  } catch (const cv::Exception& e) {
    throw parse_error(name, e);
  }
  return settings_from(fs, text, name);
}

void MotionSensorSettings::check(const std::string& source) const {
  if (uses_accel(setup) && !imu.present)
    throw ConfigError(source, "IMU.NoiseGyro",
                      std::string("the IMU.* keys (sensors ") + to_string(setup) + " need them; required key is missing)");
  if (uses_wheels(setup) && !robot.present)
    throw ConfigError(source, "Robot.WheelRadius",
                      std::string("the Robot.* keys (sensors ") + to_string(setup) + " need them; required key is missing)");
}

}  // namespace pvb::slam
