// pvbench sweep: runs one scenario (or campaign) over a list of seeds, each
// seed as an independent child process `pvbench run ... --seed S --out
// DIR/seed_S` (`pvbench campaign ...` with --campaign)
// (this same binary, through /proc/self/exe), at most --jobs at once, then
// aggregates DIR/seed_*/metrics.json into DIR/aggregate.{md,csv,json,svg,png}
// and, with --compare, prints the paired PE-SLAM − baseline ATE line last
// (with --compare-sensors A,B the paired B − A line).
//
// Every seed's command is self-contained (--print-commands prints them), so
// a cluster scheduler can run them anywhere and `--aggregate-only` collects
// the results afterwards (docs/sweeps.md).
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "command.hpp"
#include "count_option.hpp"
#include "io_plan.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"
#include "pvb/eval/charts.hpp"
#include "pvb/plot/matrix.hpp"
#include "pvb/plot/png.hpp"
#include "pvb/campaign/campaign_run.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/suite/aggregate.hpp"
#include "pvb/suite/campaign_aggregate.hpp"
#include "pvb/suite/check.hpp"
#include "pvb/suite/metrics_file.hpp"
#include "pvb/suite/seeds.hpp"
#include "sensor_options.hpp"

namespace pvb::cli {
namespace {

namespace fs = std::filesystem;

/// Exit status when at least one seed failed or, with --check, a bound is
/// violated (the aggregate is still written).
constexpr int kSeedFailedExit = 3;
/// Exit status after Ctrl-C / SIGTERM (the aggregate of what finished is written).
constexpr int kInterruptedExit = 130;

struct SweepArgs {
  std::string scenario;
  std::string campaign;  ///< sweep a campaign instead of a scenario
  std::string seeds;
  std::string jobs_text = "1";  ///< --jobs, checked by parse_count
  int jobs = 1;
  std::string out;
  std::string frames_text;  ///< --frames, checked by parse_count
  int frames = 0;
  bool compare = false;
  std::string compare_sensors;  ///< --compare-sensors A,B, passed on to every run
  std::string sensors;          ///< --sensors, passed on to every run
  bool baseline = false;
  bool sync = false;
  bool no_map_eval = false;
  std::string gl;
  bool print_commands = false;
  bool aggregate_only = false;
  bool check = false;
  bool overwrite = false;
};

volatile std::sig_atomic_t g_stop_signal = 0;
extern "C" void sweep_on_stop_signal(int sig) { g_stop_signal = sig; }

std::string seed_dir(const std::string& out, std::uint64_t seed) {
  return (fs::path(out) / ("seed_" + std::to_string(seed))).string();
}

/// The arguments after the program name for one seed's `pvbench run`.
std::vector<std::string> run_args(const SweepArgs& a, std::uint64_t seed) {
  // --overwrite: a seed's command replaces that seed's earlier output, so
  // that a failed seed can be run again (the sweep folder itself is
  // checked once, by the sweep).
  std::vector<std::string> v = {"run",   "--scenario",         a.scenario, "--seed", std::to_string(seed),
                                "--out", seed_dir(a.out, seed), "--overwrite"};
  if (!a.campaign.empty()) v = {"campaign", "--campaign", a.campaign, "--seed", std::to_string(seed),
                                "--out",    seed_dir(a.out, seed), "--overwrite"};
  if (a.frames > 0) {
    v.push_back("--frames");
    v.push_back(std::to_string(a.frames));
  }
  if (a.compare) v.push_back("--compare");
  if (!a.compare_sensors.empty()) v.insert(v.end(), {"--compare-sensors", a.compare_sensors});
  if (!a.sensors.empty()) v.insert(v.end(), {"--sensors", a.sensors});
  if (a.baseline) v.push_back("--baseline");
  if (a.sync) v.push_back("--sync");
  if (a.no_map_eval) v.push_back("--no-map-eval");
  if (!a.gl.empty()) {
    v.push_back("--gl");
    v.push_back(a.gl);
  }
  return v;
}

std::string shell_quote(const std::string& s) {
  if (!s.empty() &&
      s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./=:,+@") ==
          std::string::npos)
    return s;
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string self_path() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("pvbench") : p.string();
}

/// One line of shell per seed: make the folder, run, log to stdout.log.
std::string seed_command(const SweepArgs& a, const std::string& exe, std::uint64_t seed) {
  const std::string dir = seed_dir(a.out, seed);
  std::string cmd = "mkdir -p " + shell_quote(dir) + " && " + shell_quote(exe);
  for (const auto& arg : run_args(a, seed)) cmd += " " + shell_quote(arg);
  return cmd + " > " + shell_quote(dir + "/stdout.log") + " 2>&1";
}

/// Starts `exe run ...` for one seed with stdout and stderr in DIR/seed_S/stdout.log.
pid_t start_seed(const SweepArgs& a, std::uint64_t seed) {
  const std::string dir = seed_dir(a.out, seed);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError(dir, "cannot create the seed folder: " + ec.message());
  const std::string log = dir + "/stdout.log";
  note_output(log);
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError(log, std::string("cannot open: ") + std::strerror(errno));
  std::vector<std::string> args = run_args(a, seed);
  args.insert(args.begin(), "pvbench");
  std::vector<char*> argv;
  for (auto& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fd);
    throw IoError(log, std::string("cannot start a child process: ") + std::strerror(errno));
  }
  if (pid == 0) {
    // Child: only async-signal-safe calls until exec.
    ::dup2(fd, STDOUT_FILENO);
    ::dup2(fd, STDERR_FILENO);
    ::execv("/proc/self/exe", argv.data());
    const char msg[] = "pvbench sweep: cannot exec /proc/self/exe\n";
    ssize_t ignored = ::write(STDERR_FILENO, msg, sizeof msg - 1);
    (void)ignored;
    ::_exit(127);
  }
  ::close(fd);
  return pid;
}

std::string describe_exit(int status) {
  if (WIFEXITED(status)) return "exit " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return std::string("killed by signal ") + std::to_string(WTERMSIG(status));
  return "ended";
}

std::string seed_summary(const suite::SeedRun& r) {
  if (!r.metrics) return "no metrics: " + r.error;
  const suite::RunMetrics& m = r.metrics->primary;
  auto mm = [](const std::optional<double>& v) {
    return v ? format_number("%.2f mm", *v * 1000.0) : std::string("n/a");
  };
  std::string s =
      m.status + ", ATE RMSE " + mm(m.ate_rmse_m) + ", " + std::to_string(m.lost_frames) + " lost";
  if (const std::optional<suite::RunMetrics>& b = r.metrics->baseline) {
    // --compare-sensors: the reference run is named by its sensors, as in the aggregate
    const bool by_sensors = b->sensors != m.sensors;
    s = (by_sensors ? m.sensors + ": " : std::string()) + s + ", " + (by_sensors ? b->sensors : "baseline") + " " +
        mm(b->ate_rmse_m);
  }
  return s;
}

/// The campaign file's name and sessions, which every seed's campaign.json must match.
suite::ExpectedCampaign expected_campaign(const run::Campaign& c) {
  suite::ExpectedCampaign e{c.file, c.name, {}};
  for (const run::CampaignSession& s : c.sessions)
    e.sessions.push_back({s.name, run::to_string(s.mode), s.map});
  return e;
}

std::string campaign_seed_summary(const suite::ExpectedCampaign& campaign, const std::string& dir,
                                  std::uint64_t seed) {
  const suite::CampaignSeed c = suite::read_campaign_seed(seed, dir + "/campaign.json");
  if (!c.error.empty()) return "no campaign figures: " + c.error;
  try {
    suite::expect_campaign_identity(c, campaign);
  } catch (const Error& e) {
    return std::string("refused: ") + e.what();
  }
  int completed = 0, wrong = 0;
  for (const auto& s : c.sessions) {
    completed += s.completed();
    wrong += s.wrong_place.value_or(0);
  }
  return std::to_string(completed) + " of " + std::to_string(c.sessions.size()) + " sessions completed, " +
         std::to_string(wrong) + " wrong-place poses";
}

/// Runs every seed, at most a.jobs at once.  Returns each seed's exit code
/// (-1 for a seed never started because the sweep was stopped).
std::map<std::uint64_t, int> run_seeds(const SweepArgs& a, const std::vector<std::uint64_t>& seeds,
                                       const suite::ExpectedCampaign* campaign = nullptr) {
  struct sigaction sa {};
  sa.sa_handler = sweep_on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: waitpid returns EINTR so the loop sees the flag
  struct sigaction old_int = {};
  struct sigaction old_term = {};
  ::sigaction(SIGINT, &sa, &old_int);
  ::sigaction(SIGTERM, &sa, &old_term);

  std::map<std::uint64_t, int> exit_codes;
  std::map<pid_t, std::uint64_t> running;
  std::size_t next = 0, done = 0;
  bool forwarded = false;
  while (next < seeds.size() || !running.empty()) {
    while (g_stop_signal == 0 && next < seeds.size() && static_cast<int>(running.size()) < a.jobs) {
      const std::uint64_t seed = seeds[next++];
      running[start_seed(a, seed)] = seed;
      std::printf("seed %llu: started (%s/stdout.log)\n", static_cast<unsigned long long>(seed),
                  seed_dir(a.out, seed).c_str());
      std::fflush(stdout);
    }
    if (g_stop_signal != 0 && !forwarded) {
      // Ctrl-C reaches the children through the terminal's process group;
      // a SIGTERM sent to the sweep alone is passed on so they write their
      // partial reports too.
      if (g_stop_signal == SIGTERM)
        for (const auto& [pid, seed] : running) ::kill(pid, SIGTERM);
      std::printf("sweep: stopping, waiting for %zu running seed(s)\n", running.size());
      std::fflush(stdout);
      forwarded = true;
    }
    if (running.empty()) break;
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      throw IoError("sweep", std::string("waitpid failed: ") + std::strerror(errno));
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const std::uint64_t seed = it->second;
    running.erase(it);
    ++done;
    const int code =
        WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    exit_codes[seed] = code;
    const std::string summary =
        campaign == nullptr
            ? seed_summary(suite::read_seed_run(seed, seed_dir(a.out, seed) + "/metrics.json", code))
            : campaign_seed_summary(*campaign, seed_dir(a.out, seed), seed);
    std::printf("[%zu/%zu] seed %llu: %s; %s\n", done, seeds.size(), static_cast<unsigned long long>(seed),
                describe_exit(status).c_str(), summary.c_str());
    if (code != 0) std::printf("  see %s/stdout.log\n", seed_dir(a.out, seed).c_str());
    std::fflush(stdout);
  }
  for (std::uint64_t s : seeds)
    if (!exit_codes.count(s)) exit_codes[s] = -1;
  ::sigaction(SIGINT, &old_int, nullptr);
  ::sigaction(SIGTERM, &old_term, nullptr);
  return exit_codes;
}

/// --aggregate-only reads an existing sweep folder: a missing one is said
/// to be missing, before any seed is read or anything written.
void require_sweep_folder(const std::string& out) {
  std::error_code ec;
  const fs::file_status st = fs::status(out, ec);
  if (st.type() == fs::file_type::not_found)
    throw IoError(out, "missing; expected the sweep folder that holds the seed_S folders");
  if (ec) throw IoError(out, "cannot read the sweep folder: " + ec.message());
  if (st.type() != fs::file_type::directory)
    throw IoError(out, "not a folder; expected the sweep folder that holds the seed_S folders");
}

/// Seeds with a DIR/seed_S folder, in numeric order.
std::vector<std::uint64_t> discover_seeds(const std::string& out) {
  std::vector<std::uint64_t> seeds;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out, ec)) {
    const std::string name = e.path().filename().string();
    if (!e.is_directory() || name.rfind("seed_", 0) != 0) continue;
    try {
      const auto s = suite::parse_seed_list(name.substr(5), "seed folder");
      if (s.size() == 1 && std::to_string(s[0]) == name.substr(5)) seeds.push_back(s[0]);
    } catch (const ConfigError&) {
    }
  }
  if (ec) throw IoError(out, "cannot list the sweep folder: " + ec.message());
  std::sort(seeds.begin(), seeds.end());
  return seeds;
}

