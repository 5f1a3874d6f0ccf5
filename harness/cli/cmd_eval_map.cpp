// pvbench eval-map: the accuracy and completeness of a dense map against
// the scenario's true surface (docs/map_accuracy.md).
//
//   pvbench eval-map --map PointCloud.ply --scenario scenes/S.yaml [--seed N]
//                    --trajectory CameraTrajectory.txt --gt groundtruth.txt [--out DIR]
//
// The map is taken into the world by the first frame's pose (the estimate's
// first pose put on its ground truth; SLAM's world is its first camera), or
// with --align ate by the trajectory's SE(3) alignment to the ground truth,
// as for the ATE.  The latter is ill-conditioned in roll about a nearly
// straight route and rotates the map by a degree on pv_station
// (docs/map_accuracy.md).  The true surface is what the camera saw along
// the route's frames (as many as the ground truth has).
// Prints a table per class, writes map_accuracy.json and map_errors.ply
// (each map point with its class and error, for CloudCompare or MeshLab).
//
// --map may be given several times: the dense maps of sessions that share
// the first one's frame (a campaign's extend sessions, whose poses are in
// the loaded map's frame), runs at the same station.  They are scored as
// one merged map, and "ghosting between maps" says where two sessions drew
// the same surface apart.
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "command.hpp"
#include "count_option.hpp"
#include "io_plan.hpp"
#include "pvb/common/clock.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/eval/map_accuracy.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/run/map_eval.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/truth_surface.hpp"
#include "pvb/slam/dense/ply.hpp"
#include "pvb/suite/metrics_file.hpp"

