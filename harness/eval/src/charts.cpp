#include "pvb/eval/charts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pvb/common/text.hpp"
#include "pvb/geometry/time.hpp"

namespace pvb::eval {
namespace {
constexpr Rgb kBlack{0, 0, 0};
constexpr Rgb kBlue{31, 90, 230};
constexpr Rgb kRed{220, 30, 30};
constexpr Rgb kGrid{225, 225, 225};
constexpr Rgb kAxis{60, 60, 60};
constexpr double kTickFont = 15.0;
constexpr double kLabelFont = 17.0;

struct Panel {
  double left, top, width, height;  // pixel box of the plotting area
  double x_lo, x_hi, y_lo, y_hi;    // data range
  double px(double x) const { return left + (x - x_lo) / (x_hi - x_lo) * width; }
  double py(double y) const { return top + height - (y - y_lo) / (y_hi - y_lo) * height; }
};

void draw_axes(Figure* f, const Panel& p, const std::string& x_label, const std::string& y_label) {
  double sx = 0, sy = 0;
  const std::vector<double> xt = nice_ticks(p.x_lo, p.x_hi, 8, &sx);
  const std::vector<double> yt = nice_ticks(p.y_lo, p.y_hi, 6, &sy);
  for (double x : xt) {
    f->lines.push_back({p.px(x), p.top, p.px(x), p.top + p.height, kGrid, 1.0});
    f->lines.push_back({p.px(x), p.top + p.height, p.px(x), p.top + p.height + 5, kAxis, 1.0});
    f->texts.push_back(
        {p.px(x), p.top + p.height + 21, tick_label(x, sx), kTickFont, TextAnchor::kMiddle, false, kAxis});
  }
  for (double y : yt) {
    f->lines.push_back({p.left, p.py(y), p.left + p.width, p.py(y), kGrid, 1.0});
    f->lines.push_back({p.left - 5, p.py(y), p.left, p.py(y), kAxis, 1.0});
    f->texts.push_back(
        {p.left - 8, p.py(y) + 5, tick_label(y, sy), kTickFont, TextAnchor::kEnd, false, kAxis});
  }
  // Frame.
  const double l = p.left, t = p.top, r = p.left + p.width, b = p.top + p.height;
  f->lines.push_back({l, t, r, t, kAxis, 1.0});
  f->lines.push_back({l, b, r, b, kAxis, 1.0});
  f->lines.push_back({l, t, l, b, kAxis, 1.0});
  f->lines.push_back({r, t, r, b, kAxis, 1.0});
  f->texts.push_back({p.left + p.width / 2, b + 46, x_label, kLabelFont, TextAnchor::kMiddle, false, kBlack});
  f->texts.push_back(
      {p.left - 62, p.top + p.height / 2, y_label, kLabelFont, TextAnchor::kMiddle, true, kBlack});
}

std::string rgb(const Rgb& c) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c.r, c.g, c.b);
  return buf;
}
}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target, double* step) {
  const double span = std::max(hi - lo, 1e-12);
  const double raw = span / std::max(target, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double s = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) {
      s = m * mag;
      break;
    }
  *step = s;
  std::vector<double> out;
  for (double v = std::ceil(lo / s - 1e-9) * s; v <= hi + 1e-9 * s; v += s)
    out.push_back(std::fabs(v) < 1e-12 * s ? 0.0 : v);
  return out;
}

std::string tick_label(double v, double step) {
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  return format_fixed(v, decimals);
}