suite::SweepAggregate write_aggregate(const SweepArgs& a, const std::string& scenario_name,
                                      const std::vector<std::uint64_t>& seeds,
                                      const std::map<std::uint64_t, int>& exit_codes) {
  std::vector<suite::SeedRun> runs;
  // Without --scenario, the first seed with metrics names the sweep's scenario.
  std::string expected = scenario_name;
  std::string expected_source = a.scenario;
  for (std::uint64_t s : seeds) {
    const auto it = exit_codes.find(s);
    const int code = it == exit_codes.end() ? 0 : it->second;
    suite::SeedRun r = suite::read_seed_run(s, seed_dir(a.out, s) + "/metrics.json", code);
    if (code == -1 && !r.metrics) r.error = "not run (the sweep was stopped)";
    // A seed folder holds that seed's run of this scenario, or the sweep
    // would report another run as this seed, judged by the wrong bounds.
    if (r.metrics) {
      suite::expect_run_identity(*r.metrics, expected, expected_source, s, "the folder seed_" + std::to_string(s));
      if (expected.empty()) {
        expected = r.metrics->scenario;
        expected_source = "the sweep's other seeds";
      }
    }
    runs.push_back(std::move(r));
  }
  std::string name = scenario_name;
  if (name.empty())
    for (const auto& r : runs)
      if (r.metrics && !r.metrics->scenario.empty()) {
        name = r.metrics->scenario;
        break;
      }
  const suite::SweepAggregate agg = suite::aggregate(name, std::move(runs));
  const fs::path out(a.out);
  write_file((out / "aggregate.md").string(), suite::format_markdown(agg));
  write_file((out / "aggregate.csv").string(), suite::format_csv(agg));
  write_file((out / "aggregate.json").string(), suite::format_json(agg));
  const eval::Figure fig = suite::make_sweep_figure(agg);
  write_file((out / "aggregate.svg").string(), eval::format_svg(fig));
  plot::write_png(fig, (out / "aggregate.png").string());
  std::printf("\n%s\nwrote %s/aggregate.{md,csv,json,svg,png}\n", suite::format_markdown(agg).c_str(),
              a.out.c_str());
  // With --compare (--compare-sensors), the paired figure is the sweep's answer: last.
  if (agg.has_baseline) std::printf("%s\n", suite::format_paired_line(agg.paired).c_str());
  std::fflush(stdout);
  return agg;
}

