// pvbench map-check: is a SLAM map's error noise or bias?  Re-runs a global
// bundle adjustment of a map written by `pvbench slam --dump-map`, started
// from ground truth, with the measurements as they are and with synthetic
// ones (harness/run/map_check.hpp).
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include "command.hpp"
#include "count_option.hpp"
#include "pvb/common/error.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/run/map_check.hpp"
#include "pvb/slam/core/map_snapshot.hpp"

namespace pvb::cli {
namespace {

struct MapCheckArgs {
  std::string map;
  std::string gt;
  int draws = 20;
  std::uint32_t seed = 1;
  double max_diff_s = 0.02;
};

int run_map_check(const MapCheckArgs& a) {
  std::ifstream is(a.map);
  if (!is) throw IoError(a.map, "cannot open for reading");
  const slam::MapSnapshot map = slam::read_map_snapshot(is, a.map);
  const eval::Trajectory gt = eval::read_tum(a.gt);
  run::MapCheckOptions o;
  o.draws = a.draws;
  o.seed = a.seed;
  o.max_time_diff_s = a.max_diff_s;
  const run::MapCheckResult r = run::check_map(map, gt, o);
  std::fputs(run::format_map_check(r).c_str(), stdout);
  return 0;
}

}  // namespace

Command add_map_check_command(CLI::App& app) {
  auto args = std::make_shared<MapCheckArgs>();
  CLI::App* sub = app.add_subcommand(
      "map-check", "global BA of a dumped map (pvbench slam --dump-map) from ground truth: bias or noise?");
  sub->add_option("--map", args->map, "Map.txt written by pvbench slam --dump-map")
      ->required()
      ->check(path_check("map-check", "--map"));
  sub->add_option("--gt", args->gt, "ground-truth trajectory (TUM format)")
      ->required()
      ->check(path_check("map-check", "--gt"));
  sub->add_option("--draws", args->draws, "synthetic draws per noise kind")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  sub->add_option("--seed", args->seed, "seed of the first draw")
      ->capture_default_str()
      ->check(seed_check("map-check", "--seed"));
  sub->add_option("--max-diff", args->max_diff_s, "keyframe to ground-truth association, s")
      ->capture_default_str();
  return {sub, [args] { return run_map_check(*args); }};
}

}  // namespace pvb::cli