Figure make_error_figure(const EvalResult& r, const std::string& title) {
  Figure f;
  f.width_px = 1000;
  f.height_px = 1180;
  // --- top view -------------------------------------------------------
  double x_lo = 1e300, x_hi = -1e300, y_lo = 1e300, y_hi = -1e300;
  for (const auto* list : {&r.T_w_c_gt, &r.T_w_c_est})
    for (const geom::SE3d& T : *list) {
      x_lo = std::min(x_lo, T.translation().x());
      x_hi = std::max(x_hi, T.translation().x());
      y_lo = std::min(y_lo, T.translation().y());
      y_hi = std::max(y_hi, T.translation().y());
    }
  Panel top{100, 70, 860, 700, x_lo, x_hi, y_lo, y_hi};
  {
    // Equal scale on both axes with a 5 % margin.
    const double span_x = std::max(x_hi - x_lo, 1e-3), span_y = std::max(y_hi - y_lo, 1e-3);
    const double m_per_px = 1.1 * std::max(span_x / top.width, span_y / top.height);
    const double cx = 0.5 * (x_lo + x_hi), cy = 0.5 * (y_lo + y_hi);
    top.x_lo = cx - 0.5 * m_per_px * top.width;
    top.x_hi = cx + 0.5 * m_per_px * top.width;
    top.y_lo = cy - 0.5 * m_per_px * top.height;
    top.y_hi = cy + 0.5 * m_per_px * top.height;
  }
  draw_axes(&f, top, "x [m]", "y [m]");
  for (std::size_t i = 0; i < r.T_w_c_gt.size(); ++i) {
    const geom::Vec3d g = r.T_w_c_gt[i].translation(), e = r.T_w_c_est[i].translation();
    f.lines.push_back({top.px(e.x()), top.py(e.y()), top.px(g.x()), top.py(g.y()), kRed, 1.0});
  }
  FigPolyline gt_line{{}, kBlack, 2.0}, est_line{{}, kBlue, 2.0};
  for (std::size_t i = 0; i < r.T_w_c_gt.size(); ++i) {
    gt_line.points.emplace_back(top.px(r.T_w_c_gt[i].translation().x()),
                                top.py(r.T_w_c_gt[i].translation().y()));
    est_line.points.emplace_back(top.px(r.T_w_c_est[i].translation().x()),
                                 top.py(r.T_w_c_est[i].translation().y()));
  }
  f.polylines.push_back(gt_line);
  f.polylines.push_back(est_line);
  f.texts.push_back({f.width_px / 2.0, 32, title, 20.0, TextAnchor::kMiddle, false, kBlack});
  char sub[200];
  std::snprintf(sub, sizeof sub, "top view, %s alignment, %zu pairs, ATE rmse %.4f m",
                alignment_name(r.alignment_kind), r.pairs.size(), r.ate.rmse);
  f.texts.push_back({f.width_px / 2.0, 56, sub, 15.0, TextAnchor::kMiddle, false, kAxis});
  // Legend (top-left of the panel, on a white box drawn as thick lines).
  {
    const double lx = top.left + 12, ly = top.top + 12;
    for (int k = 0; k < 84; k += 2)
      f.lines.push_back({lx, ly + k, lx + 175, ly + k, Rgb{255, 255, 255}, 2.0});
    const struct {
      const char* name;
      Rgb color;
      double w;
    } items[] = {{"ground truth", kBlack, 2.0}, {"estimate", kBlue, 2.0}, {"error (est -> gt)", kRed, 1.5}};
    for (int k = 0; k < 3; ++k) {
      const double y = ly + 16 + 26 * k;
      f.polylines.push_back({{{lx + 10, y}, {lx + 40, y}}, items[k].color, items[k].w});
      f.texts.push_back({lx + 50, y + 5, items[k].name, kTickFont, TextAnchor::kStart, false, kBlack});
    }
  }
  // --- ATE over time -----------------------------------------------------
  double t_max = 0.0, e_max = 0.0;
  for (std::size_t i = 0; i < r.t_ns.size(); ++i) {
    t_max = std::max(t_max, geom::ns_to_seconds(r.t_ns[i] - r.t_ns.front()));
    e_max = std::max(e_max, r.ate_m[i]);
  }
  Panel err{100, 870, 860, 220, 0.0, std::max(t_max, 1e-3), 0.0, std::max(e_max * 1.1, 1e-4)};
  draw_axes(&f, err, "time since first pair [s]", "ATE [m]");
  FigPolyline err_line{{}, kRed, 1.8};
  for (std::size_t i = 0; i < r.t_ns.size(); ++i)
    err_line.points.emplace_back(err.px(geom::ns_to_seconds(r.t_ns[i] - r.t_ns.front())), err.py(r.ate_m[i]));
  f.polylines.push_back(err_line);
  f.lines.push_back({err.left, err.py(r.ate.rmse), err.left + err.width, err.py(r.ate.rmse), kBlue, 1.0});
  char rm[120];
  std::snprintf(rm, sizeof rm, "absolute trajectory error over time (blue line: rmse %.4f m)", r.ate.rmse);
  f.texts.push_back({f.width_px / 2.0, err.top - 14, rm, 17.0, TextAnchor::kMiddle, false, kBlack});
  return f;
}

