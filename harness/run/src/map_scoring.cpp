#include "map_scoring.hpp"

#include "pvb/common/clock.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/eval/slam_mode.hpp"
#include "pvb/plot/contact_sheet.hpp"
#include "pvb/plot/map_view.hpp"
#include "pvb/slam/dense/ply.hpp"

namespace pvb::run {
namespace {

/// The corrected map's per-point output: map_errors.ply and the top view.
void write_error_outputs(const SystemSink& sink, const std::string& scenario, const std::vector<eval::MapPoint>& map,
                         const std::vector<eval::MapPointScore>& scores, DenseMapReport* d) {
  write_map_errors_ply(sink.dir + "/map_errors.ply", map, scores);
  std::vector<Eigen::Vector3d> p;
  std::vector<double> e;
  p.reserve(map.size());
  e.reserve(map.size());
  for (std::size_t i = 0; i < map.size(); ++i) p.push_back(map[i].p_w), e.push_back(scores[i].error_m);
  const std::string title = scenario + ", " + sink.run.label +
                            ": dense map from above, coloured by distance to the true surface";
  d->top_view = "map_error_top.png";
  plot::write_rgb_png(plot::make_map_error_top_view(p, e, title), sink.dir + "/" + d->top_view);
}

/// Scores one system's maps against the surface.
void score_sink(SystemSink& sink, const std::string& scenario, const eval::Trajectory& gt,
                const std::vector<eval::SurfacePoint>& surface, RunLog& log) {
  DenseMapReport& d = *sink.run.dense_map;
  const eval::Sim3Transform T = map_to_world(MapAlignment::kFirstFrame, *sink.run.eval, gt, sink.est);
  d.alignment = to_string(MapAlignment::kFirstFrame);
  d.surface_samples = surface.size();
  for (const DenseMapFile& file : sink.dense_files) {
    const std::string& name = file.name;
    const slam::dense::PointCloud cloud = slam::dense::read_ply(sink.dir + "/" + file.file);
    if (cloud.empty()) {  // nothing to score: never a perfect score
      log.line(sink.run.label + ": " + name + " map: not scored, it has no points");
      d.note += (d.note.empty() ? "" : "; ") + name + " map not scored: it has no points";
      continue;
    }
    const auto t0 = SteadyClock::now();
    const std::vector<eval::MapPoint> map = map_in_world(cloud, T);
    std::vector<eval::MapPointScore> scores;
    MapResult r{name, eval::evaluate_map(map, surface, {}, &scores), 0.0};
    r.score_s = seconds_since(t0);
    if (name == "corrected") write_error_outputs(sink, scenario, map, scores, &d);
    log.line(sink.run.label + ": " + name + " map: accuracy median " +
             format_number("%.1f", 1000 * r.accuracy.all.accuracy.median) + " mm, complete within 5 cm " +
             format_number("%.1f", 100 * r.accuracy.all.completeness_at[2]) + " %, ghosting " +
             format_number("%.2f", 100 * r.accuracy.all.ghosting) + " % (scored in " +
             format_number("%.1f", r.score_s) + " s)");
    d.maps.push_back(std::move(r));
  }
}

}  // namespace

double score_dense_maps(const scenes::Scenario& scenario, sim::GlBackend backend, const eval::Trajectory& gt,
                        SystemSinks& sinks, RunLog& log) {
  const auto t0 = SteadyClock::now();
  bool wanted = false;
  for (auto& sink : sinks) {
    if (!sink->run.dense_map) continue;
    if (!sink->run.eval) sink->run.dense_map->note = "the trajectory was not evaluated";
    else wanted = true;
  }
  std::vector<eval::SurfacePoint> surface;
  std::string failure;
  if (wanted) {
    try {
      sim::TruthSurfaceOptions to;
      to.frames = static_cast<int>(gt.size());
      surface = true_surface(scenario, backend, to);
      if (surface.empty()) failure = "the camera saw no surface";
    } catch (const Error& e) {
      failure = std::string("the true surface could not be sampled: ") + e.what();
    }
  }
  const double truth_s = seconds_since(t0);
  for (auto& sink : sinks) {
    if (sink->run.dense_map && sink->run.eval) {
      sink->run.dense_map->truth_s = truth_s;
      if (failure.empty()) score_sink(*sink, scenario.name, gt, surface, log);
      else sink->run.dense_map->note = failure;
    }
  }
  if (!failure.empty()) log.line("warning: dense maps not scored: " + failure);
  return 1000.0 * seconds_since(t0);
}

}  // namespace pvb::run
