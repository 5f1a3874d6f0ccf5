#pragma once
// Charts as lists of drawing primitives in pixel coordinates: the
// trajectory error figure (top view + error over time), line charts and
// histograms, and their SVG serialisation.  The PNG renderer lives in
// pvb::plot (it needs OpenCV; this library does not).
#include <string>
#include <vector>

#include "pvb/eval/evaluate.hpp"

namespace pvb::eval {

struct Rgb {
  unsigned char r = 0, g = 0, b = 0;
};

/// Drawing primitives; coordinates are pixels, origin top-left, y down.
struct FigLine {
  double x0, y0, x1, y1;
  Rgb color;
  double width_px;
};
struct FigPolyline {
  std::vector<std::pair<double, double>> points;
  Rgb color;
  double width_px;
};
enum class TextAnchor { kStart, kMiddle, kEnd };
struct FigText {
  double x, y;  ///< anchor point on the text baseline
  std::string text;
  double size_px;
  TextAnchor anchor = TextAnchor::kStart;
  bool vertical = false;  ///< rotated 90 degrees counter-clockwise about (x, y)
  Rgb color;
};

struct Figure {
  int width_px = 0, height_px = 0;
  std::vector<FigLine> lines;          ///< drawn first
  std::vector<FigPolyline> polylines;  ///< drawn over lines, in order
  std::vector<FigText> texts;          ///< drawn last
};

/// Lays out the trajectory error figure for one result: a top view (x-y
/// plane, equal axes, metres) with ground truth in black, the aligned
/// estimate in blue and a red segment from each estimated position to its
/// ground truth; below it the ATE over time (seconds since the first pair).
Figure make_error_figure(const EvalResult& result, const std::string& title);

/// One named line of a chart; x and y have the same length.  Points whose
/// y is not finite break the line (a gap, e.g. frames that were not tracked).
struct Series {
  std::string name;
  std::vector<double> x, y;
  Rgb color;
};

/// Colours for the first, second, ... series of a chart.
Rgb series_color(std::size_t index);

/// A line chart of several series on shared axes, with a legend.  The y
/// range starts at 0 when every value is non-negative.  Empty series are
/// allowed (the axes then span [0, 1]).
Figure make_line_chart(const std::string& title, const std::string& x_label, const std::string& y_label,
                       const std::vector<Series>& series);

/// A histogram of `values` with `bins` equal bins over [min, max] (or
/// [0, 1] for no values); the bar heights are counts.  A thin vertical line
/// marks the median.
Figure make_histogram(const std::string& title, const std::string& x_label, const std::vector<double>& values,
                      int bins);

/// Bin counts of make_histogram(): `bins` equal bins over [lo, hi], the last
/// bin closed; values outside [lo, hi] are not counted.
std::vector<std::size_t> histogram_counts(const std::vector<double>& values, double lo, double hi, int bins);

/// Serialises a figure as a standalone SVG document.
std::string format_svg(const Figure& figure);

/// "1.5", "0.25", "-2": a tick label without trailing zeros.
std::string tick_label(double v, double step);

/// Tick positions covering [lo, hi] with a 1-2-5 step giving about `target` ticks.
std::vector<double> nice_ticks(double lo, double hi, int target, double* step);

}  // namespace pvb::eval