/// A campaign sweep: DIR/aggregate.{md,json} per session and the matrix of
/// the mean shares within (0.25 m, 2 deg).  Returns the seeds that failed.
int write_campaign_aggregate(const SweepArgs& a, const suite::ExpectedCampaign& campaign,
                             const std::vector<std::uint64_t>& seeds) {
  std::vector<suite::CampaignSeed> runs;
  for (std::uint64_t s : seeds) {
    runs.push_back(suite::read_campaign_seed(s, seed_dir(a.out, s) + "/campaign.json"));
    // A seed folder holds that seed's run of this campaign, or the sweep
    // would report another campaign's sessions as these.
    if (runs.back().error.empty()) suite::expect_campaign_identity(runs.back(), campaign);
  }
  const suite::CampaignAggregate agg = suite::aggregate_campaign(campaign, runs);
  const fs::path out(a.out);
  write_file((out / "aggregate.md").string(), suite::format_campaign_markdown(agg));
  write_file((out / "aggregate.json").string(), suite::format_campaign_json(agg));
  std::vector<run::MatrixSession> sessions;
  for (const auto& g : agg.sessions) {
    const run::SessionMode mode = g.mode == "map"        ? run::SessionMode::kMap
                                  : g.mode == "localise" ? run::SessionMode::kLocalise
                                                         : run::SessionMode::kExtend;
    sessions.push_back({g.name, mode, g.map, g.high.count > 0 ? std::optional<double>(g.high.mean) : std::nullopt});
  }
  const plot::MatrixFigure m = run::campaign_matrix(
      "campaign " + agg.campaign + ", " + std::to_string(seeds.size()) + " seeds: mean share within 0.25 m, 2 deg",
      sessions);
  plot::write_matrix(m, (out / "matrix").string());
  std::printf("\n%s\nwrote %s/aggregate.{md,json}, matrix.{svg,png}\n", suite::format_campaign_markdown(agg).c_str(),
              a.out.c_str());
  std::fflush(stdout);
  int failed = static_cast<int>(agg.seed_errors.size());
  for (const auto& g : agg.sessions) failed += g.failed;
  return failed;
}

