#include "pvb/report/map_scores.hpp"

#include <cstdio>
#include <sstream>

#include "pvb/common/text.hpp"
#include "pvb/sim/truth_surface.hpp"

namespace pvb::run {

namespace {
/// One subset's scores.  What a subset without map points (or without
/// surface points) cannot have is null, and "null_reason" says why: an
/// empty map is never scored as a perfect one.
std::string scores_json(const eval::MapScores& s, bool merged) {
  const bool has_map = s.accuracy.count > 0, has_surface = s.completeness.count > 0;
  std::ostringstream js;
  auto list = [&js](bool known, const std::vector<double>& v) {
    if (!known) {
      js << "null";
      return;
    }
    js << "[";
    for (std::size_t i = 0; i < v.size(); ++i) js << (i ? ", " : "") << json_number(v[i], 6);
    js << "]";
  };
  js << "{\"map_points\": " << s.accuracy.count << ", \"surface_points\": " << s.completeness.count
     << ", \"accuracy_m\": ";
  if (has_map)
    js << "{\"mean\": " << json_number(s.accuracy.mean, 6) << ", \"median\": " << json_number(s.accuracy.median, 6)
       << ", \"rmse\": " << json_number(s.accuracy.rmse, 6) << ", \"p95\": " << json_number(s.accuracy.p95, 6) << "}";
  else
    js << "null";
  js << ", \"completeness_at\": ";
  list(has_surface, s.completeness_at);
  js << ", \"precision_at\": ";
  list(has_map, s.precision_at);
  js << ", \"fscore_at\": ";
  list(has_map && has_surface, s.fscore_at);
  js << ", \"chamfer_m\": " << (has_map && has_surface ? json_number(s.chamfer_m, 6) : "null")
     << ", \"ghosting\": " << json_number(s.ghosting, 6) << ", \"ghosting_judged\": " << s.ghosting_judged;
  if (merged)
    js << ", \"ghosting_between_maps\": " << json_number(s.ghosting_between, 6)
       << ", \"ghosting_between_maps_judged\": " << s.ghosting_between_judged;
  if (!has_map || !has_surface)
    js << ", \"null_reason\": \"" << (has_map ? "no surface points" : "no map points") << " in this subset\"";
  js << "}";
  return js.str();
}

/// One row of the table; a subset without map points shows "-" for what it cannot have.
std::string scores_row(const std::string& name, const eval::MapScores& s) {
  const bool has_map = s.accuracy.count > 0;
  auto mm = [has_map](double v_m) { return has_map ? format_number("%8.1f", 1000 * v_m) : std::string("       -"); };
  auto pct = [&s](std::size_t i) { return i < s.completeness_at.size() ? 100.0 * s.completeness_at[i] : 0.0; };
  char line[256];
  std::snprintf(line, sizeof line, "%-7s %9zu %9zu %s %s %s %6.1f %6.1f %6.1f %6.1f %7s %7.1f\n", name.c_str(),
                s.accuracy.count, s.completeness.count, mm(s.accuracy.median).c_str(), mm(s.accuracy.mean).c_str(),
                mm(s.accuracy.p95).c_str(), pct(0), pct(1), pct(2), pct(3),
                has_map && s.fscore_at.size() > 1 ? format_number("%.3f", s.fscore_at[1]).c_str() : "-",
                100.0 * s.ghosting);
  return line;
}
}  // namespace

std::string map_accuracy_json(const eval::MapAccuracy& r, int indent) {
  const std::string nl = "\n" + std::string(static_cast<std::size_t>(indent), ' ');
  std::ostringstream js;
  js << "{" << nl << "  \"tau_m\": [";
  for (std::size_t i = 0; i < r.options.tau_m.size(); ++i) js << (i ? ", " : "") << json_number(r.options.tau_m[i], 6);
  const bool merged = r.sources > 1;
  js << "]";
  if (merged) js << "," << nl << "  \"maps_merged\": " << r.sources;
  js << "," << nl << "  \"all\": " << scores_json(r.all, merged) << "," << nl << "  \"per_class\": {";
  bool first = true;
  for (const auto& [c, s] : r.per_class) {
    js << (first ? "" : ",") << nl << "    \"" << sim::to_string(static_cast<sim::SurfaceClass>(c))
       << "\": " << scores_json(s, merged);
    first = false;
  }
  js << nl << "  }," << nl << "  \"per_range\": [";
  for (std::size_t b = 0; b < r.per_range.size(); ++b)
    js << (b ? "," : "") << nl << "    {\"from_m\": " << json_number(r.options.range_edges_m[b], 6)
       << ", \"to_m\": " << json_number(r.options.range_edges_m[b + 1], 6) << ", \"scores\": " << scores_json(r.per_range[b], merged)
       << "}";
  js << nl << "  ]" << nl << "}";
  return js.str();
}

std::string map_accuracy_table(const eval::MapAccuracy& r) {
  std::string t =
      "class     map pts  surf pts  acc med  acc mean  acc p95  comp1  comp2  comp5 comp10  F@2cm  ghost%\n";
  t += scores_row("all", r.all);
  for (const auto& [c, s] : r.per_class) t += scores_row(sim::to_string(static_cast<sim::SurfaceClass>(c)), s);
  if (r.sources > 1)
    t += "ghosting between the " + std::to_string(r.sources) + " maps: " +
         format_number("%.2f", 100 * r.all.ghosting_between) + " % of " + std::to_string(r.all.ghosting_between_judged) +
         " surface points seen by two of them\n";
  return t;
}

}  // namespace pvb::run
