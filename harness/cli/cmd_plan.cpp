// pvbench plan: a station seen from above, drawn from its scenario file (no
// rendering): its rows, walls and inverter stations, and its route; north
// up, with a scale bar (docs/plants.md).
//
//   pvbench plan --scenario scenes/plants/plant_10mw_tracker.yaml --out plan.png
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "command.hpp"
#include "io_plan.hpp"
#include "pvb/plot/contact_sheet.hpp"
#include "pvb/report/plan_view.hpp"
#include "pvb/scenes/route.hpp"
#include "pvb/scenes/scenario.hpp"

namespace pvb::cli {
namespace {

struct PlanArgs {
  std::string scenario;
  std::string out;
  int max_side_px = 1600;
};

int run_plan(const PlanArgs& a) {
  const scenes::Scenario s = scenes::load_scenario(a.scenario);
  IoPlan plan;
  add_scenario_inputs(&plan, "--scenario", s);
  plan.output_file("--out", a.out).check();
  plot::write_rgb_png(run::make_plan_view(s, a.max_side_px), a.out);
  const std::vector<Eigen::Vector2d> route = scenes::route_polyline(s, 0.25);
  std::printf("wrote %s (route %.1f m: %.0f s at %.2f m/s)\n", a.out.c_str(), scenes::polyline_length(route),
              scenes::polyline_length(route) / s.route.speed_mps, s.route.speed_mps);
  return 0;
}

}  // namespace

Command add_plan_command(CLI::App& app) {
  auto a = std::make_shared<PlanArgs>();
  CLI::App* sub = app.add_subcommand("plan", "a station from above (rows, walls, inverter stations, route), from its scenario file");
  sub->add_option("--scenario", a->scenario, "scenario YAML file")->required()->check(path_check("plan", "--scenario"));
  sub->add_option("--out", a->out, "the plan (PNG)")->required()->check(path_check("plan", "--out"));
  sub->add_option("--max-side", a->max_side_px, "the plan's longer side, pixels")
      ->capture_default_str()
      ->check(CLI::Range(200, 8000));
  return {sub, [a] { return run_plan(*a); }};
}

}  // namespace pvb::cli