std::string format_svg(const Figure& f) {
  std::string out;
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\">\n"
      "<rect width=\"100%%\" height=\"100%%\" fill=\"#ffffff\"/>\n",
      f.width_px, f.height_px, f.width_px, f.height_px);
  out += buf;
  for (const FigLine& l : f.lines) {
    std::snprintf(
        buf, sizeof buf,
        "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"%s\" stroke-width=\"%.2g\"/>\n", l.x0,
        l.y0, l.x1, l.y1, rgb(l.color).c_str(), l.width_px);
    out += buf;
  }
  for (const FigPolyline& p : f.polylines) {
    out += "<polyline fill=\"none\" stroke=\"" + rgb(p.color) + "\" stroke-width=\"" +
           std::to_string(p.width_px) + "\" stroke-linejoin=\"round\" points=\"";
    for (const auto& [x, y] : p.points) {
      std::snprintf(buf, sizeof buf, "%.2f,%.2f ", x, y);
      out += buf;
    }
    out += "\"/>\n";
  }
  for (const FigText& t : f.texts) {
    const char* anchor = t.anchor == TextAnchor::kStart    ? "start"
                         : t.anchor == TextAnchor::kMiddle ? "middle"
                                                           : "end";
    std::snprintf(buf, sizeof buf,
                  "<text x=\"%.2f\" y=\"%.2f\" font-family=\"sans-serif\" font-size=\"%.1f\" fill=\"%s\" "
                  "text-anchor=\"%s\"",
                  t.x, t.y, t.size_px, rgb(t.color).c_str(), anchor);
    out += buf;
    if (t.vertical) {
      std::snprintf(buf, sizeof buf, " transform=\"rotate(-90 %.2f %.2f)\"", t.x, t.y);
      out += buf;
    }
    out += ">" + html_escape(t.text) + "</text>\n";
  }
  out += "</svg>\n";
  return out;
}

}  // namespace pvb::eval

namespace pvb::eval {

Rgb series_color(std::size_t index) {
  static const Rgb kColors[] = {{31, 90, 230}, {230, 120, 20}, {30, 150, 60}, {200, 30, 30}, {130, 60, 180}};
  return kColors[index % (sizeof kColors / sizeof kColors[0])];
}

Figure make_line_chart(const std::string& title, const std::string& x_label, const std::string& y_label,
                       const std::vector<Series>& series) {
  Figure f;
  f.width_px = 1000;
  f.height_px = 480;
  double x_lo = 1e300, x_hi = -1e300, y_lo = 1e300, y_hi = -1e300;
  for (const Series& s : series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x_lo = std::min(x_lo, s.x[i]);
      x_hi = std::max(x_hi, s.x[i]);
      y_lo = std::min(y_lo, s.y[i]);
      y_hi = std::max(y_hi, s.y[i]);
    }
  if (x_lo > x_hi) x_lo = 0, x_hi = 1, y_lo = 0, y_hi = 1;
  if (y_lo >= 0) y_lo = 0;
  if (x_hi - x_lo < 1e-9) x_hi = x_lo + 1;
  if (y_hi - y_lo < 1e-12) y_hi = y_lo + 1;
  y_hi += 0.08 * (y_hi - y_lo);
  const Panel p{100, 60, 860, 330, x_lo, x_hi, y_lo, y_hi};
  draw_axes(&f, p, x_label, y_label);
  f.texts.push_back({f.width_px / 2.0, 34, title, 20.0, TextAnchor::kMiddle, false, kBlack});
  for (const Series& s : series) {
    FigPolyline line{{}, s.color, 1.6};
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        if (line.points.size() > 1) f.polylines.push_back(line);
        line.points.clear();
        continue;
      }
      line.points.emplace_back(p.px(s.x[i]), p.py(s.y[i]));
    }
    if (line.points.size() == 1) line.points.push_back(line.points.front());
    if (!line.points.empty()) f.polylines.push_back(line);
  }
  // Legend, right-aligned above the panel.
  double lx = p.left + p.width;
  for (std::size_t k = series.size(); k-- > 0;) {
    const double text_w = 8.0 * static_cast<double>(series[k].name.size());
    lx -= text_w + 50;
    f.polylines.push_back({{{lx, p.top - 10}, {lx + 30, p.top - 10}}, series[k].color, 2.5});
    f.texts.push_back({lx + 36, p.top - 5, series[k].name, kTickFont, TextAnchor::kStart, false, kBlack});
  }
  return f;
}

