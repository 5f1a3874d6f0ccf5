#pragma once
// The two SLAM systems a `--compare` run evaluates: their ids, as
// metrics.json's "mode" and file names carry them, and their labels, as
// reports, tables and figures show them.  The baseline is PE-SLAM's own
// tracking with PE-match switched off (ORB-SLAM2's motion model), not the
// ORB-SLAM2 program, and its label says so.
#include <string>

namespace pvb::eval {

inline constexpr const char* kPeSlamMode = "pe-slam";
inline constexpr const char* kBaselineMode = "baseline";
/// metrics.json before version 2 named the baseline's mode "orb-slam2".
inline constexpr const char* kBaselineModeV1 = "orb-slam2";
/// metrics.json's "metrics_version": 2 since the baseline's mode is "baseline".
inline constexpr int kMetricsVersion = 2;

inline constexpr const char* kPeSlamLabel = "PE-SLAM";
inline constexpr const char* kBaselineLabel = "baseline (ORB-SLAM2 motion model)";

/// The mode id of metrics.json of any version: "orb-slam2" becomes "baseline".
inline std::string normalized_mode(const std::string& mode) {
  return mode == kBaselineModeV1 ? std::string(kBaselineMode) : mode;
}

/// The label of a mode id (either version); an unknown id is its own label.
inline std::string mode_label(const std::string& mode) {
  const std::string m = normalized_mode(mode);
  if (m == kPeSlamMode) return kPeSlamLabel;
  if (m == kBaselineMode) return kBaselineLabel;
  return mode;
}

}  // namespace pvb::eval
