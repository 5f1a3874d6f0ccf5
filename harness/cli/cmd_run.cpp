// pvbench run: simulation in the loop.  The simulator renders the scenario
// and feeds PE-SLAM in memory; the report folder gets metrics.json,
// trajectories, figures, a contact sheet, run.log and index.html.
// Ctrl-C (SIGINT/SIGTERM) stops the loop and writes the partial report.
#include <cstdio>
#include <memory>
#include <optional>

#include "check_report.hpp"
#include "command.hpp"
#include "count_option.hpp"
#include "map_options.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/progress.hpp"
#include "pvb/run/run.hpp"
#include "sensor_options.hpp"
#include "stop_signals.hpp"

namespace pvb::cli {
namespace {

struct RunArgs {
  run::RunOptions options;
  std::string frames;  ///< --frames, checked by parse_count
  std::optional<std::uint64_t> seed;
  bool baseline = false;
  bool no_loop_closing = false;
  bool no_map_eval = false;
  bool compare = false;
  bool check = false;
  bool no_pace = false;
  std::string map_mode;
  std::string sensors;          ///< --sensors
  std::string compare_sensors;  ///< --compare-sensors A,B
};

int run_run(RunArgs& a) {
  if (a.baseline && a.compare)
    throw ConfigError("pvbench run", "--baseline/--compare", "at most one of them");
  run::RunOptions& o = a.options;
  o.sensors = sensors_from_flag(a.sensors);
  if (!a.compare_sensors.empty()) {
    if (a.compare || o.sensors)
      throw ConfigError("pvbench run", "--compare-sensors", "without --compare and --sensors");
    o.compare_sensors = run::parse_sensor_pair_option(a.compare_sensors, "--compare-sensors");
  }
  if (!a.frames.empty())
    o.max_frames = static_cast<int>(parse_count("run", "--frames", a.frames, 1, 10'000'000));
  o.seed = a.seed;
  if (!a.map_mode.empty()) o.map.use = run::parse_map_use(a.map_mode, "--map-mode");
  if (o.map.allow_other_station && o.map.load_path.empty())  // as --map-mode: refused, not ignored
    throw ConfigError("command line", "--allow-other-station",
                      "a --map to use (it lets a map of another station be used)");
  o.pace = !a.no_pace;
  o.loop_closing = !a.no_loop_closing;
  o.map_eval = !a.no_map_eval;
  o.mode = a.compare    ? run::SlamMode::kCompare
           : a.baseline ? run::SlamMode::kBaseline
                        : run::SlamMode::kPeSlam;
  o.stop = &StopSignals::flag();
  o.on_log = [](const std::string& line) {
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  std::unique_ptr<ProgressBar> bar;
  o.on_progress = [&bar](std::size_t done, std::size_t total) {
    if (!bar) bar = std::make_unique<ProgressBar>("run", total);
    bar->update(done);
  };
  const StopSignals signals;
  const run::RunReport report = run::run_scenario(o);
  if (bar) bar->finish();
  std::printf("report: %s/index.html (metrics.json, trajectories, figures, run.log)\n", o.out_dir.c_str());
  std::fflush(stdout);
  if (report.status == run::RunStatus::kFailed)  // after the report: it is kept
    throw IoError(o.scenario_file, report.status_detail + "; the report is in " + o.out_dir);
  const int code = run::exit_code(report.status);
  if (!a.check || report.status == run::RunStatus::kInterrupted) return code;
  // --check: the scenario's expect: bounds judge the run.  An aborted run
  // (on_loss: abort) passes when the scenario expects tracking to be lost.
  return check_and_print(o.scenario_file, o.out_dir + "/metrics.json", report.seed, code);
}

}  // namespace

Command add_run_command(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* sub = app.add_subcommand(
      "run", "simulate a scenario and run PE-SLAM on it in memory; write a report folder (index.html)");
  sub->add_option("--scenario", args->options.scenario_file, "scenario YAML file")
      ->required()
      ->check(path_check("run", "--scenario"));
  sub->add_option("--out", args->options.out_dir, "report folder (created; refused when not empty)")
      ->required()
      ->check(path_check("run", "--out"));
  sub->add_flag("--overwrite", args->options.overwrite, "empty an earlier pvbench output in --out first");
  sub->add_option("--seed", args->seed, "override the scenario's seed (also seeds PE-match)")
      ->check(seed_check("run", "--seed", std::numeric_limits<std::uint64_t>::max()));
  sub->add_option("--frames", args->frames, "stop after N frames (default: the scenario's duration)");
  sub->add_flag("--sync", args->options.sync, "synchronous: no threads, bit-identical runs");
  sub->add_flag("--no-loop-closing", args->no_loop_closing,
                "switch loop closing off (LoopClosing.enabled: 0)");
  sub->add_flag("--no-map-eval", args->no_map_eval,
                "write the dense maps without scoring them against the true surface");
  sub->add_flag("--baseline", args->baseline,
                "run the baseline (PE-match off: ORB-SLAM2's motion model) instead of PE-SLAM");
  sub->add_flag("--compare", args->compare, "run PE-SLAM and the baseline on the same rendered frames");
  add_sensors_option(sub, &args->sensors);
  sub->add_option("--compare-sensors", args->compare_sensors,
                  "A,B: two sensor setups on the same rendered frames; B is the primary run, A the reference "
                  "(in baseline/)");
  sub->add_flag("--closed-loop", args->options.closed_loop,
                "the route follower steers from the SLAM pose instead of ground truth");
  sub->add_option("--gl", args->options.gl, "rendering backend")
      ->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  sub->add_flag("--no-pace", args->no_pace,
                "pipelined: run the stages as fast as they go instead of at the camera's frame rate");
  sub->add_option("--mapping-nice", args->options.mapping_nice,
                  "pipelined: nice value of the local/dense mapping workers (default 10 when paced, else 0)")
      ->check(CLI::Range(-20, 19));
  add_map_options(sub, &args->options.map, &args->map_mode);
  sub->add_flag(
      "--allow-other-station", args->options.map.allow_other_station,
      "use a --map whose META names another station (scenario file or station seed) after a warning");
  sub->add_option("--start-m", args->options.start_m,
                  "start this many metres along the route (overrides the scenario's route.start_m)");
  sub->add_flag("--check", args->check, "check metrics.json against the scenario's expect: bounds (exit 3)");
  return {sub, [args] { return run_run(*args); }};
}

}  // namespace pvb::cli
