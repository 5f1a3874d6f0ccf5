#pragma once
// The report's gravity, tilt, inertial-state and dead-reckoning pieces
// (metrics.json keys: report.hpp's gravity_inertial_fields): the summary
// rows and section of index.html and their figures.
#include <string>
#include <vector>

#include "pvb/report/report.hpp"

namespace pvb::run {

/// Summary-table rows of the primary system: dead-reckoned frames, the
/// gravity error, the keyframes' tilt drift, the inertial state.
std::string inertial_summary_rows(const SlamRun& primary);

/// "Gravity and inertial state": one row per system; empty when no system
/// has a gravity figure or an inertial state.
std::string inertial_section(const RunReport& report);

/// The gravity error over time, the keyframes' pitch and roll error and,
/// per system with the truth, its estimated IMU biases against the true
/// ones (dashed against solid); only the figures with data.
void write_inertial_figures(const RunReport& report, const std::string& dir,
                            std::vector<std::string>* written);

}  // namespace pvb::run
