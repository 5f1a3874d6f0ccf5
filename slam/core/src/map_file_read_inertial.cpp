// Reading a map file's INER section (version 2): the sensor setup and
// extrinsics, gravity and the map's bias, and each keyframe's inertial
// state and link in time, every value checked (map_file_read.cpp reads the
// rest of the file).
#include <cmath>
#include <optional>
#include <string>

#include "map_file_bytes.hpp"
#include "map_file_read.hpp"
#include "pvb/common/text.hpp"

namespace pvb::slam::mapfile {
namespace {

std::string vector_text(const Eigen::Vector3d& v) {
  return "(" + format_g(v.x()) + ", " + format_g(v.y()) + ", " + format_g(v.z()) + ")";
}

Eigen::Vector3d read_vector(ByteReader& r) {
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v(i) = r.f64();
  return v;
}

ImuBias read_bias(ByteReader& r) {
  ImuBias b;
  b.gyro_radps = read_vector(r);
  b.accel_mps2 = read_vector(r);
  return b;
}

/// "gyro bias (..) rad/s and accelerometer bias (..) m/s^2"
std::string bias_text(const ImuBias& b) {
  return "gyro bias " + vector_text(b.gyro_radps) + " rad/s and accelerometer bias " +
         vector_text(b.accel_mps2) + " m/s^2";
}

void check_bias(ByteReader& r, const std::string& whose, const ImuBias& b) {
  if (!bias_in_range(b))
    r.fail(whose + " " + bias_text(b) + ": not finite or beyond " + format_g(kMaxGyroBiasRadps) +
           " rad/s and " + format_g(kMaxAccelBiasMps2) + " m/s^2");
}

/// An extrinsic transform (12 f64: the rotation row by row, the translation).
geom::SE3d read_extrinsic(ByteReader& r, const char* name) {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = r.f64();
  t = read_vector(r);
  const geom::SE3d T = geom::make_se3(R, t);
  if (!rigid_in_range(T))
    r.fail(std::string(name) + " is not a rigid transform within " + format_g(kMaxExtrinsicM) +
           " m (finite, its rotation orthonormal within 1e-6 with determinant +1)");
  return T;
}

/// A keyframe's inertial state: none (all zero) or a speed and biases in range.
void check_state(ByteReader& r, std::uint64_t id, std::uint8_t has_state, const Eigen::Vector3d& v_w,
                 const ImuBias& b) {
  const std::string what = "keyframe " + std::to_string(id);
  if (has_state > 1) r.fail(what + ": has_state " + std::to_string(has_state) + ", expected 0 or 1");
  if (has_state == 0) {
    if (!v_w.isZero(0) || !b.gyro_radps.isZero(0) || !b.accel_mps2.isZero(0))
      r.fail(what + " has no inertial state but a velocity or bias other than 0");
    return;
  }
  if (!speed_in_range(v_w))
    r.fail(what + ": velocity " + vector_text(v_w) + " m/s, not finite or faster than " +
           format_g(kMaxSpeedMps) + " m/s");
  check_bias(r, what + "'s", b);
}

/// Links keyframe `kf` after `prev_id` in time (kNone: it starts a chain).
/// The predecessor is another keyframe of the map, older (a smaller id and
/// an earlier time), of the same session, and no other keyframe's.
void link_in_time(ByteReader& r, const std::shared_ptr<KeyFrame>& kf, std::uint64_t prev_id, const Map& map) {
  if (prev_id == kNone) return;
  const std::string what =
      "keyframe " + std::to_string(kf->id()) + ": its predecessor in time " + std::to_string(prev_id);
  const auto it = map.keyframes().find(prev_id);
  if (it == map.keyframes().end()) r.fail(what + " is not in the map");
  const std::shared_ptr<KeyFrame>& prev = it->second;
  if (!(prev_id < kf->id() && prev->t_ns() < kf->t_ns()))
    r.fail(what + " is not older (at " + std::to_string(prev->t_ns()) + " ns, it at " +
           std::to_string(kf->t_ns()) + " ns)");
  if (prev->session() != kf->session())
    r.fail(what + " is of session " + std::to_string(prev->session()) + ", it of session " +
           std::to_string(kf->session()));
  if (const auto next = prev->motion().next.lock())
    r.fail(what + " is already keyframe " + std::to_string(next->id()) + "'s");
  kf->motion().prev = prev;
  prev->motion().next = kf;
}

}  // namespace

void read_inertial_head(ByteReader& r, MapSettings* s, MapGravity* g) {
  const std::uint32_t code = r.u32();
  const std::optional<sensor::SensorSetup> setup = sensor_of_code(code);
  if (!setup) r.fail("sensor setup " + std::to_string(code) + " is not known (0 to 3)");
  if (!uses_accel(*setup))
    r.fail(std::string("sensor setup ") + to_string(*setup) + " has no inertial state");
  s->sensors = *setup;
  g->ready = true;
  g->g_w = read_vector(r);
  if (!gravity_in_range(g->g_w))
    r.fail("gravity " + vector_text(g->g_w) + " m/s^2 of magnitude " + format_g(g->g_w.norm()) +
           ", expected " + format_g(kMinGravityMps2) + " to " + format_g(kMaxGravityMps2) + " m/s^2");
  s->T_b_c = read_extrinsic(r, "IMU.T_b_c1");
  s->T_base_c = uses_wheels(*setup) ? read_extrinsic(r, "Robot.T_base_c1") : geom::SE3d::Identity();
  g->bias = read_bias(r);
  check_bias(r, "the map's", g->bias);
  g->ready_keyframe_id = r.u64();
  if (g->ready_keyframe_id >= kMaxId)
    r.fail("gravity trusted at keyframe " + std::to_string(g->ready_keyframe_id) + ", an id not below 2^48");
  g->ready_t_ns = r.i64();
  g->init_rms = r.f64();
  if (!(std::isfinite(g->init_rms) && g->init_rms >= 0))
    r.fail("initialisation RMS " + format_g(g->init_rms) + ", expected a finite value >= 0");
}

void read_inertial(ByteReader r, Map* map) {
  MapSettings unused;
  MapGravity g;
  read_inertial_head(r, &unused, &g);
  const auto& kfs = map->keyframes();
  const std::uint64_t n = r.count(8 + 8 + 1 + 72, "keyframe states");
  if (n != kfs.size())
    r.fail(std::to_string(n) + " keyframe states for " + std::to_string(kfs.size()) + " keyframes");
  for (const auto& [id, kf] : kfs) {
    const std::uint64_t entry = r.u64();
    if (entry != id) r.fail("keyframe state for keyframe " + std::to_string(entry) + " out of order");
    const std::uint64_t prev_id = r.u64();
    const std::uint8_t has_state = r.u8();
    const Eigen::Vector3d v_w = read_vector(r);
    const ImuBias bias = read_bias(r);
    check_state(r, id, has_state, v_w, bias);
    link_in_time(r, kf, prev_id, *map);
    KeyFrameMotion& m = kf->motion();
    m.has_state = has_state == 1;
    m.v_w_mps = v_w;
    m.bias = bias;
  }
  if (!r.at_end()) r.fail("longer than its keyframe states");
  map->gravity() = g;
}

WheelFit read_wheels(ByteReader r) {
  WheelFit f;
  const auto length = [&](const char* name) {
    const double v = r.f64();
    if (!(v > 0 && v <= kMaxWheelDescriptionM))
      r.fail(std::string(name) + " " + format_g(v) + " m, expected more than 0 and at most " +
             format_g(kMaxWheelDescriptionM) + " m");
    return v;
  };
  f.described_radius_m = length("described wheel radius");
  f.described_track_m = length("described track");
  for (double* scale : {&f.calibration.left_scale, &f.calibration.right_scale, &f.calibration.track_scale}) {
    *scale = r.f64();
    if (!wheel_scale_in_range(*scale))
      r.fail("wheel factor " + format_g(*scale) + ", expected " + format_g(kMinWheelScale) + " to " +
             format_g(kMaxWheelScale));
  }
  const auto flag = [&](const char* name) {
    const std::uint8_t v = r.u8();
    if (v > 1) r.fail(std::string(name) + " " + std::to_string(v) + ", expected 0 or 1");
    return v == 1;
  };
  f.radii_known = flag("radii_known");
  f.track_known = flag("track_known");
  const auto count = [&](const char* name) {
    const std::uint32_t v = r.u32();
    if (v > 0x7fffffffu) r.fail(std::string(name) + " " + std::to_string(v) + ", expected below 2^31");
    return static_cast<int>(v);
  };
  f.intervals = count("intervals fitted");
  f.refused = count("intervals refused");
  if (f.intervals == 0) r.fail("no interval fitted (a map without a fit has no WHEL section)");
  const auto amount = [&](const char* name) {
    const double v = r.f64();
    if (!(std::isfinite(v) && v >= 0)) r.fail(std::string(name) + " " + format_g(v) + ", expected a finite value >= 0");
    return v;
  };
  f.rolled_m = amount("rolled (m)");
  f.turned_rad = amount("turned (rad)");
  WheelFitSums& m = f.sums;
  double v[10];
  for (double& x : v) x = r.f64();
  m.turn_normal << v[0], v[1], v[1], v[2];
  m.turn_rhs << v[3], v[4];
  m.mm = v[5], m.mn = v[6], m.nn = v[7], m.am = v[8], m.an = v[9];
  for (double x : v)
    if (!std::isfinite(x)) r.fail("a calibration sum that is not finite");
  if (v[0] < 0 || v[2] < 0 || m.mm < 0 || m.nn < 0) r.fail("a sum of squares below 0");
  if (!r.at_end()) r.fail("longer than its calibration");
  return f;
}

}  // namespace pvb::slam::mapfile