/// --check: every seed against the scenario's single-run bounds and the sweep
/// against expect.sweep; one line per violation (or one "ok" line).  Returns
/// true when everything holds.
bool check_sweep_and_print(const std::string& scenario_file, const suite::SweepAggregate& agg) {
  const scenes::Scenario s = scenes::load_scenario(scenario_file);
  std::vector<std::string> notes;
  const std::vector<suite::Violation> violations = suite::check_sweep(s.expect, agg, &notes);
  for (const auto& n : notes) std::printf("check: note: %s\n", n.c_str());
  for (const auto& v : violations) std::printf("check: %s\n", v.line().c_str());
  if (violations.empty()) std::printf("check: ok (%s, %zu seeds)\n", s.name.c_str(), agg.runs.size());
  std::fflush(stdout);
  return violations.empty();
}

/// The sweep's outputs against its inputs (`plan`): the folder, or with
/// --aggregate-only the aggregate files written into it.
void check_sweep_paths(const SweepArgs& a, IoPlan* plan, const std::vector<std::string>& aggregate_files) {
  if (!a.aggregate_only) {
    plan->output_folder("--out", a.out);
  } else {
    for (const std::string& f : aggregate_files) plan->output_file("--out", (fs::path(a.out) / f).string());
  }
  plan->check();
}

