#include "pvb/dataset/fakenect_dump.hpp"

#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/common/yaml_reader.hpp"
#include "pvb/dataset/tum_imu.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/stamped_pose.hpp"

namespace pvb::dataset {
namespace {

using sensor::kinect::kHeight;
using sensor::kinect::kWidth;

constexpr double kTicksPerNs = sensor::kinect::kClockHz * 1e-9;

std::string device_json(const sensor::kinect::Calibration& c) {
  // libfreenect's field names (newer fakenect reads the same file); a zero
  // reg_info polynomial is the registration table x + 1, y + 1.
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "{\n"
                "  \"source\": \"pvbench simulated Kinect v1\",\n"
                "  \"reg_info\": {\"ax\": 0, \"bx\": 0, \"cx\": 0, \"dx\": 0, \"ay\": 0, \"by\": 0, \"cy\": 0, "
                "\"dy\": 0, \"dx_start\": 0, \"dy_start\": 0, \"dx_beta_start\": 0, \"dy_beta_start\": 0, "
                "\"dx_beta_inc\": 0, \"dy_beta_inc\": 0, \"dxdx_start\": 0, \"dxdy_start\": 0, "
                "\"dydx_start\": 0, \"dydy_start\": 0, \"dxdxdx_start\": 0, \"dydxdx_start\": 0, "
                "\"dxdxdy_start\": 0, \"dydxdy_start\": 0, \"dydydx_start\": 0, \"dydydy_start\": 0},\n"
                "  \"reg_pad_info\": {\"start_lines\": 0, \"end_lines\": 0, \"cropping_lines\": 0},\n"
                "  \"zero_plane_info\": {\"dcmos_emitter_dist\": %.9g, \"dcmos_rcmos_dist\": %.9g, "
                "\"reference_distance\": %.9g, \"reference_pixel_size\": %.9g},\n"
                "  \"const_shift\": %d\n"
                "}\n",
                c.dcmos_emitter_dist_cm, c.dcmos_rcmos_dist_cm, c.reference_distance_cm,
                c.reference_pixel_size_mm, c.const_shift);
  return buf;
}

/// A number device.json must give (any finite value; the caller checks its range).
double required_number(yaml::MapReader& r, const std::string& key) {
  if (!r.has(key)) r.context().missing(r.full(key), r.node());
  return r.number(key, 0, -yaml::kInf, yaml::kInf);
}

}  // namespace

std::uint32_t kinect_ticks(std::int64_t t_ns) {
  return static_cast<std::uint32_t>(static_cast<std::uint64_t>(std::llround(static_cast<double>(t_ns) * kTicksPerNs)));
}

FakenectWriter::FakenectWriter(const std::string& dir, const sensor::kinect::Calibration& cal) : dir_(dir) {
  make_dirs(dir);
  write_file(dir + "/device.json", device_json(cal));
  index_ = OutputFile(dir + "/INDEX.txt");
  gt_ = OutputFile(dir + "/groundtruth.txt");
  gt_.append("# timestamp tx ty tz qx qy qz qw (T_w_c; time = device clock / 60 MHz, whole microseconds)\n");
}

std::string FakenectWriter::add_file(char type, std::int64_t t_ns, const char* ext, const std::string& header,
                                     const void* data, std::size_t n) {
  char name[96];
  std::snprintf(name, sizeof name, "%c-%.6f-%u.%s", type, static_cast<double>(t_ns) * 1e-9, kinect_ticks(t_ns),
                ext);
  OutputFile f(dir_ + "/" + name);
  f.append(header);
  f.append(static_cast<const char*>(data), n);
  f.close();
  return name;
}

void FakenectWriter::write(std::int64_t t_ns, const cv::Mat& rgb, const cv::Mat& raw_ir,
                           const Eigen::Vector3d& gravity_c, const geom::SE3d& T_w_c) {
  CV_Assert(rgb.type() == CV_8UC3 && rgb.cols == kWidth && rgb.rows == kHeight && rgb.isContinuous());
  CV_Assert(raw_ir.type() == CV_16UC1 && raw_ir.cols == kWidth && raw_ir.rows == kHeight && raw_ir.isContinuous());
  // freenect_raw_tilt_state: int16 x, y, z; int8 tilt angle; pad; int32 status.  In the
  // accelerometer's own axes, as a Kinect's, TUM's and libfreenect's.
  const Eigen::Vector3d k = kinect_accel_to_optical().transpose() * gravity_c;
  unsigned char tilt[kTiltStateBytes] = {};
  for (int i = 0; i < 3; ++i) {
    const auto counts = static_cast<std::int16_t>(std::lround(k[i] / 9.80665 * sensor::kinect::kCountsPerG));
    std::memcpy(tilt + 2 * i, &counts, 2);
  }
  // The accelerometer first: fakenect sleeps before the first entry of a new
  // time, so a reader that takes long over a frame is not slowed further.
  std::string lines = add_file('a', t_ns, "dump", "", tilt, sizeof tilt) + "\n";
  lines += add_file('d', t_ns, "pgm", "P5 640 480 65535\n", raw_ir.data, raw_ir.total() * 2) + "\n";
  lines += add_file('r', t_ns, "ppm", "P6 640 480 255\n", rgb.data, rgb.total() * 3) + "\n";
  index_.append(lines);
  // The stamp the camera source will see: ticks / 60 in whole microseconds.
  const std::int64_t t_us = std::llround(static_cast<double>(kinect_ticks(t_ns)) / 60.0);
  gt_.append(geom::format_tum_line({t_us * 1000, T_w_c}) + "\n");
  ++frames_;
}