std::vector<std::size_t> histogram_counts(const std::vector<double>& values, double lo, double hi, int bins) {
  std::vector<std::size_t> counts(static_cast<std::size_t>(std::max(bins, 1)), 0);
  const double w = (hi - lo) / static_cast<double>(counts.size());
  for (double v : values) {
    if (!(v >= lo && v <= hi)) continue;
    std::size_t b = w > 0 ? static_cast<std::size_t>((v - lo) / w) : 0;
    if (b >= counts.size()) b = counts.size() - 1;
    ++counts[b];
  }
  return counts;
}

Figure make_histogram(const std::string& title, const std::string& x_label, const std::vector<double>& values,
                      int bins) {
  Figure f;
  f.width_px = 1000;
  f.height_px = 480;
  bins = std::max(bins, 1);
  double lo = 0, hi = 1;
  if (!values.empty()) {
    lo = *std::min_element(values.begin(), values.end());
    hi = *std::max_element(values.begin(), values.end());
    if (hi - lo < 1e-9) hi = lo + 1;
  }
  const std::vector<std::size_t> counts = histogram_counts(values, lo, hi, bins);
  const std::size_t peak = *std::max_element(counts.begin(), counts.end());
  const Panel p{100, 60, 860, 330, lo, hi, 0.0, std::max<double>(1.0, 1.08 * static_cast<double>(peak))};
  draw_axes(&f, p, x_label, "frames");
  f.texts.push_back({f.width_px / 2.0, 34, title, 20.0, TextAnchor::kMiddle, false, kBlack});
  const double w = (hi - lo) / bins;
  for (int b = 0; b < bins; ++b) {
    const double x0 = p.px(lo + b * w), x1 = p.px(lo + (b + 1) * w);
    const double y0 = p.py(0), y1 = p.py(static_cast<double>(counts[static_cast<std::size_t>(b)]));
    if (y1 >= y0) continue;
    // A bar: filled with vertical strokes, then outlined.
    for (double x = x0 + 1; x < x1 - 0.5; x += 2) f.lines.push_back({x, y0, x, y1, Rgb{140, 170, 235}, 2.0});
    f.polylines.push_back({{{x0, y0}, {x0, y1}, {x1, y1}, {x1, y0}}, kBlue, 1.0});
  }
  if (!values.empty()) {
    std::vector<double> sorted = values;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t n = sorted.size();
    const double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    f.polylines.push_back({{{p.px(median), p.top}, {p.px(median), p.top + p.height}}, kRed, 1.5});
    char buf[80];
    std::snprintf(buf, sizeof buf, "median %.3g", median);
    f.texts.push_back({p.px(median) + 6, p.top + 18, buf, kTickFont, TextAnchor::kStart, false, kRed});
  }
  return f;
}

}  // namespace pvb::eval
