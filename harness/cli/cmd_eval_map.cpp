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
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "command.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/eval/map_accuracy.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/truth_surface.hpp"
#include "pvb/slam/dense/ply.hpp"

namespace pvb::cli {
namespace {

struct EvalMapArgs {
  std::string map, scenario, trajectory, gt, out;
  std::optional<std::uint64_t> seed;
  double voxel_m = 0.01;
  int every = 5;
  std::string gl = "auto";
  std::string align = "first";
};

/// The map's transform into the world: the ATE's SE(3) alignment of the
/// trajectory, or ("first") the pose of the first estimated frame put on
/// its ground truth, for systems whose world is their first camera.
eval::Sim3Transform map_to_world(const EvalMapArgs& a, const eval::EvalResult& ate, const eval::Trajectory& gt,
                                 const eval::Trajectory& est) {
  if (a.align == "ate") return ate.alignment;
  const eval::IndexPair first = ate.pairs.front();
  const geom::SE3d T = gt.poses[first.gt].T_w_c * est.poses[first.est].T_w_c.inverse();
  eval::Sim3Transform out;
  out.R = T.linear();
  out.t = T.translation();
  return out;
}

/// The truth samples as the evaluation layer's surface points.
std::vector<eval::SurfacePoint> to_surface(const std::vector<sim::TruthSample>& truth) {
  std::vector<eval::SurfacePoint> s;
  s.reserve(truth.size());
  for (const sim::TruthSample& t : truth) s.push_back({t.p_w, t.n_w, static_cast<int>(t.cls), t.range_m});
  return s;
}

std::string scores_row(const std::string& name, const eval::MapScores& s) {
  char line[256];
  auto pct = [&s](std::size_t i) { return i < s.completeness_at.size() ? 100.0 * s.completeness_at[i] : 0.0; };
  std::snprintf(line, sizeof line, "%-7s %9zu %9zu %8.1f %8.1f %8.1f %6.1f %6.1f %6.1f %6.1f %7.3f %7.1f\n",
                name.c_str(), s.accuracy.count, s.completeness.count, 1000 * s.accuracy.median,
                1000 * s.accuracy.mean, 1000 * s.accuracy.p95, pct(0), pct(1), pct(2), pct(3),
                s.fscore_at.size() > 1 ? s.fscore_at[1] : 0.0, 100.0 * s.ghosting);
  return line;
}

std::string scores_json(const eval::MapScores& s) {
  std::ostringstream js;
  auto list = [&js](const std::vector<double>& v) {
    js << "[";
    for (std::size_t i = 0; i < v.size(); ++i) js << (i ? ", " : "") << format_g(v[i]);
    js << "]";
  };
  js << "{\"map_points\": " << s.accuracy.count << ", \"surface_points\": " << s.completeness.count
     << ", \"accuracy_m\": {\"mean\": " << format_g(s.accuracy.mean) << ", \"median\": " << format_g(s.accuracy.median)
     << ", \"rmse\": " << format_g(s.accuracy.rmse) << ", \"p95\": " << format_g(s.accuracy.p95) << "}"
     << ", \"completeness_at\": ";
  list(s.completeness_at);
  js << ", \"precision_at\": ";
  list(s.precision_at);
  js << ", \"fscore_at\": ";
  list(s.fscore_at);
  js << ", \"chamfer_m\": " << format_g(s.chamfer_m) << ", \"ghosting\": " << format_g(s.ghosting)
     << ", \"ghosting_judged\": " << s.ghosting_judged << "}";
  return js.str();
}

void write_json(const std::string& path, const eval::MapAccuracy& r, double ate_m) {
  std::ostringstream js;
  js << "{\n  \"tau_m\": [";
  for (std::size_t i = 0; i < r.options.tau_m.size(); ++i) js << (i ? ", " : "") << format_g(r.options.tau_m[i]);
  js << "],\n  \"ate_rmse_m\": " << format_g(ate_m) << ",\n  \"all\": " << scores_json(r.all)
     << ",\n  \"per_class\": {";
  bool first = true;
  for (const auto& [c, s] : r.per_class) {
    js << (first ? "" : ",") << "\n    \"" << sim::to_string(static_cast<sim::SurfaceClass>(c)) << "\": " << scores_json(s);
    first = false;
  }
  js << "\n  },\n  \"per_range\": [";
  for (std::size_t b = 0; b < r.per_range.size(); ++b)
    js << (b ? "," : "") << "\n    {\"from_m\": " << format_g(r.options.range_edges_m[b])
       << ", \"to_m\": " << format_g(r.options.range_edges_m[b + 1]) << ", \"scores\": " << scores_json(r.per_range[b])
       << "}";
  js << "\n  ]\n}\n";
  write_file(path, js.str());
}

/// The map points with their class and error, as binary PLY properties.
void write_error_ply(const std::string& path, const std::vector<eval::MapPoint>& map,
                     const std::vector<eval::MapPointScore>& scores) {
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment PE-SLAM dense map in the world frame, with class "
       "(0 other, 1 ground, 2 panel, 3 frame, 4 post, 5 wall, 6 shrub) and error (m) to the true surface\n"
    << "element vertex " << map.size()
    << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar class\nproperty float error\n"
       "end_header\n";
  std::string body = h.str();
  for (std::size_t i = 0; i < map.size(); ++i) {
    const float v[3] = {static_cast<float>(map[i].p_w.x()), static_cast<float>(map[i].p_w.y()),
                        static_cast<float>(map[i].p_w.z())};
    body.append(reinterpret_cast<const char*>(v), sizeof v);
    body.push_back(static_cast<char>(scores[i].class_id));
    const float e = static_cast<float>(scores[i].error_m);
    body.append(reinterpret_cast<const char*>(&e), sizeof e);
  }
  write_file(path, body);
}

int run_eval_map(const EvalMapArgs& a) {
  scenes::Scenario scenario = scenes::load_scenario(a.scenario);
  if (a.seed) scenario.seed = *a.seed;
  const eval::Trajectory gt = eval::read_tum(a.gt);
  const eval::Trajectory est = eval::read_tum(a.trajectory);
  const eval::EvalResult ate = eval::evaluate(gt, est, eval::EvalOptions{});
  const eval::Sim3Transform to_world = map_to_world(a, ate, gt, est);
  std::vector<eval::MapPoint> map;
  for (const slam::dense::CloudPoint& p : slam::dense::read_ply(a.map))
    map.push_back({to_world.apply(geom::Vec3d(p.x, p.y, p.z)), -1.0});
  sim::TruthSurfaceOptions to;
  to.voxel_m = a.voxel_m;
  to.every = a.every;
  to.frames = static_cast<int>(gt.size());
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<eval::SurfacePoint> surface =
      to_surface(sim::sample_truth_surface(scenario, sim::parse_gl_backend(a.gl, "--gl"), to));
  const auto t1 = std::chrono::steady_clock::now();
  std::vector<eval::MapPointScore> point_scores;
  const eval::MapAccuracy r = eval::evaluate_map(map, surface, {}, &point_scores);
  const auto t2 = std::chrono::steady_clock::now();
  std::printf("true surface sampled in %.2f s, map scored in %.2f s\n",
              std::chrono::duration<double>(t1 - t0).count(), std::chrono::duration<double>(t2 - t1).count());
  std::printf("map %s: %zu points; true surface: %zu samples (%.0f mm voxels, every %d of %zu frames); ATE %.4f m\n",
              a.map.c_str(), map.size(), surface.size(), 1000 * a.voxel_m, a.every, gt.size(), ate.ate.rmse);
  {  // how far the two alignments are apart: the map's error grows with range by this rotation
    EvalMapArgs other = a;
    other.align = a.align == "ate" ? "first" : "ate";
    const eval::Sim3Transform b = map_to_world(other, ate, gt, est);
    std::printf("alignment (%s) differs from the %s one by %.3f deg and %.1f mm at the first camera\n",
                a.align.c_str(), other.align.c_str(),
                geom::rotation_angle_rad(to_world.R.transpose() * b.R) * 180.0 / M_PI,
                1000 * (to_world.apply(geom::Vec3d(est.poses[ate.pairs.front().est].T_w_c.translation())) -
                        b.apply(geom::Vec3d(est.poses[ate.pairs.front().est].T_w_c.translation())))
                           .norm());
  }
  std::printf("class     map pts  surf pts  acc med  acc mean  acc p95  comp1  comp2  comp5 comp10  F@2cm  ghost%%\n");
  std::printf("%s", scores_row("all", r.all).c_str());
  for (const auto& [c, s] : r.per_class) std::printf("%s", scores_row(sim::to_string(static_cast<sim::SurfaceClass>(c)), s).c_str());
  std::printf("(accuracy in mm; completeness in %% of the surface within 1, 2, 5, 10 cm)\n");
  if (!a.out.empty()) {
    dataset::make_dirs(a.out);
    write_json(a.out + "/map_accuracy.json", r, ate.ate.rmse);
    write_error_ply(a.out + "/map_errors.ply", map, point_scores);
    std::printf("wrote %s/{map_accuracy.json,map_errors.ply}\n", a.out.c_str());
  }
  return 0;
}

}  // namespace

Command add_eval_map_command(CLI::App& app) {
  auto a = std::make_shared<EvalMapArgs>();
  CLI::App* sub = app.add_subcommand("eval-map", "accuracy and completeness of a dense map against the scene's true surface");
  sub->add_option("--map", a->map, "the dense map (PointCloud.ply of pvbench slam or run)")->required();
  sub->add_option("--scenario", a->scenario, "the scenario the map was made in")->required();
  sub->add_option("--seed", a->seed, "the scenario's seed, when the run overrode it");
  sub->add_option("--trajectory", a->trajectory, "the estimated trajectory (TUM), for the alignment")->required();
  sub->add_option("--gt", a->gt, "the ground truth (TUM) of the same run")->required();
  sub->add_option("--out", a->out, "folder for map_accuracy.json and map_errors.ply");
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
