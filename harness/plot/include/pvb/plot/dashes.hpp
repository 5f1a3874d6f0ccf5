#pragma once
// Dashed lines on a chart (pvb::eval::Figure): the line chart draws solid
// polylines; dash_polylines() breaks those of one colour into dashes, the
// legend's sample among them.
#include "pvb/eval/charts.hpp"

namespace pvb::plot {

/// Replaces every polyline of `figure` drawn in `color` by dashes along
/// it: on_px drawn, off_px left out, measured along the line (pixels).
/// Other polylines are kept as they are, in their order.
void dash_polylines(eval::Figure* figure, eval::Rgb color, double on_px = 8.0, double off_px = 5.0);

}  // namespace pvb::plot
