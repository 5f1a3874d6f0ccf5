// The blind stretch in the report: metrics.json's "blind" object and the
// log's line (docs/evaluation.md, "The blind stretch").
#include "pvb/common/text.hpp"
#include "pvb/report/report.hpp"

namespace pvb::run {
namespace {

/// The tracking method timing.csv writes for a global relocalisation.
constexpr const char* kRelocalisationMethodName = "reloc";

std::string error_json(const std::optional<PoseError>& e) {
  if (!e) return "null";
  return "{\"trans_m\": " + json_number(e->trans_m, 10) + ", \"rot_deg\": " + json_number(e->rot_deg, 10) +
         "}";
}

std::string optional_int_json(const std::optional<int>& v) { return v ? std::to_string(*v) : "null"; }

}  // namespace

std::string blind_json(const BlindStretch& b) {
  std::string out = "{\"covered_frames\": [" + std::to_string(b.first_covered) + ", " +
                    std::to_string(b.last_covered) + "]";
  out += ", \"covered_frames_processed\": " + std::to_string(b.covered_processed);
  out += ", \"covered_frames_with_pose\": " + std::to_string(b.covered_with_pose);
  out += ", \"relocalised_frames\": " + std::to_string(b.relocalised_frames);
  out += ", \"last_before_frame\": " + optional_int_json(b.last_before);
  out += ", \"first_after_frame\": " + optional_int_json(b.first_after);
  out += ", \"first_after_tracked\": " + std::string(b.first_after_tracked ? "true" : "false");
  out += ", \"first_after_state\": " + (b.first_after ? json_string(b.first_after_state) : "null");
  out += ", \"first_after_method\": " + (b.first_after ? json_string(b.first_after_method) : "null");
  out += ", \"first_after_error\": " + error_json(b.first_after_error);
  out += ", \"first_after_ate\": " + error_json(b.first_after_ate);
  return out + "}";
}

std::string blind_summary(const BlindStretch& b) {
  std::string out = "blind stretch (frames " + std::to_string(b.first_covered) + "-" +
                    std::to_string(b.last_covered) + "): " + std::to_string(b.covered_with_pose) + " of " +
                    std::to_string(b.covered_frames()) + " covered frames with a pose";
  if (!b.first_after) return out + "; the run ended before the camera's return";
  out += "; frame " + std::to_string(*b.first_after) + " after it ";
  if (!b.first_after_tracked) return out + "has no pose (state " + b.first_after_state + ")";
  out += "tracked (" + b.first_after_method + ")";
  if (b.first_after_method == kRelocalisationMethodName) out += " by a global relocalisation";
  if (b.first_after_error)
    out += ", " + format_number("%.4f m", b.first_after_error->trans_m) + " / " +
           format_number("%.3f deg", b.first_after_error->rot_deg) + " off across the stretch";
  else
    out += ", no pose before the stretch to measure it from";
  return out;
}

}  // namespace pvb::run
