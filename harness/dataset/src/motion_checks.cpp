#include "pvb/dataset/motion_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/geometry/time.hpp"

namespace pvb::dataset {
namespace {

constexpr double kGravityMps2 = 9.80665;

double span_seconds(std::int64_t dt_ns) { return static_cast<double>(dt_ns) * 1e-9; }
std::string seconds_text(double s) { return format_number("%.3f s", s); }

/// One stream's times and lines, whichever sensor it is.
struct MotionStream {
  const std::string& file;
  std::vector<std::int64_t> t_ns;
  const std::vector<int>& line;
  const char* key;                ///< the setting of its rate
  std::optional<double> rate_hz;  ///< that setting's value
};

/// The mean rate against the setting; a rate no sensor has first (time
/// stamps in another unit than the file's).
void check_rate(const MotionStream& s, const MotionExpectations& e) {
  const std::size_t n = s.t_ns.size();
  if (n < 2) throw IoError(s.file, "holds one reading; a run needs a stream of them", s.line.front());
  const double span_s = span_seconds(s.t_ns.back() - s.t_ns.front());
  const double rate_hz = static_cast<double>(n - 1) / span_s;
  const std::string what = std::to_string(n) + " readings over " + format_g(span_s, 4) + " s";
  if (rate_hz > kMaxMotionRateHz)
    throw IoError(
        s.file,
        what + ", " + format_g(rate_hz, 4) + " a second: faster than any such sensor (at most " +
            format_g(kMaxMotionRateHz) + "); are the time stamps in the file's unit (" +
            (s.file.size() >= 4 && s.file.compare(s.file.size() - 4, 4, ".txt") == 0 ? "seconds"
                                                                                     : "nanoseconds") +
            ")?",
        s.line.back());
  if (!s.rate_hz) return;
  const double ratio = rate_hz / *s.rate_hz;
  if (ratio < 1.0 - kMotionRateTolerance || ratio > 1.0 + kMotionRateTolerance)
    throw ConfigError(e.settings_file, s.key,
                      "the rate of the readings, " + format_g(rate_hz, 4) + " Hz (" + s.file + ": " + what +
                          "), within " + format_g(100 * kMotionRateTolerance) + " %",
                      format_g(*s.rate_hz));
}

/// The readings cover the frames: they start and end within the gap bound
/// of the frames' ends and stop nowhere in between for longer.
void check_cover(const MotionStream& s, const MotionExpectations& e) {
  const double late_s = span_seconds(s.t_ns.front() - e.first_frame_t_ns);
  if (late_s > kMaxMotionGapS)
    throw IoError(s.file,
                  "the readings start " + seconds_text(late_s) +
                      " after the first frame (t = " + geom::format_tum_time(e.first_frame_t_ns) +
                      " s): more than " + seconds_text(kMaxMotionGapS) + " without readings",
                  s.line.front());
  const double early_s = span_seconds(e.last_frame_t_ns - s.t_ns.back());
  if (early_s > kMaxMotionGapS)
    throw IoError(s.file,
                  "the readings end " + seconds_text(early_s) +
                      " before the last frame (t = " + geom::format_tum_time(e.last_frame_t_ns) +
                      " s): more than " + seconds_text(kMaxMotionGapS) + " without readings",
                  s.line.back());
  for (std::size_t k = 1; k < s.t_ns.size(); ++k) {
    if (s.t_ns[k] <= e.first_frame_t_ns || s.t_ns[k - 1] >= e.last_frame_t_ns) continue;
    const double gap_s = span_seconds(s.t_ns[k] - s.t_ns[k - 1]);
    if (gap_s > kMaxMotionGapS)
      throw IoError(s.file,
                    "no reading for " + seconds_text(gap_s) + " before this one (since line " +
                        std::to_string(s.line[k - 1]) + "): more than " + seconds_text(kMaxMotionGapS) +
                        " between frames, which no motion interval bridges",
                    s.line[k]);
  }
}

/// An accelerometer reads g at rest and about g on a ground robot: its
/// median magnitude far from that is a stream of zeros or another unit.
void check_accelerometer(const MotionReadings& m) {
  std::vector<double> norm;
  norm.reserve(m.imu.size());
  for (const sensor::ImuSample& s : m.imu) norm.push_back(s.accel_mps2.norm());
  std::nth_element(norm.begin(), norm.begin() + static_cast<long>(norm.size() / 2), norm.end());
  const double median = norm[norm.size() / 2];
  if (median < 0.5 * kGravityMps2 || median > 2.0 * kGravityMps2)
    throw IoError(m.imu_file, "the accelerometer's median reading is " + format_g(median, 4) +
                                  " m/s^2; one at rest or on a driving robot reads about g, 9.81 m/s^2" +
                                  (median < 1e-9 ? " (every reading 0?)" : " (readings in another unit?)"));
}

/// No count jumps further than a rim at kMaxWheelSpeedMps turns it.
void check_wheel_jumps(const MotionReadings& m, const MotionExpectations& e) {
  if (e.ticks_per_rev <= 0 || !(e.wheel_radius_m > 0)) return;
  const double m_per_tick = 2.0 * M_PI * e.wheel_radius_m / e.ticks_per_rev;
  for (std::size_t k = 1; k < m.ticks.size(); ++k) {
    const sensor::WheelTicks &a = m.ticks[k - 1], &b = m.ticks[k];
    // long double: a jump of 2^62 counts in int64 arithmetic would overflow
    const long double dl = static_cast<long double>(b.left) - a.left,
                      dr = static_cast<long double>(b.right) - a.right;
    const double jump = static_cast<double>(std::max(std::fabs(dl), std::fabs(dr)));
    const double speed = jump * m_per_tick / span_seconds(b.t_ns - a.t_ns);
    if (speed > kMaxWheelSpeedMps)
      throw IoError(m.ticks_file,
                    "a count changes by " + format_g(jump, 6) + " ticks since line " +
                        std::to_string(m.tick_line[k - 1]) + ": a wheel at " + format_g(speed, 3) +
                        " m/s (more than " + format_g(kMaxWheelSpeedMps) + "; Robot.TicksPerRev " +
                        std::to_string(e.ticks_per_rev) + ")",
                    m.tick_line[k]);
  }
}

}  // namespace

void check_motion_readings(const MotionReadings& m, const MotionExpectations& e) {
  if (!m.imu.empty()) {
    MotionStream s{m.imu_file, {}, m.imu_line, "IMU.Frequency", e.imu_rate_hz};
    for (const sensor::ImuSample& r : m.imu) s.t_ns.push_back(r.t_ns);
    check_rate(s, e);
    check_cover(s, e);
    check_accelerometer(m);
  }
  if (!m.ticks.empty()) {
    MotionStream s{m.ticks_file, {}, m.tick_line, "Robot.EncoderFrequency", e.encoder_rate_hz};
    for (const sensor::WheelTicks& r : m.ticks) s.t_ns.push_back(r.t_ns);
    check_rate(s, e);
    check_cover(s, e);
    check_wheel_jumps(m, e);
  }
}

}  // namespace pvb::dataset
