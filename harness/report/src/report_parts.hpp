#pragma once
// What the report's writers share (metrics.json, index.html, the figures):
// private to harness/report.
#include <string>
#include <vector>

#include "pvb/eval/charts.hpp"
#include "pvb/report/report.hpp"

namespace pvb::run {

/// The tracking time of every frame of one system, milliseconds.
std::vector<double> tracking_times(const SlamRun& run);

/// A number with `decimals` decimals, "-" when not finite (the HTML tables).
std::string fixed(double v, int decimals);

/// Writes figure `name` as SVG and PNG into dir and adds the name to `written`.
void write_figure(const eval::Figure& f, const std::string& dir, const std::string& name,
                  std::vector<std::string>* written);

}  // namespace pvb::run
