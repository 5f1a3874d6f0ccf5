#include "pvb/report/inertial_report.hpp"

#include "pvb/common/text.hpp"

namespace pvb::run {
namespace {

std::string bias_num(double v) { return json_number(v, 9); }

/// [[x, y, z], ...] of one series.
std::string axes_json(const Axes& a) {
  std::string out = "[";
  for (std::size_t i = 0; i < a[0].size(); ++i)
    out += std::string(i ? ", " : "") + "[" + bias_num(a[0][i]) + ", " + bias_num(a[1][i]) + ", " +
           bias_num(a[2][i]) + "]";
  return out + "]";
}

std::string biases_json(const BiasComparison& b) {
  const auto gyro = [&](const std::string& v) { return b.has_gyro ? v : std::string("null"); };
  std::string out = "{\"keyframes\": " + std::to_string(b.t_s.size()) +
                    ", \"gyro_rms_radps\": " + gyro(bias_num(b.gyro_rms_radps)) +
                    ", \"accel_rms_mps2\": " + bias_num(b.accel_rms_mps2) +
                    ", \"gyro_final_radps\": " + gyro(bias_num(b.gyro_final_radps)) +
                    ", \"accel_final_mps2\": " + bias_num(b.accel_final_mps2) + ", \"keyframe_id\": [";
  for (std::size_t i = 0; i < b.keyframe_id.size(); ++i)
    out += (i ? ", " : "") + std::to_string(b.keyframe_id[i]);
  out += "], \"t_s\": [";
  for (std::size_t i = 0; i < b.t_s.size(); ++i) out += (i ? ", " : "") + bias_num(b.t_s[i]);
  out += "], \"gyro_est_radps\": " + gyro(axes_json(b.gyro_est_radps)) +
         ", \"gyro_true_radps\": " + gyro(axes_json(b.gyro_true_radps)) +
         ", \"accel_est_mps2\": " + axes_json(b.accel_est_mps2) +
         ", \"accel_true_mps2\": " + axes_json(b.accel_true_mps2) + "}";
  return out;
}

std::string wheels_json(const slam::WheelFit& w, const std::optional<slam::WheelCalibration>& truth) {
  const auto known = [](bool b) { return std::string(b ? "true" : "false"); };
  const auto true_num = [&](double slam::WheelCalibration::*f) {
    return truth ? bias_num((*truth).*f) : std::string("null");
  };
  return "{\"left_scale\": " + bias_num(w.calibration.left_scale) +
         ", \"right_scale\": " + bias_num(w.calibration.right_scale) +
         ", \"track_scale\": " + bias_num(w.calibration.track_scale) + ", \"radii_known\": " +
         known(w.radii_known) + ", \"track_known\": " + known(w.track_known) +
         ", \"intervals\": " + std::to_string(w.intervals) + ", \"refused\": " + std::to_string(w.refused) +
         ", \"rolled_m\": " + bias_num(w.rolled_m) + ", \"turned_rad\": " + bias_num(w.turned_rad) +
         ", \"true_left_scale\": " + true_num(&slam::WheelCalibration::left_scale) +
         ", \"true_right_scale\": " + true_num(&slam::WheelCalibration::right_scale) +
         ", \"true_track_scale\": " + true_num(&slam::WheelCalibration::track_scale) + "}";
}

}  // namespace

std::string inertial_json(const InertialReport& r) {
  const auto when = [&](const std::string& v) { return r.trusted ? v : std::string("null"); };
  return std::string("{\"trusted\": ") + (r.trusted ? "true" : "false") +
         ", \"trusted_t_s\": " + when(bias_num(r.trusted_t_s)) +
         ", \"trusted_keyframe\": " + when(std::to_string(r.trusted_keyframe)) +
         ", \"gravity_tilt_deg\": " + when(bias_num(r.gravity_tilt_deg)) + ", \"gravity_true_deg\": " +
         (r.gravity_true_deg ? bias_num(*r.gravity_true_deg) : std::string("null")) +
         ", \"init_rms\": " + when(bias_num(r.init_rms)) +
         ", \"biases\": " + (r.biases ? biases_json(*r.biases) : std::string("null")) +
         ", \"wheels\": " + (r.wheels ? wheels_json(*r.wheels, r.wheels_true) : std::string("null")) + "}";
}

}  // namespace pvb::run
