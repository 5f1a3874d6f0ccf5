// The sweep's figure: ATE RMSE per seed, PE-SLAM's and the baseline's,
// their means dashed, failed seeds marked (aggregate.svg and .png of a sweep).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "pvb/suite/aggregate.hpp"
#include "seed_failed.hpp"

namespace pvb::suite {
namespace {

/// ATE RMSE per seed in millimetres (NaN where missing), and the largest
/// (1 when none is above 0).
struct SeedAtes {
  std::vector<double> pe_mm, base_mm;
  double max_mm = 0;
};

SeedAtes seed_ates_mm(const SweepAggregate& a) {
  SeedAtes out;
  double ymax = 0;
  for (const SeedRun& r : a.runs) {
    const double nan = std::nan("");
    double p = nan, b = nan;
    if (r.metrics && r.metrics->primary.ate_rmse_m) p = *r.metrics->primary.ate_rmse_m * 1000.0;
    if (r.metrics && r.metrics->baseline && r.metrics->baseline->ate_rmse_m)
      b = *r.metrics->baseline->ate_rmse_m * 1000.0;
    out.pe_mm.push_back(p);
    out.base_mm.push_back(b);
    if (std::isfinite(p)) ymax = std::max(ymax, p);
    if (std::isfinite(b)) ymax = std::max(ymax, b);
  }
  out.max_mm = ymax > 0 ? ymax : 1.0;
  return out;
}

/// The sweep figure's legend above the plot's top right corner (`right`,
/// `top`): the run's dot, the baseline's square (with one), the mean's dashes.
void add_sweep_legend(eval::Figure& f, double right, double top, bool has_baseline) {
  const eval::Rgb black{0, 0, 0}, blue{31, 119, 180}, orange{230, 120, 20};
  double lx = right - 250;
  f.lines.push_back({lx, top - 8, lx + 1, top - 8, blue, 8});
  f.texts.push_back(
      {lx + 10, top - 4, has_baseline ? "PE-SLAM" : "run", 11, eval::TextAnchor::kStart, false, black});
  if (has_baseline) {
    lx += 90;
    f.polylines.push_back(
        {{{lx - 5, top - 13}, {lx + 5, top - 13}, {lx + 5, top - 3}, {lx - 5, top - 3}, {lx - 5, top - 13}},
         orange,
         1.5});
    f.texts.push_back({lx + 10, top - 4, "baseline", 11, eval::TextAnchor::kStart, false, black});
  }
  f.texts.push_back({right, top - 4 + 14, "dashed: mean", 10, eval::TextAnchor::kEnd, false, black});
}

}  // namespace

eval::Figure make_sweep_figure(const SweepAggregate& a) {
  eval::Figure f;
  f.width_px = 760;
  f.height_px = 380;
  const double left = 70, right = f.width_px - 20.0, top = 40, bottom = f.height_px - 50.0;
  const eval::Rgb black{0, 0, 0}, grey{200, 200, 200}, blue{31, 119, 180}, orange{230, 120, 20};

  const SeedAtes ates = seed_ates_mm(a);
  const std::vector<double>& pe = ates.pe_mm;
  const std::vector<double>& base = ates.base_mm;
  const double ymax = ates.max_mm;
  double step = 1;
  std::vector<double> ticks = eval::nice_ticks(0.0, ymax * 1.05, 5, &step);
  // The axis ends on a tick at or above the largest value.
  if (ticks.empty()) ticks.push_back(0.0);
  while (ticks.back() < ymax * 1.05 - 1e-12) ticks.push_back(ticks.back() + step);
  const double ytop = ticks.back() > 0 ? ticks.back() : ymax * 1.05;
  auto Y = [&](double v) { return bottom - (bottom - top) * v / ytop; };
  const std::size_t n = a.runs.size();
  auto X = [&](std::size_t i) { return left + (right - left) * (i + 0.5) / std::max<std::size_t>(n, 1); };

  f.texts.push_back({f.width_px / 2.0, 22, "ATE RMSE per seed: " + a.scenario, 15, eval::TextAnchor::kMiddle,
                     false, black});
  for (double t : ticks) {
    if (t > ytop + 1e-12) continue;
    f.lines.push_back({left, Y(t), right, Y(t), grey, 1});
    f.texts.push_back(
        {left - 6, Y(t) + 4, eval::tick_label(t, step), 11, eval::TextAnchor::kEnd, false, black});
  }
  f.lines.push_back({left, top, left, bottom, black, 1});
  f.lines.push_back({left, bottom, right, bottom, black, 1});
  f.texts.push_back({18, (top + bottom) / 2, "ATE RMSE (mm)", 12, eval::TextAnchor::kMiddle, true, black});
  f.texts.push_back(
      {(left + right) / 2, f.height_px - 10.0, "seed", 12, eval::TextAnchor::kMiddle, false, black});
  const std::size_t label_every = std::max<std::size_t>(1, n / 20);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % label_every == 0)
      f.texts.push_back(
          {X(i), bottom + 16, std::to_string(a.runs[i].seed), 11, eval::TextAnchor::kMiddle, false, black});
    if (seed_failed(a.runs[i]))
      f.texts.push_back(
          {X(i), bottom - 6, "x", 13, eval::TextAnchor::kMiddle, false, eval::Rgb{200, 30, 30}});
  }
  auto dashed = [&](double v, const eval::Rgb& c) {
    for (double x = left; x < right; x += 12)
      f.lines.push_back({x, Y(v), std::min(x + 7, right), Y(v), c, 1.5});
  };
  if (a.primary.ate_rmse_m.count > 0) dashed(a.primary.ate_rmse_m.mean * 1000.0, blue);
  if (a.has_baseline && a.baseline.ate_rmse_m.count > 0) dashed(a.baseline.ate_rmse_m.mean * 1000.0, orange);
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isfinite(base[i])) {  // hollow square
      const double x = X(i), y = Y(base[i]), h = 5;
      f.polylines.push_back(
          {{{x - h, y - h}, {x + h, y - h}, {x + h, y + h}, {x - h, y + h}, {x - h, y - h}}, orange, 1.5});
    }
    if (std::isfinite(pe[i])) {  // filled dot: a short thick stroke
      const double x = X(i), y = Y(pe[i]);
      f.lines.push_back({x - 0.5, y, x + 0.5, y, blue, 8});
    }
  }
  add_sweep_legend(f, right, top, a.has_baseline);
  return f;
}

}  // namespace pvb::suite
