// pvbench campaign: the sessions of a campaign file in order (map,
// localise, extend), the maps passed along, one report for all
// (docs/map_reuse.md).  Ctrl-C stops after the running session's partial
// report; campaign.json lists it as interrupted and the sessions after it
// as not run.
#include <cstdio>
#include <memory>
#include <optional>

#include "command.hpp"
#include "count_option.hpp"
#include "io_plan.hpp"
#include "pvb/common/error.hpp"
#include "pvb/campaign/campaign_run.hpp"
#include "stop_signals.hpp"

namespace pvb::cli {
namespace {

struct CampaignArgs {
  run::CampaignOptions options;
  std::optional<std::uint64_t> seed;
  std::string frames;
  bool no_map_eval = false;
};

int run_campaign_command(CampaignArgs& a) {
  run::CampaignOptions& o = a.options;
  o.seed = a.seed;
  if (!a.frames.empty())
    o.max_frames = static_cast<int>(parse_count("campaign", "--frames", a.frames, 1, 10'000'000));
  o.map_eval = !a.no_map_eval;
  o.stop = &StopSignals::flag();
  o.on_log = [](const std::string& line) {
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  IoPlan plan;
  add_campaign_inputs(&plan, "--campaign", run::load_campaign(o.campaign_file));
  plan.output_folder("--out", o.out_dir).check();
  const StopSignals signals;
  const run::CampaignReport report = run::run_campaign(o);
  std::printf("campaign report: %s/index.html (campaign.json, campaign.md, matrix.png)\n", o.out_dir.c_str());
  return run::campaign_exit_code(report);
}

}  // namespace

Command add_campaign_command(CLI::App& app) {
  auto args = std::make_shared<CampaignArgs>();
  CLI::App* sub = app.add_subcommand(
      "campaign", "run the sessions of a campaign file (one station over several days) and report them together");
  sub->add_option("--campaign", args->options.campaign_file, "campaign YAML file")
      ->required()
      ->check(path_check("campaign", "--campaign"));
  sub->add_option("--out", args->options.out_dir, "report folder (created; refused when not empty)")
      ->required()
      ->check(path_check("campaign", "--out"));
  sub->add_flag("--overwrite", args->options.overwrite, "empty an earlier pvbench output in --out first");
  sub->add_option("--seed", args->seed, "session i runs with seed * 1000 + i (default: each scenario's seed)")
      ->check(seed_check("campaign", "--seed", std::numeric_limits<std::uint64_t>::max() / 1000 - 1));
  sub->add_option("--frames", args->frames, "at most N frames per session");
  sub->add_flag("--sync", args->options.sync, "synchronous: no threads, bit-identical sessions");
  sub->add_flag("--no-map-eval", args->no_map_eval, "write the dense maps without scoring them");
  sub->add_option("--gl", args->options.gl, "rendering backend")->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  return {sub, [args] { return run_campaign_command(*args); }};
}

}  // namespace pvb::cli
