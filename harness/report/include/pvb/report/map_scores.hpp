#pragma once
// A dense map's scores against the true surface as the report shows them
// (docs/map_accuracy.md): metrics.json's map objects and the table of
// `pvbench eval-map`.  Scoring itself is harness/run's map_eval.
#include <string>

#include "pvb/eval/map_accuracy.hpp"

namespace pvb::run {

/// One scored map.
struct MapResult {
  std::string name;  ///< corrected, live, before_loop, after_loop
  eval::MapAccuracy accuracy;
  double score_s = 0;
};

/// The result as JSON: {"tau_m", "all", "per_class": {...}, "per_range":
/// [...]}, each scores object {"map_points", "surface_points",
/// "accuracy_m": {mean, median, rmse, p95}, "completeness_at",
/// "precision_at", "fscore_at", "chamfer_m", "ghosting", "ghosting_judged"};
/// indented by `indent` spaces after each newline.
std::string map_accuracy_json(const eval::MapAccuracy& r, int indent = 0);
/// A fixed-width table, one row for the whole map and one per class
/// (accuracy in mm, completeness in % within each tau, F at 2 cm, ghosting).
std::string map_accuracy_table(const eval::MapAccuracy& r);

}  // namespace pvb::run