/// --sensors and --compare-sensors, checked before any seed runs (each run
/// checks them again).
void check_sensor_flags(const SweepArgs& a) {
  if (!a.sensors.empty()) run::parse_sensors_option(a.sensors, "--sensors");
  if (a.compare_sensors.empty()) return;
  if (a.compare || !a.sensors.empty())
    throw ConfigError("command line", "--compare-sensors", "without --compare and --sensors");
  run::parse_sensor_pair_option(a.compare_sensors, "--compare-sensors");
}

/// A sweep of a campaign: each seed a `pvbench campaign` child process.
int run_campaign_sweep(const SweepArgs& a) {
  if (!a.scenario.empty() || a.compare || a.baseline || a.check || !a.sensors.empty() ||
      !a.compare_sensors.empty())
    throw ConfigError("command line", "--campaign",
                      "no --scenario, --compare, --compare-sensors, --sensors, --baseline or --check with it");
  // Validates the file early: every session's scenario, before any seed runs.
  const run::Campaign campaign = run::load_campaign(a.campaign);
  const suite::ExpectedCampaign expected = expected_campaign(campaign);
  IoPlan plan;
  add_campaign_inputs(&plan, "--campaign", campaign);
  if (a.aggregate_only) require_sweep_folder(a.out);
  check_sweep_paths(a, &plan, {"aggregate.md", "aggregate.json", "matrix.svg", "matrix.png"});
  std::vector<std::uint64_t> seeds;
  if (a.aggregate_only) {
    seeds = a.seeds.empty() ? discover_seeds(a.out) : suite::parse_seed_list(a.seeds);
    if (seeds.empty()) throw ConfigError(a.out, "seed_*/campaign.json", "at least one seed folder", "none");
    return write_campaign_aggregate(a, expected, seeds) > 0 ? kSeedFailedExit : 0;
  }
  if (a.seeds.empty()) throw ConfigError("command line", "--seeds", "a seed list like 1-20, 1,3,5 or 1-5,9");
  seeds = suite::parse_seed_list(a.seeds);
  if (a.print_commands) {
    const std::string exe = self_path();
    for (std::uint64_t s : seeds) std::printf("%s\n", seed_command(a, exe, s).c_str());
    return 0;
  }
  prepare_output_folder(a.out, a.overwrite, "sweep");
  std::printf("sweep: campaign %s, %zu seed(s), %d at once, into %s\n", campaign.name.c_str(), seeds.size(), a.jobs,
              a.out.c_str());
  run_seeds(a, seeds, &expected);
  const int failed = write_campaign_aggregate(a, expected, seeds);
  if (g_stop_signal != 0) return kInterruptedExit;
  return failed > 0 ? kSeedFailedExit : 0;
}