namespace pvb::cli {
namespace {

struct EvalMapArgs {
  std::vector<std::string> maps;
  std::string scenario, trajectory, gt, out;
  std::optional<std::uint64_t> seed;
  double voxel_m = 0.01;
  int every = 5;
  std::string gl = "auto";
  std::string align = "first";
  bool overwrite = false;
};

run::MapAlignment alignment_of(const std::string& name) {
  return name == "ate" ? run::MapAlignment::kAte : run::MapAlignment::kFirstFrame;
}

/// How far the two alignments are apart: the map's error grows with range by this rotation.
void print_alignment_gap(run::MapAlignment used, const eval::Sim3Transform& to_world, const eval::EvalResult& ate,
                         const eval::Trajectory& gt, const eval::Trajectory& est) {
  const run::MapAlignment other = used == run::MapAlignment::kAte ? run::MapAlignment::kFirstFrame : run::MapAlignment::kAte;
  const eval::Sim3Transform b = run::map_to_world(other, ate, gt, est);
  const geom::Vec3d c(est.poses[ate.pairs.front().est].T_w_c.translation());
  std::printf("alignment (%s) differs from the %s one by %.3f deg and %.1f mm at the first camera\n",
              run::to_string(used), run::to_string(other),
              geom::rotation_angle_rad(to_world.R.transpose() * b.R) * 180.0 / M_PI,
              1000 * (to_world.apply(c) - b.apply(c)).norm());
}

std::string folder_of(const std::string& file) {
  const std::size_t slash = file.rfind('/');
  return slash == std::string::npos ? std::string(".") : file.substr(0, slash);
}

/// A further map must come from a run at the first map's station (when both
/// folders say where they were made).
void check_same_station(const suite::FolderIdentity& first, const std::string& map) {
  const std::optional<suite::FolderIdentity> id = suite::read_folder_identity(folder_of(map));
  if (!id) return;
  if (!first.station_seed || !id->station_seed)
    throw ConfigError(id->file, "world.station_seed",
                      "a run at a station (metrics.json \"world\"), as " + first.file + " for a merged map", "none");
  if (*id->station_seed != *first.station_seed || id->station_file != first.station_file)
    throw ConfigError(id->file, "world", "station " + first.station_file + " seed " + std::to_string(*first.station_seed),
                      id->station_file + " seed " + std::to_string(*id->station_seed));
}

/// The scenario and seed that the map's and the ground truth's folders say
/// they were made from (a run's metrics.json, a recording's meta.json), if
/// any, must be the ones given: a map is never scored against another world.
/// Further maps must come from runs at the first map's station.
void check_inputs_match(const scenes::Scenario& scenario, const EvalMapArgs& a) {
  for (const std::string& dir : {folder_of(a.maps.front()), folder_of(a.gt)}) {
    const std::optional<suite::FolderIdentity> id = suite::read_folder_identity(dir);
    if (!id) continue;
    if (!id->scenario.empty() && id->scenario != scenario.name)
      throw ConfigError(id->file, "scenario", "a run of " + scenario.name + " (--scenario " + a.scenario + ")",
                        id->scenario);
    if (id->seed && *id->seed != scenario.seed)
      throw ConfigError(id->file, "seed",
                        std::to_string(scenario.seed) + " (the scenario's seed" + (a.seed ? ", --seed" : "") +
                            "; give --seed " + std::to_string(*id->seed) + " for this run)",
                        std::to_string(*id->seed));
  }
  const std::optional<suite::FolderIdentity> first = suite::read_folder_identity(folder_of(a.maps.front()));
  if (!first) return;
  for (std::size_t i = 1; i < a.maps.size(); ++i) check_same_station(*first, a.maps[i]);
}

/// The map's points, refusing a map with none: an empty map scores nothing,
/// never a perfect accuracy.
slam::dense::PointCloud read_map(const std::string& path, std::size_t* dropped, bool may_be_empty = false) {
  slam::dense::PlyReadStats stats;
  slam::dense::PointCloud cloud = slam::dense::read_ply(path, &stats);
  *dropped = stats.non_finite_dropped;
  if (cloud.empty() && !may_be_empty)
    throw IoError(path, "the map has no points to score" +
                            (*dropped ? " (" + std::to_string(*dropped) + " vertices with a NaN or infinite coordinate)"
                                      : std::string()));
  if (*dropped)
    std::printf("map %s: %zu vertices with a NaN or infinite coordinate left out\n", path.c_str(), *dropped);
  return cloud;
}

std::string joined(const std::vector<std::string>& files) {
  std::string s;
  for (const std::string& f : files) s += (s.empty() ? "" : " + ") + f;
  return s;
}

/// The maps' points in the world, each labelled by the map it came from.
std::vector<eval::MapPoint> merged_in_world(const std::vector<std::string>& maps, const eval::Sim3Transform& to_world,
                                            std::size_t* dropped) {
  std::vector<eval::MapPoint> all;
  for (std::size_t i = 0; i < maps.size(); ++i) {
    std::size_t d = 0;
    const slam::dense::PointCloud cloud = read_map(maps[i], &d, i > 0);
    if (cloud.empty()) {  // a further map: a session that added no keyframe
      std::printf("map %s: no points (its session added no keyframe)\n", maps[i].c_str());
      continue;
    }
    std::vector<eval::MapPoint> one = run::map_in_world(cloud, to_world);
    for (eval::MapPoint& p : one) p.source = static_cast<int>(i);
    all.insert(all.end(), one.begin(), one.end());
    *dropped += d;
  }
  return all;
}

int run_eval_map(const EvalMapArgs& a) {
  scenes::Scenario scenario = scenes::load_scenario(a.scenario);
  if (a.seed) scenario.seed = *a.seed;
  IoPlan plan;
  add_scenario_inputs(&plan, "--scenario", scenario);
  plan.inputs("a --map file", a.maps)
      .input("the --trajectory file", a.trajectory)
      .input("the --gt file", a.gt);
  plan.output_folder("--out", a.out).check();
  if (!a.out.empty()) check_output_folder(a.out, a.overwrite);  // before the work
  check_inputs_match(scenario, a);
  const eval::Trajectory gt = eval::read_tum(a.gt);
  const eval::Trajectory est = eval::read_tum(a.trajectory);
  const eval::EvalResult ate = eval::evaluate(gt, est, eval::EvalOptions{});
  const run::MapAlignment alignment = alignment_of(a.align);
  const eval::Sim3Transform to_world = run::map_to_world(alignment, ate, gt, est);
  std::size_t dropped = 0;
  const std::vector<eval::MapPoint> map = merged_in_world(a.maps, to_world, &dropped);
  if (!a.out.empty()) prepare_output_folder(a.out, a.overwrite, "eval-map");
  sim::TruthSurfaceOptions to;
  to.voxel_m = a.voxel_m;
  to.every = a.every;
  to.frames = static_cast<int>(gt.size());
  const auto t0 = SteadyClock::now();
  const std::vector<eval::SurfacePoint> surface =
      run::true_surface(scenario, sim::parse_gl_backend(a.gl, "--gl"), to);
  const double truth_s = seconds_since(t0);
  const auto t1 = SteadyClock::now();
  std::vector<eval::MapPointScore> point_scores;
  const eval::MapAccuracy r = eval::evaluate_map(map, surface, {}, &point_scores);
  std::printf("true surface sampled in %.2f s, map scored in %.2f s\n", truth_s, seconds_since(t1));
  std::printf("map %s: %zu points; true surface: %zu samples (%.0f mm voxels, every %d of %zu frames); ATE %.4f m\n",
              joined(a.maps).c_str(), map.size(), surface.size(), 1000 * a.voxel_m, a.every, gt.size(), ate.ate.rmse);
  print_alignment_gap(alignment, to_world, ate, gt, est);
  std::printf("%s", run::map_accuracy_table(r).c_str());
  std::printf("(accuracy in mm; completeness in %% of the surface within 1, 2, 5, 10 cm)\n");
  if (!a.out.empty()) {
    const std::string body = run::map_accuracy_json(r);
    write_file(a.out + "/map_accuracy.json", "{\n  \"ate_rmse_m\": " + json_number(ate.ate.rmse, 6) +
                                                 ",\n  \"alignment\": \"" + run::to_string(alignment) + "\"," +
                                                 "\n  \"non_finite_vertices_dropped\": " + std::to_string(dropped) +
                                                 "," + body.substr(1) + "\n");
    run::write_map_errors_ply(a.out + "/map_errors.ply", map, point_scores);
    std::printf("wrote %s/{map_accuracy.json,map_errors.ply}\n", a.out.c_str());
  }
  return 0;
}

}  // namespace

Command add_eval_map_command(CLI::App& app) {
  auto a = std::make_shared<EvalMapArgs>();
  CLI::App* sub = app.add_subcommand("eval-map", "accuracy and completeness of a dense map against the scene's true surface");
  sub->add_option(
         "--map", a->maps,
         "the dense map (PointCloud.ply of pvbench slam or run); several: maps in the first one's frame "
         "(a campaign's extend sessions), scored as one")
      ->required()
      ->take_all()
      ->check(path_check("eval-map", "--map"));
  sub->add_option("--scenario", a->scenario, "the scenario the map was made in")
      ->required()
      ->check(path_check("eval-map", "--scenario"));
  sub->add_option("--seed", a->seed, "the scenario's seed, when the run overrode it");
  sub->add_option("--trajectory", a->trajectory, "the estimated trajectory (TUM), for the alignment")
      ->required()
      ->check(path_check("eval-map", "--trajectory"));
  sub->add_option("--gt", a->gt, "the ground truth (TUM) of the same run")
      ->required()
      ->check(path_check("eval-map", "--gt"));
  sub->add_option("--out", a->out, "folder for map_accuracy.json and map_errors.ply (refused when not empty)")
      ->check(path_check("eval-map", "--out"));
  sub->add_flag("--overwrite", a->overwrite, "empty an earlier pvbench output in --out first");
  sub->add_option("--voxel", a->voxel_m, "true-surface sampling, metres")->capture_default_str()->check(CLI::Range(0.002, 0.5));
  sub->add_option("--every", a->every, "render every k-th frame of the route")->capture_default_str()->check(CLI::Range(1, 1000));
  sub->add_option("--gl", a->gl, "rendering backend")->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  sub->add_option("--align", a->align,
                  "first: the first frame's pose; ate: the trajectory's SE(3) alignment to the ground truth "
                  "(ill-conditioned about a straight route)")
      ->capture_default_str()
      ->check(CLI::IsMember({"ate", "first"}));
  return {sub, [a] { return run_eval_map(*a); }};
}

}  // namespace pvb::cli
