// pvbench eval: ATE/RPE of one or more estimated trajectories against ground
// truth, as a table on stdout, optionally as JSON and as plots.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "command.hpp"
#include "count_option.hpp"
#include "pvb/common/io_paths.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/text.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/eval/charts.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/plot/png.hpp"

namespace pvb::cli {
namespace {

struct EvalArgs {
  std::string gt;
  std::vector<std::string> est;
  std::string format = "tum";
  std::string gt_timestamps;
  std::vector<std::string> est_timestamps;
  std::string align = "se3";
  double max_diff_s = 0.02;
  double offset_s = 0.0;
  double delta = 1.0;
  std::string delta_unit = "f";
  std::string rpe_pairs = "all";
  std::string json;
  std::string plot;
};

/// "out/run.svg" + k -> "out/run_k.svg"; k == 0 keeps the name.
std::string numbered(const std::string& path, std::size_t k) {
  if (k == 0) return path;
  const std::size_t slash = path.find_last_of('/');
  const std::size_t dot = path.find_last_of('.');
  const std::string suffix = "_" + std::to_string(k + 1);
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return path + suffix;
  return path.substr(0, dot) + suffix + path.substr(dot);
}

/// "plot.svg" -> "plot.png"; other names get ".png" appended.
std::string png_beside(const std::string& svg_path) {
  const std::string ext = ".svg";
  if (svg_path.size() > ext.size() && svg_path.compare(svg_path.size() - ext.size(), ext.size(), ext) == 0)
    return svg_path.substr(0, svg_path.size() - ext.size()) + ".png";
  return svg_path + ".png";
}

std::string base_name(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string text_of(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// What eval reads and writes: an output never replaces a trajectory or a
/// timestamps file, nor another output (each --plot figure and its PNG).
void check_eval_paths(const EvalArgs& a, std::size_t figures) {
  IoPlan plan;
  plan.input("the --gt trajectory", a.gt).inputs("an --est trajectory", a.est);
  plan.input("the --timestamps file", a.gt_timestamps).inputs("an --est-timestamps file", a.est_timestamps);
  plan.output_file("--json", a.json);
  bool stream = false;
  try {
    stream = !a.plot.empty() && resolve_output_target(a.plot).kind == OutputTarget::Kind::kStream;
  } catch (const IoError&) {  // a folder, a socket: the plan names it
  }
  if (stream || a.plot.empty()) {
    plan.output_file("--plot", a.plot);
  } else {
    for (std::size_t k = 0; k < figures; ++k)
      plan.output_file("--plot", numbered(a.plot, k))
          .output_file("--plot (PNG)", png_beside(numbered(a.plot, k)));
  }
  plan.check();
}

int run_eval(const EvalArgs& a) {
  check_eval_paths(a, a.est.size());
  eval::TrajectoryFormat format = eval::TrajectoryFormat::kTum;
  if (a.format == "kitti") format = eval::TrajectoryFormat::kKitti;
  else if (a.format != "tum") throw ConfigError("command line", "--format", "tum or kitti", a.format);
  // KITTI estimates share the ground truth's timestamps file unless each has its own.
  std::vector<std::string> est_timestamps = a.est_timestamps;
  if (est_timestamps.empty()) est_timestamps.assign(a.est.size(), a.gt_timestamps);
  if (format == eval::TrajectoryFormat::kKitti && est_timestamps.size() != a.est.size())
    throw ConfigError("command line", "--est-timestamps",
                      "one timestamps file per --est (" + std::to_string(a.est.size()) + ")",
                      std::to_string(est_timestamps.size()));

  eval::EvalOptions options;
  options.association.max_diff_s = a.max_diff_s;
  options.association.offset_s = a.offset_s;
  options.alignment = eval::parse_alignment(a.align);
  options.rpe.delta = a.delta;
  options.rpe.unit = eval::parse_delta_unit(a.delta_unit);
  options.rpe.pairs = eval::parse_pair_mode(a.rpe_pairs);
  if (!(a.max_diff_s > 0.0 && a.max_diff_s <= eval::kMaxAssociationDiffS))
    throw ConfigError("command line", "--max-diff", "a number of seconds in (0, 1e9]", text_of(a.max_diff_s));
  if (!(std::fabs(a.offset_s) <= geom::kMaxAbsTimeS))
    throw ConfigError("command line", "--offset", "a number of seconds in [-9e9, 9e9]", text_of(a.offset_s));
  if (!(a.delta > 0.0 && std::isfinite(a.delta)))
    throw ConfigError("command line", "--delta", "a positive number", text_of(a.delta));

  const eval::Trajectory gt = eval::read_trajectory(a.gt, format, a.gt_timestamps);
  std::vector<eval::EvalResult> results;
  for (std::size_t k = 0; k < a.est.size(); ++k) {
    const eval::Trajectory est =
        eval::read_trajectory(a.est[k], format, est_timestamps[k]);
    results.push_back(eval::evaluate(gt, est, options));
  }

  std::printf("ground truth %s (%zu poses)\n", a.gt.c_str(), gt.size());
  for (const eval::EvalResult& r : results) std::printf("\n%s", eval::format_report(r).c_str());
  if (results.size() > 1) std::printf("\ncomparison\n%s", eval::format_comparison(results).c_str());

  if (!a.json.empty()) write_file(a.json, eval::format_json_document(a.gt, results));
  if (!a.plot.empty()) {
    // A stream (--plot /dev/stdout, a FIFO) gets every figure's SVG, one
    // after the other, and nothing is created beside it.
    const bool stream = resolve_output_target(a.plot).kind == OutputTarget::Kind::kStream;
    for (std::size_t k = 0; k < results.size(); ++k) {
      const eval::Figure fig =
          eval::make_error_figure(results[k], "Trajectory error: " + base_name(results[k].est_source));
      if (stream) {
        write_file(a.plot, eval::format_svg(fig));
        continue;
      }
      const std::string svg = numbered(a.plot, k);
      write_file(svg, eval::format_svg(fig));
      plot::write_png(fig, png_beside(svg));
      std::printf("plot: %s, %s\n", svg.c_str(), png_beside(svg).c_str());
    }
  }
  return 0;
}

}  // namespace

Command add_eval_command(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* sub = app.add_subcommand("eval", "ATE and RPE of estimated trajectories against ground truth");
  sub->add_option("--gt", args->gt, "ground-truth trajectory")->required()->check(path_check("eval", "--gt"));
  sub->add_option("--est", args->est,
                  "estimated trajectory (repeat to compare runs; the first is the reference)")
      ->required()
      ->check(path_check("eval", "--est"));
  sub->add_option("--format", args->format, "trajectory format: tum or kitti")
      ->check(CLI::IsMember({"tum", "kitti"}))
      ->capture_default_str();
  sub->add_option("--timestamps", args->gt_timestamps, "KITTI: timestamps file of the ground truth")
      ->check(path_check("eval", "--timestamps"));
  sub->add_option("--est-timestamps", args->est_timestamps,
                  "KITTI: timestamps file of each --est, in order (default: --timestamps)")
      ->check(path_check("eval", "--est-timestamps"));
  sub->add_option("--align", args->align, "alignment: se3, sim3, none or origin")
      ->check(CLI::IsMember({"se3", "sim3", "none", "origin"}))
      ->capture_default_str();
  sub->add_option("--max-diff", args->max_diff_s, "association: maximum time difference, s")->capture_default_str();
  sub->add_option("--offset", args->offset_s, "association: offset added to estimate times, s")
      ->capture_default_str();
  sub->add_option("--delta", args->delta, "RPE delta, in --delta-unit")->capture_default_str();
  sub->add_option("--delta-unit", args->delta_unit, "RPE delta unit: f (frames), s (seconds), m (metres)")
      ->check(CLI::IsMember({"f", "s", "m"}))
      ->capture_default_str();
  sub->add_option("--rpe-pairs", args->rpe_pairs, "RPE pairs: all (every start pose) or consecutive")
      ->check(CLI::IsMember({"all", "consecutive"}))
      ->capture_default_str();
  sub->add_option("--json", args->json, "write the results as JSON to this file")
      ->check(path_check("eval", "--json"));
  sub->add_option("--plot", args->plot,
                  "write the error figure as SVG here, and PNG beside it (_2, _3... for further --est)")
      ->check(path_check("eval", "--plot"));
  return {sub, [args] { return run_eval(*args); }};
}

}  // namespace pvb::cli