int run_sweep(SweepArgs a) {
  a.jobs = static_cast<int>(parse_count("sweep", "--jobs", a.jobs_text, 1, 1024));
  if (!a.frames_text.empty())
    a.frames = static_cast<int>(parse_count("sweep", "--frames", a.frames_text, 1, 10'000'000));
  if (a.compare && a.baseline)
    throw ConfigError("command line", "--baseline", "either --compare or --baseline, not both");
  check_sensor_flags(a);
  if (!a.campaign.empty()) return run_campaign_sweep(a);
  std::string scenario_name;
  IoPlan plan;
  if (!a.scenario.empty()) {
    const scenes::Scenario scenario = scenes::load_scenario(a.scenario);  // validates the file early
    scenario_name = scenario.name;
    add_scenario_inputs(&plan, "--scenario", scenario);
  } else if (!a.aggregate_only) {
    throw ConfigError("command line", "--scenario", "a scenario file (or --campaign)");
  }
  if (a.aggregate_only) require_sweep_folder(a.out);
  check_sweep_paths(a, &plan,
                    {"aggregate.md", "aggregate.csv", "aggregate.json", "aggregate.svg", "aggregate.png"});

  if (a.check && a.scenario.empty())
    throw ConfigError("command line", "--check", "a --scenario whose expect: section judges the sweep");
  if (a.aggregate_only) {
    const std::vector<std::uint64_t> seeds =
        a.seeds.empty() ? discover_seeds(a.out) : suite::parse_seed_list(a.seeds);
    if (seeds.empty()) throw ConfigError(a.out, "seed_*/metrics.json", "at least one seed folder", "none");
    const suite::SweepAggregate agg = write_aggregate(a, scenario_name, seeds, {});
    const bool holds = !a.check || check_sweep_and_print(a.scenario, agg);
    return agg.failed > 0 || !holds ? kSeedFailedExit : 0;
  }
  if (a.seeds.empty()) throw ConfigError("command line", "--seeds", "a seed list like 1-20, 1,3,5 or 1-5,9");
  const std::vector<std::uint64_t> seeds = suite::parse_seed_list(a.seeds);
  if (a.print_commands) {
    const std::string exe = self_path();
    for (std::uint64_t s : seeds) std::printf("%s\n", seed_command(a, exe, s).c_str());
    return 0;
  }
  prepare_output_folder(a.out, a.overwrite, "sweep");
  std::printf("sweep: %s, %zu seed(s), %d at once, into %s\n", scenario_name.c_str(), seeds.size(), a.jobs,
              a.out.c_str());
  const std::map<std::uint64_t, int> exit_codes = run_seeds(a, seeds);
  const suite::SweepAggregate agg = write_aggregate(a, scenario_name, seeds, exit_codes);
  if (g_stop_signal != 0) {
    std::printf("sweep: stopped by signal %d; the aggregate covers the seeds that wrote metrics\n",
                static_cast<int>(g_stop_signal));
    return kInterruptedExit;
  }
  if (agg.failed > 0) std::printf("sweep: %d seed(s) failed\n", agg.failed);
  const bool holds = !a.check || check_sweep_and_print(a.scenario, agg);
  return agg.failed > 0 || !holds ? kSeedFailedExit : 0;
}

}  // namespace

Command add_sweep_command(CLI::App& app) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* sub = app.add_subcommand(
      "sweep", "Run a scenario over many seeds in parallel processes and aggregate the results");
  sub->add_option("--scenario", args->scenario, "scenario YAML file")
      ->check(path_check("sweep", "--scenario"));
  sub->add_option("--campaign", args->campaign,
                  "campaign YAML file: sweep pvbench campaign instead of pvbench run")
      ->check(path_check("sweep", "--campaign"));
  sub->add_option("--seeds", args->seeds, "seed list: 1-20, 1,3,5 or 1-5,9");
  sub->add_option("--jobs,-j", args->jobs_text, "seeds run at once")->capture_default_str();
  sub->add_option("--out", args->out,
                  "sweep folder (DIR/seed_S per seed, DIR/aggregate.*; refused when not empty)")
      ->required()
      ->check(path_check("sweep", "--out"));
  sub->add_flag("--overwrite", args->overwrite, "empty an earlier pvbench output in --out first");
  sub->add_option("--frames", args->frames_text, "passed to pvbench run: at most N frames");
  sub->add_flag("--compare", args->compare, "passed to pvbench run: PE-SLAM and the baseline (PE-match off)");
  sub->add_flag("--baseline", args->baseline, "passed to pvbench run: the baseline alone (PE-match off)");
  sub->add_option("--compare-sensors", args->compare_sensors,
                  "passed to pvbench run: A,B, two sensor setups on the same frames; paired B − A per seed");
  add_sensors_option(sub, &args->sensors);
  sub->add_flag("--sync", args->sync, "passed to pvbench run: synchronous, bit-reproducible SLAM");
  sub->add_flag("--no-map-eval", args->no_map_eval, "passed to pvbench run: dense maps written, not scored");
  sub->add_option("--gl", args->gl, "passed to pvbench run: rendering backend")
      ->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  sub->add_flag("--print-commands", args->print_commands,
                "print one self-contained shell command per seed (for Slurm, GNU parallel) and exit");
  sub->add_flag("--aggregate-only", args->aggregate_only,
                "only aggregate existing DIR/seed_*/metrics.json (after a cluster run)");
  sub->add_flag("--check", args->check,
                "judge every seed by the scenario's expect: bounds and the sweep by expect.sweep (exit 3)");
  return {sub, [args] { return run_sweep(*args); }};
}

}  // namespace pvb::cli
