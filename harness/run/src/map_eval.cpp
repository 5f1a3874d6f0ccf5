#include "pvb/run/map_eval.hpp"

#include <cstdio>
#include <sstream>

#include "pvb/common/output_file.hpp"
#include "pvb/common/text.hpp"
#include "pvb/slam/dense/ply.hpp"

namespace pvb::run {

std::vector<DenseMapFile> write_dense_maps(slam::System& system, const std::string& dir) {
  std::vector<DenseMapFile> files;
  files.push_back({"corrected", "PointCloud.ply", 0});
  files.back().points = system.write_point_cloud(dir + "/" + files.back().file);
  files.push_back({"live", "PointCloud_live.ply", 0});
  files.back().points = system.write_live_point_cloud(dir + "/" + files.back().file);
  if (system.write_dense_first_loop(dir + "/PointCloud_before_loop.ply", dir + "/PointCloud_after_loop.ply")) {
    files.push_back({"before_loop", "PointCloud_before_loop.ply", 0});
    files.push_back({"after_loop", "PointCloud_after_loop.ply", 0});
  }
  return files;
}

const char* to_string(MapAlignment a) { return a == MapAlignment::kAte ? "ate" : "first"; }

eval::Sim3Transform map_to_world(MapAlignment alignment, const eval::EvalResult& ate, const eval::Trajectory& gt,
                                 const eval::Trajectory& est) {
  if (alignment == MapAlignment::kAte) return ate.alignment;
  const eval::IndexPair first = ate.pairs.front();
  const geom::SE3d T = gt.poses[first.gt].T_w_c * est.poses[first.est].T_w_c.inverse();
  eval::Sim3Transform out;
  out.R = T.linear();
  out.t = T.translation();
  return out;
}

std::vector<eval::MapPoint> map_in_world(const slam::dense::PointCloud& cloud, const eval::Sim3Transform& T) {
  std::vector<eval::MapPoint> map;
  map.reserve(cloud.size());
  for (const slam::dense::CloudPoint& p : cloud) map.push_back({T.apply(geom::Vec3d(p.x, p.y, p.z)), -1.0});
  return map;
}

std::vector<eval::SurfacePoint> true_surface(const scenes::Scenario& scenario, sim::GlBackend backend,
                                             const sim::TruthSurfaceOptions& options) {
  const std::vector<sim::TruthSample> truth = sim::sample_truth_surface(scenario, backend, options);
  std::vector<eval::SurfacePoint> s;
  s.reserve(truth.size());
  for (const sim::TruthSample& t : truth) s.push_back({t.p_w, t.n_w, static_cast<int>(t.cls), t.range_m});
  return s;
}

void write_map_errors_ply(const std::string& path, const std::vector<eval::MapPoint>& map,
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

}  // namespace pvb::run
