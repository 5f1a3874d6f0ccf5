#include "pvb/sensor/kinect_v1.hpp"

#include <cmath>

namespace pvb::sensor::kinect {
namespace {

constexpr double kParamCoeff = 4.0;    // raw units per sensor pixel
constexpr double kShiftScale10 = 10.0; // cm -> mm
constexpr double kConstOffset = 0.375; // S2D_CONST_OFFSET

double sensor_offset_mm(double raw, const Calibration& cal) {
  return cal.reference_pixel_size_mm * ((raw - kParamCoeff * cal.const_shift) / kParamCoeff - kConstOffset);
}

}  // namespace

double raw_to_depth_mm(double raw, const Calibration& cal) {
  const double e = cal.dcmos_emitter_dist_cm;
  const double m = sensor_offset_mm(raw, cal);
  if (e - m <= 0) return -1.0;
  return kShiftScale10 * cal.reference_distance_cm * e / (e - m);
}

double depth_mm_to_raw_exact(double z_mm, const Calibration& cal) {
  const double e = cal.dcmos_emitter_dist_cm;
  const double m = e - kShiftScale10 * cal.reference_distance_cm * e / z_mm;
  return kParamCoeff * (m / cal.reference_pixel_size_mm + kConstOffset) + kParamCoeff * cal.const_shift;
}

std::uint16_t depth_mm_to_raw(double z_mm, const Calibration& cal) {
  if (!(z_mm > 0) || z_mm >= kMaxMetricMm) return kNoRaw;
  const double raw = std::round(depth_mm_to_raw_exact(z_mm, cal));
  if (raw < 0 || raw >= kNoRaw) return kNoRaw;
  return static_cast<std::uint16_t>(raw);
}

double quantisation_step_mm(double z_mm, const Calibration& cal) {
  // dz/draw of z = 10 R E / (E - m), dm/draw = s / 4.
  const double k = kShiftScale10 * cal.reference_distance_cm * cal.dcmos_emitter_dist_cm;
  return z_mm * z_mm / k * cal.reference_pixel_size_mm / kParamCoeff;
}

std::array<std::uint16_t, kRawValues> raw_to_mm_table(const Calibration& cal) {
  std::array<std::uint16_t, kRawValues> t{};
  for (int raw = 0; raw < kRawValues; ++raw) {
    const double z = raw_to_depth_mm(raw, cal);
    t[static_cast<std::size_t>(raw)] = (z > 0 && z < kMaxMetricMm) ? static_cast<std::uint16_t>(z) : 0;
  }
  t[kNoRaw] = 0;
  return t;
}

std::array<std::int32_t, kMaxMetricMm> depth_to_rgb_shift_table(const Calibration& cal) {
  // libfreenect: pel = 1 / (2 s), D = B pel, shift = D (1 - 10 R / z) + 0.375.
  const double d_px = cal.dcmos_rcmos_dist_cm / (2.0 * cal.reference_pixel_size_mm);
  const double ref_mm = kShiftScale10 * cal.reference_distance_cm;
  std::array<std::int32_t, kMaxMetricMm> t{};
  for (int z = 1; z < kMaxMetricMm; ++z) {
    const double shift = d_px * (1.0 - ref_mm / z) + kConstOffset + cal.registration_dx_px;
    t[static_cast<std::size_t>(z)] = static_cast<std::int32_t>(shift * kShiftScale);
  }
  return t;
}

DepthRegistration::DepthRegistration(const Calibration& cal)
    : cal_(cal), raw_to_mm_(raw_to_mm_table(cal)), shift_(depth_to_rgb_shift_table(cal)) {}

namespace {

/// The whole-pixel part of a shift in 1/16 px (floor, also for negatives).
int floor_px(std::int32_t shift16) {
  return shift16 >= 0 ? shift16 / kShiftScale : -((-shift16 + kShiftScale - 1) / kShiftScale);
}

}  // namespace

cv::Mat DepthRegistration::encode_ir_raw(const cv::Mat& depth_colour_m) const {
  CV_Assert(depth_colour_m.type() == CV_32FC1);
  cv::Mat raw(depth_colour_m.size(), CV_16UC1, cv::Scalar(kNoRaw));
  cv::Mat nearest_mm(depth_colour_m.size(), CV_16UC1, cv::Scalar(0));
  for (int v = 0; v < depth_colour_m.rows; ++v) {
    const int y_ir = v - cal_.registration_dy_px;
    if (y_ir < 0 || y_ir >= raw.rows) continue;
    const float* z_row = depth_colour_m.ptr<float>(v);
    for (int u = 0; u < depth_colour_m.cols; ++u) {
      const std::uint16_t r = depth_mm_to_raw(1000.0 * z_row[u], cal_);
      const std::uint16_t z_mm = raw_to_mm(r);
      if (z_mm == 0) continue;
      // The decoder puts IR pixel x at floor(x + shift): x = u - floor(shift) lands on u.
      const int x_ir = u - floor_px(shift_[z_mm]);
      if (x_ir < 0 || x_ir >= raw.cols) continue;
      std::uint16_t& best = nearest_mm.at<std::uint16_t>(y_ir, x_ir);
      if (best != 0 && best <= z_mm) continue;  // the IR camera sees the nearer surface
      best = z_mm;
      raw.at<std::uint16_t>(y_ir, x_ir) = r;
    }
  }
  return raw;
}

cv::Mat DepthRegistration::register_to_colour_mm(const cv::Mat& raw_ir) const {
  CV_Assert(raw_ir.type() == CV_16UC1);
  // Pass 1: every IR pixel lands at floor(x + shift(z)), y + dy; the nearest wins.
  cv::Mat out(raw_ir.size(), CV_16UC1, cv::Scalar(0));
  for (int y = 0; y < raw_ir.rows; ++y) {
    const int ny = y + cal_.registration_dy_px;
    if (ny < 0 || ny >= out.rows) continue;
    const std::uint16_t* row = raw_ir.ptr<std::uint16_t>(y);
    for (int x = 0; x < raw_ir.cols; ++x) {
      const std::uint16_t z = raw_to_mm(row[x]);
      if (z == 0) continue;
      const int nx = x + floor_px(shift_[z]);
      if (nx < 0 || nx >= out.cols) continue;
      std::uint16_t& cur = out.at<std::uint16_t>(ny, nx);
      if (cur == 0 || cur > z) cur = z;
    }
  }
  // Pass 2, libfreenect's dense registration: a target also covers the
  // pixels left, up and up-left of it.  Here only pixels that pass 1 left
  // empty are filled (libfreenect overwrites them), from the nearest of the
  // right, lower and lower-right targets.  In place: a pixel reads only
  // pixels after it in raster order, which still hold pass 1's values.
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      if (out.at<std::uint16_t>(y, x) != 0) continue;
      std::uint16_t best = 0;
      const int dx[3] = {1, 0, 1}, dy[3] = {0, 1, 1};
      for (int k = 0; k < 3; ++k) {
        const int sx = x + dx[k], sy = y + dy[k];
        if (sx >= out.cols || sy >= out.rows) continue;
        const std::uint16_t z = out.at<std::uint16_t>(sy, sx);
        if (z != 0 && (best == 0 || z < best)) best = z;
      }
      out.at<std::uint16_t>(y, x) = best;
    }
  }
  return out;
}

}  // namespace pvb::sensor::kinect
