#include "pvb/plot/dashes.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace pvb::plot {
namespace {

using Point = std::pair<double, double>;

bool same_color(eval::Rgb a, eval::Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

/// The dashes of one polyline.
std::vector<eval::FigPolyline> dashes_of(const eval::FigPolyline& line, double on_px, double off_px) {
  std::vector<eval::FigPolyline> out;
  eval::FigPolyline dash{{}, line.color, line.width_px};
  bool drawing = true;
  double left_px = on_px;  // of the current dash or gap
  if (!line.points.empty()) dash.points.push_back(line.points.front());
  for (std::size_t i = 0; i + 1 < line.points.size(); ++i) {
    Point a = line.points[i];
    const Point b = line.points[i + 1];
    double seg_px = std::hypot(b.first - a.first, b.second - a.second);
    while (seg_px > left_px) {
      const double s = left_px / seg_px;
      a = {a.first + s * (b.first - a.first), a.second + s * (b.second - a.second)};
      seg_px -= left_px;
      if (drawing) {
        dash.points.push_back(a);
        out.push_back(dash);
        dash.points.clear();
      } else {
        dash.points.push_back(a);
      }
      drawing = !drawing;
      left_px = drawing ? on_px : off_px;
    }
    left_px -= seg_px;
    if (drawing) dash.points.push_back(b);
  }
  if (drawing && dash.points.size() > 1) out.push_back(dash);
  return out;
}

}  // namespace

void dash_polylines(eval::Figure* figure, eval::Rgb color, double on_px, double off_px) {
  on_px = std::max(on_px, 0.5);
  off_px = std::max(off_px, 0.5);
  std::vector<eval::FigPolyline> kept;
  for (const eval::FigPolyline& line : figure->polylines) {
    if (!same_color(line.color, color)) {
      kept.push_back(line);
      continue;
    }
    for (eval::FigPolyline& d : dashes_of(line, on_px, off_px)) kept.push_back(std::move(d));
  }
  figure->polylines = std::move(kept);
}

}  // namespace pvb::plot