std::vector<FakenectEntry> read_fakenect_index(const std::string& dir) {
  const std::string index = dir + "/INDEX.txt";
  struct stat st {};
  if (::stat(index.c_str(), &st) != 0)
    throw IoError(dir, "not a fakenect dump: it has no INDEX.txt (pvbench record --format fakenect writes one)");
  require_regular_file(index);
  std::ifstream in(index);
  if (!in) throw IoError(index, "cannot read the dump's index");
  std::vector<FakenectEntry> entries;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    FakenectEntry e;
    e.line = n;
    unsigned int ts = 0;
    char sep = 0;
    if (std::sscanf(line.c_str(), "%c-%lf-%u%c", &e.type, &e.record_time_s, &ts, &sep) < 3 ||
        (e.type != 'r' && e.type != 'd' && e.type != 'a'))
      throw IoError(index, "expected a name TYPE-TIME-TIMESTAMP... with TYPE r, d or a, got '" + line + "'", n);
    e.timestamp = ts;
    e.path = dir + "/" + line;
    entries.push_back(e);
  }
  if (entries.empty()) throw IoError(index, "the index names no frames");
  return entries;
}

void check_fakenect_entry(const FakenectEntry& e) {
  std::ifstream f(e.path, std::ios::binary | std::ios::ate);
  if (!f) throw IoError(e.path, "missing (named on line " + std::to_string(e.line) + " of INDEX.txt)");
  const auto size = static_cast<std::uint64_t>(f.tellg());
  if (e.type == 'a') {
    if (size != kTiltStateBytes)
      throw IoError(e.path, "an accelerometer record has " + std::to_string(kTiltStateBytes) + " bytes, this has " +
                                std::to_string(size));
    return;
  }
  f.seekg(0);
  std::string header;
  std::getline(f, header);
  std::istringstream hs(header);
  std::string magic;
  long w = 0, h = 0, maxval = 0;
  hs >> magic >> w >> h >> maxval;
  const bool depth = e.type == 'd';
  const char* want = depth ? "P5" : "P6";
  if (!hs || magic != want)
    throw IoError(e.path, std::string("expected a one-line ") + want + " header, got '" + header + "'");
  if (w != kWidth || h != kHeight)
    throw IoError(e.path, "the frame is " + std::to_string(w) + "x" + std::to_string(h) +
                              "; a Kinect v1 dump holds 640x480 frames");
  if (maxval != (depth ? 65535 : 255))
    throw IoError(e.path, "maxval " + std::to_string(maxval) + ", expected " + (depth ? "65535" : "255"));
  const std::uint64_t payload = static_cast<std::uint64_t>(kWidth) * kHeight * (depth ? 2 : 3);
  const std::uint64_t have = size - (header.size() + 1);
  if (have != payload)
    throw IoError(e.path, "truncated or padded: " + std::to_string(have) + " bytes of pixels, expected " +
                              std::to_string(payload));
}

sensor::kinect::Calibration read_fakenect_calibration(const std::string& dir) {
  const std::string path = dir + "/device.json";
  sensor::kinect::Calibration c;
  std::ifstream probe(path);
  if (!probe) return c;
  // The common JSON reader: a damaged file is an IoError naming its line, a
  // field a ConfigError naming the file, the line and the key.  Only the
  // fields used are read: libfreenect's file holds more (reg_info, ...).
  yaml::ReadContext ctx;
  ctx.file = path;
  ctx.errors = yaml::ErrorKind::kIo;
  ctx.json = true;
  const YAML::Node root = yaml::parse(read_file(path), ctx);
  ctx.errors = yaml::ErrorKind::kConfig;
  yaml::MapReader top(root, ctx, "");
  yaml::MapReader zp(top.child("zero_plane_info"), ctx, "zero_plane_info");
  c.dcmos_emitter_dist_cm = required_number(zp, "dcmos_emitter_dist");
  c.dcmos_rcmos_dist_cm = required_number(zp, "dcmos_rcmos_dist");
  c.reference_distance_cm = required_number(zp, "reference_distance");
  c.reference_pixel_size_mm = required_number(zp, "reference_pixel_size");
  c.const_shift = static_cast<int>(std::lround(required_number(top, "const_shift")));
  if (!(c.dcmos_emitter_dist_cm > 0 && c.reference_distance_cm > 0 && c.reference_pixel_size_mm > 0))
    zp.fail("zero_plane_info", zp.node(), "positive distances and pixel size");
  return c;
}

}  // namespace pvb::dataset
