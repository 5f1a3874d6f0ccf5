#pragma once
// The Kinect v1's depth pipeline: raw 11-bit disparity, its conversion to
// millimetres and the registration of the IR (depth) view to the colour view,
// with the relations libfreenect uses (src/registration.c, 0.5.x), so a
// simulated device and a real one go through the same arithmetic.
//
//   raw -> depth:   m = s * ((raw - 4 c) / 4 - 0.375)                 [mm on the sensor]
//                   z_mm = 10 * R * E / (E - m)
//   depth -> shift: x_rgb = x_ir + dx + D * (1 - 10 R / z_mm) + 0.375  [pixels]
//                   with D = B / (2 s), in 1/16 px fixed point
//
// E = dcmos_emitter_dist (cm), B = dcmos_rcmos_dist (cm), R =
// reference_distance (cm), s = reference_pixel_size (mm), c = const_shift;
// the factory values below are libfreenect's defaults.  The IR and colour
// cameras of the model share intrinsics; dx, dy are the constant part of the
// registration table (docs/openni.md, "Kinect v1 depth").
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>

namespace pvb::sensor::kinect {

inline constexpr int kWidth = 640;
inline constexpr int kHeight = 480;
inline constexpr std::uint16_t kNoRaw = 2047;      ///< raw value of "no depth"
inline constexpr int kRawValues = 2048;            ///< 11 bits
inline constexpr int kMaxMetricMm = 10000;         ///< libfreenect's table size: depth below 10 m
inline constexpr int kShiftScale = 16;             ///< fixed point of the registration shift
inline constexpr double kCountsPerG = 819.0;       ///< accelerometer counts per g (FREENECT_COUNTS_PER_G)
inline constexpr double kClockHz = 60e6;           ///< frame timestamps count a 60 MHz clock

/// The device's depth calibration, in libfreenect's names and units.
struct Calibration {
  double dcmos_emitter_dist_cm = 7.5;
  double dcmos_rcmos_dist_cm = 2.3;
  double reference_distance_cm = 120.0;
  double reference_pixel_size_mm = 0.1042;
  int const_shift = 200;
  int registration_dx_px = 1;  ///< constant x offset of the registration table (libfreenect's DEPTH_X_OFFSET)
  int registration_dy_px = 1;  ///< constant y offset
};

/// Exact depth of a raw value (mm); <= 0 or beyond kMaxMetricMm means none.
double raw_to_depth_mm(double raw, const Calibration& cal);
/// The raw value (real-valued) that measures depth z_mm.
double depth_mm_to_raw_exact(double z_mm, const Calibration& cal);
/// The raw value a Kinect reports for depth z_mm: the disparity rounded to
/// its integer step; kNoRaw when z is outside (0, kMaxMetricMm).
std::uint16_t depth_mm_to_raw(double z_mm, const Calibration& cal);
/// Depth change of one raw step at depth z_mm: the quantisation step (mm).
double quantisation_step_mm(double z_mm, const Calibration& cal);

/// libfreenect's raw -> mm table (truncated to whole mm, 0 = none).
std::array<std::uint16_t, kRawValues> raw_to_mm_table(const Calibration& cal);
/// libfreenect's depth -> horizontal registration shift, 1/16 px, for
/// z = 0..kMaxMetricMm-1 mm (the shift includes registration_dx_px).
std::array<std::int32_t, kMaxMetricMm> depth_to_rgb_shift_table(const Calibration& cal);

/// Tables built once per calibration.
class DepthRegistration {
 public:
  explicit DepthRegistration(const Calibration& cal);

  /// Colour-view depth (CV_32FC1 metres, 0 = none) -> the IR view's raw
  /// disparity (CV_16UC1, kNoRaw = none), as a Kinect at the same place would
  /// measure it: every pixel moves by its depth's shift, the nearest wins.
  cv::Mat encode_ir_raw(const cv::Mat& depth_colour_m) const;
  /// Raw IR-view disparity -> depth registered to the colour view (CV_16UC1
  /// mm, 0 = none): libfreenect's FREENECT_DEPTH_REGISTERED, including its
  /// dense fill of the pixels up and left of each target (nearest kept).
  cv::Mat register_to_colour_mm(const cv::Mat& raw_ir) const;

  const Calibration& calibration() const { return cal_; }
  std::uint16_t raw_to_mm(std::uint16_t raw) const { return raw < kRawValues ? raw_to_mm_[raw] : 0; }

 private:
  Calibration cal_;
  std::array<std::uint16_t, kRawValues> raw_to_mm_;
  std::array<std::int32_t, kMaxMetricMm> shift_;
};

}  // namespace pvb::sensor::kinect
