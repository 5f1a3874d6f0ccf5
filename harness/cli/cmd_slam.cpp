// pvbench slam: runs PE-SLAM (or its ORB-SLAM2 baseline) on a TUM RGB-D
// folder (the pipeline: pvb/run/offline_slam.hpp).  This file parses the
// flags and prints what the pipeline reports.
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "command.hpp"
#include "count_option.hpp"
#include "map_options.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/progress.hpp"
#include "pvb/run/offline_slam.hpp"
#include "sensor_options.hpp"
#include "stop_signals.hpp"

namespace pvb::cli {
namespace {

struct SlamArgs {
  run::OfflineSlamOptions options;
  std::optional<std::uint32_t> seed;  ///< --seed; else the recording's own, else the default
  std::string map_mode;
  std::string sensors;  ///< --sensors
};

int run_slam(SlamArgs a) {
  run::OfflineSlamOptions& o = a.options;
  o.sensors = sensors_from_flag(a.sensors);
  if (!a.map_mode.empty()) o.map.use = run::parse_map_use(a.map_mode, "--map-mode");
  run::resolve_offline_seed(a.seed, &o);
  // A map of another station than the recording's is used after a warning.
  o.map.station = run::recording_station(o.sequence + "/meta.json");
  o.map.allow_other_station = true;
  o.on_text = [](const std::string& text) { std::fputs(text.c_str(), stdout); };
  o.on_warning = [](const std::string& line) { std::fprintf(stderr, "pvbench slam: %s\n", line.c_str()); };
  std::unique_ptr<ProgressBar> bar;
  o.on_progress_begin = [&bar](const std::string& label, std::size_t total) {
    bar = std::make_unique<ProgressBar>(label, total);
  };
  o.on_progress = [&bar](std::size_t done, const std::string& state) { bar->update(done, state); };
  o.on_progress_end = [&bar] { bar->finish(); };
  o.stop = &StopSignals::flag();
  run::OfflineSlam slam(o);
  // Ctrl-C (or SIGTERM) stops taking frames; everything tracked so far is
  // still written and evaluated, and the exit code is 130.
  const StopSignals stop_signals;
  return slam.run();
}

}  // namespace

Command add_slam_command(CLI::App& app) {
  auto args = std::make_shared<SlamArgs>();
  CLI::App* sub = app.add_subcommand("slam", "run PE-SLAM (RGB-D) on a TUM-format sequence folder");
  sub->add_option("--sequence", args->options.sequence, "TUM RGB-D sequence folder")
      ->required()
      ->check(path_check("slam", "--sequence"));
  sub->add_option("--settings", args->options.settings, "ORB-SLAM2 RGB-D settings YAML (plus optional PEMatch.*)")
      ->required()
      ->check(path_check("slam", "--settings"));
  sub->add_option("--out", args->options.out, "output folder (created; refused when not empty)")
      ->required()
      ->check(path_check("slam", "--out"));
  sub->add_flag("--overwrite", args->options.overwrite, "empty an earlier pvbench output in --out first");
  sub->add_flag("--no-pe-match", args->options.no_pe_match, "baseline: ORB-SLAM2 motion model without PE-match");
  sub->add_flag("--no-dense", args->options.no_dense, "skip the dense point-cloud map (PointCloud.ply)");
  sub->add_flag("--sync", args->options.sync, "synchronous mode: no worker threads, bit-identical runs");
  sub->add_option("--seed", args->seed,
                  "PE-match seed (default: the recording's own seed from its meta.json, else 1)")
      ->check(seed_check("slam", "--seed"));
  sub->add_option("--max-frames", args->options.max_frames, "stop after this many frames (0: all)")
      ->capture_default_str();
  sub->add_flag("--dump-matches", args->options.dump_matches,
                "score the motion model's coarse matches against groundtruth.txt: motion_matches.csv, "
                "stats.json motion_matches");
  sub->add_flag(
      "--dump-map", args->options.dump_map,
      "write the final sparse map with every keypoint measurement to Map.txt (for pvbench map-check)");
  sub->add_option(
         "--max-missing", args->options.max_missing,
         "stop (exit 1, outputs kept) when more than this share of the frames, 0 to 1, and more than 5 "
         "frames are missing or corrupt")
      ->capture_default_str();
  add_map_options(sub, &args->options.map, &args->map_mode);
  add_sensors_option(sub, &args->sensors);
  return {sub, [args] { return run_slam(*args); }};
}

}  // namespace pvb::cli
