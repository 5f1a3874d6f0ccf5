// End to end: the dense map of a short simulated sequence against the
// rendered, noise-free geometry.
//
// Reads the shared synchronous run of the PV station's first 150 frames
// (Kinect depth model; its clouds are those `pvbench slam --sync` makes of
// the recording of them), moves PointCloud.ply into the
// ground-truth frame (origin alignment: the map lives in the first
// keyframe's camera frame, and a short, nearly straight drive leaves an
// se3 fit of positions free to roll about the direction of travel) and
// measures each cloud point's distance to the nearest point of the true
// surface: the simulator's exact rendered depth (no sensor model) of every
// 10th frame, back-projected at its ground-truth pose (stride 2, thinned to
// one point per 5 mm cell).  Bounds come from the sensor noise model, not
// from a run (see the test body).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <regex>
#include <sstream>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "pvb/common/text.hpp"
#include "pvb/eval/evaluate.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/renderer.hpp"
#include "pvb/sim/simulator.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/dense/ply.hpp"
#include "run_pvbench.hpp"
#include "station_sequence.hpp"

namespace {

constexpr int kFrames = 150;
constexpr int kReferenceEvery = 10;  // reference views: every 10th frame (the robot moves 15 cm)

std::string scratch(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_dense_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + d).c_str());
  return d;
}

// Points hashed into cubic cells, for nearest-neighbour queries.
class Grid {
 public:
  explicit Grid(double cell_m) : cell_(cell_m) {}
  static std::int64_t key(std::int64_t i, std::int64_t j, std::int64_t k) {
    return ((i + (1 << 20)) << 42) | ((j + (1 << 20)) << 21) | (k + (1 << 20));
  }
  static std::array<std::int64_t, 3> index(const Eigen::Vector3d& p, double cell_m) {
    return {static_cast<std::int64_t>(std::floor(p.x() / cell_m)),
            static_cast<std::int64_t>(std::floor(p.y() / cell_m)),
            static_cast<std::int64_t>(std::floor(p.z() / cell_m))};
  }
  void add(const Eigen::Vector3d& p) {
    const auto c = index(p, cell_);
    cells_[key(c[0], c[1], c[2])].push_back(p.cast<float>());
  }
  /// Distance to the nearest point, exact when it is below max_m; +inf beyond.
  double nearest(const Eigen::Vector3d& p, double max_m) const {
    const auto c = index(p, cell_);
    double best2 = std::numeric_limits<double>::infinity();
    for (int r = 1; r * cell_ <= max_m + cell_; ++r) {
      for (std::int64_t i = c[0] - r; i <= c[0] + r; ++i)
        for (std::int64_t j = c[1] - r; j <= c[1] + r; ++j)
          for (std::int64_t k = c[2] - r; k <= c[2] + r; ++k) {
            // only the shell of this ring (the inside was searched before)
            if (r > 1 && std::abs(i - c[0]) < r && std::abs(j - c[1]) < r && std::abs(k - c[2]) < r) continue;
            const auto it = cells_.find(key(i, j, k));
            if (it == cells_.end()) continue;
            for (const Eigen::Vector3f& q : it->second)
              best2 = std::min(best2, (q.cast<double>() - p).squaredNorm());
          }
      // every point closer than r cells has been seen
      if (std::sqrt(best2) <= r * cell_) break;
    }
    return std::sqrt(best2) <= max_m ? std::sqrt(best2) : std::numeric_limits<double>::infinity();
  }

 private:
  double cell_;
  std::unordered_map<std::int64_t, std::vector<Eigen::Vector3f>> cells_;
};

double quantile(std::vector<double> v, double q) {
  const std::size_t n = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(n), v.end());
  return v[n];
}

// The shared run of the station's first 150 frames (run --sync: its clouds
// are the same bytes as those of pvbench slam on the recording of them).
TEST(DenseScenario, CloudLiesOnTheRenderedGeometry) {
  static_assert(pvb::test::kStationRunFrames == kFrames, "the shared run's frames");
  const std::string seq = pvb::test::station_sequence(), out = pvb::test::station_ci_run();
  const std::string stats = pvb::read_file(out + "/metrics.json");
  EXPECT_NE(stats.find("\"lost_frames\": 0"), std::string::npos) << stats;

  // The cloud is built with the bundle-adjusted keyframe poses: align the
  // refined trajectory (frames re-anchored on those keyframes).
  const pvb::eval::Trajectory gt = pvb::eval::read_tum(seq + "/groundtruth.txt");
  pvb::eval::EvalOptions eo;
  eo.alignment = pvb::eval::Alignment::kOrigin;
  const pvb::eval::EvalResult ev =
      pvb::eval::evaluate(gt, pvb::eval::read_tum(out + "/CameraTrajectoryRefined.txt"), eo);
  ASSERT_EQ(ev.pairs.size(), static_cast<std::size_t>(kFrames));
  const pvb::slam::dense::PointCloud cloud = pvb::slam::dense::read_ply(out + "/PointCloud.ply");
  ASSERT_GT(cloud.size(), 1000u);
  // The map as built is there too; local BA moved keyframes, so it differs.
  const pvb::slam::dense::PointCloud live = pvb::slam::dense::read_ply(out + "/PointCloud_live.ply");
  EXPECT_GT(live.size(), 1000u);
  EXPECT_FALSE(live == cloud);
  EXPECT_NE(stats.find("\"pose_updates\": "), std::string::npos) << stats;

  // Reference surface: the same scenario and seed, its exact depth rendered
  // at the ground-truth poses (the scene's geometry: no texture, no sensor model).
  pvb::scenes::Scenario scenario = pvb::scenes::load_scenario(pvb::test::station_scenario());
  scenario.seed = pvb::test::kStationSeed;
  pvb::sim::Simulator sim(scenario, pvb::sim::SceneDetail::kGeometry);
  const pvb::geom::PinholeIntrinsics K = sim.intrinsics();
  pvb::sim::Renderer renderer(sim.model(), pvb::sim::GlBackend::kAuto, K.width, K.height);
  renderer.set_shadows(false);
  constexpr double kThinCell = 0.005;
  Grid surface(0.025);
  std::unordered_set<std::int64_t> taken;
  cv::Mat depth_gt_m;
  for (int i = 0; i < kFrames; ++i) {
    if (i > 0) sim.advance();
    if (i % kReferenceEvery != 0) continue;
    renderer.render(sim.model(), sim.data(), sim.camera_id(), nullptr, &depth_gt_m);
    const pvb::geom::SE3d T_w_c = sim.T_w_c();
    // the recording's ground truth is this simulation's
    ASSERT_LT((T_w_c.translation() - gt.poses[static_cast<std::size_t>(i)].T_w_c.translation()).norm(), 1e-6);
    for (int v = 0; v < depth_gt_m.rows; v += 2)
      for (int u = 0; u < depth_gt_m.cols; u += 2) {
        const double z = depth_gt_m.at<float>(v, u);
        if (!(z > 0) || z > sim.assets().max_scene_depth_m) continue;  // the sky lies beyond the scene
        const Eigen::Vector3d p_w = T_w_c * Eigen::Vector3d((u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z);
        const auto c = Grid::index(p_w, kThinCell);
        if (taken.insert(Grid::key(c[0], c[1], c[2])).second) surface.add(p_w);
      }
  }

  // The bounds, from the sensor model (scenes/SCHEMA.md, sim/src/sensor_model.cpp):
  // axial sigma_z = 0.0012 + 0.0019 (z - 0.4)^2 and disparity quantisation
  // of 0.125 px with b = 0.075 m (a step of z^2 * 0.125 / (b fx), uniform),
  // both worst at the mapper's depth limit.  A point is off the surface by
  // at most its error along the ray; one sample is within 2 sigma 95 % of
  // the time (0.674 sigma for the median).  Added: the pose error the SLAM
  // scenario allows (ATE 2 cm), half a voxel (a voxel mean on a curved
  // surface or an edge) and the reference's own thinning cell.
  const pvb::slam::PointCloudMappingSettings dense_defaults;
  const double z = dense_defaults.max_depth_m;
  const double sigma_axial = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
  const double q_step = z * z * 0.125 / (0.075 * K.fx);
  const double sigma = std::sqrt(sigma_axial * sigma_axial + q_step * q_step / 12.0);
  const double extra = 0.02 + dense_defaults.resolution_m / 2 + kThinCell;
  const double median_bound = 0.674 * sigma + extra, p95_bound = 2.0 * sigma + extra;

  std::vector<double> dist;
  dist.reserve(cloud.size());
  ASSERT_LT(ev.ate.rmse, 0.02) << "the pose term of the bounds assumes the SLAM scenario's ATE bound";
  for (const auto& p : cloud)
    dist.push_back(surface.nearest(ev.alignment.apply(Eigen::Vector3d(p.x, p.y, p.z)), 2 * p95_bound));
  const double median = quantile(dist, 0.5), p95 = quantile(dist, 0.95);
  std::printf(
      "dense map, %d frames: %zu points, ATE (origin-aligned) %.1f mm; distance to the rendered surface: "
      "median %.1f mm "
      "(bound %.1f), 95 %% %.1f mm (bound %.1f)\n",
      kFrames, cloud.size(), ev.ate.rmse * 1000, median * 1000, median_bound * 1000, p95 * 1000,
      p95_bound * 1000);
  EXPECT_LT(median, median_bound);
  EXPECT_LT(p95, p95_bound);

  // Control: the same cloud 10 cm too high (a pose or scale error of that
  // size) breaks the median bound, so the bounds can catch a broken map.
  std::vector<double> shifted;
  for (std::size_t i = 0; i < cloud.size(); i += 10) {
    const auto& p = cloud[i];
    shifted.push_back(surface.nearest(
        ev.alignment.apply(Eigen::Vector3d(p.x, p.y, p.z)) + Eigen::Vector3d(0, 0, 0.1), 2 * p95_bound));
  }
  EXPECT_GT(quantile(shifted, 0.5), median_bound);
}

TEST(DenseScenario, NoDenseFlagWritesNoCloud) {
  const std::string seq = pvb::test::station_sequence(), out = scratch("nodense");
  const auto r = pvb::test::run_pvbench("slam --sequence " + seq + " --settings " + seq +
                                        "/camera.yaml --out " + out + " --sync --no-dense --max-frames 30");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("dense map"), std::string::npos) << r.output;
  EXPECT_EQ(::access((out + "/PointCloud.ply").c_str(), F_OK), -1);
  EXPECT_EQ(pvb::read_file(out + "/stats.json").find("\"dense\""), std::string::npos);
}

// A run that stops on too many missing images keeps its partial dense map.
TEST(DenseScenario, StoppedRunKeepsItsPartialCloud) {
  const std::string seq = pvb::test::station_sequence(), cut = scratch("cut"), out = scratch("cutrun");
  std::system(("mkdir -p " + cut + " && ln -s " + seq + "/rgb " + cut + "/rgb && ln -s " + seq + "/depth " +
               cut + "/depth")
                  .c_str());
  // 40 frames; 20..27 point at missing files (more than the 10 % pvbench slam tolerates)
  std::istringstream in(pvb::read_file(seq + "/associations.txt"));
  std::string assoc, line;
  for (int i = 0; i < 40 && std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (i >= 20 && i < 28) line = std::regex_replace(line, std::regex("\\.png"), "_missing.png");
    assoc += line + "\n";
    ++i;
  }
  pvb::write_file(cut + "/associations.txt", assoc);
  const auto r = pvb::test::run_pvbench("slam --sequence " + cut + " --settings " + seq +
                                        "/camera.yaml --out " + out + " --sync");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("missing or corrupt"), std::string::npos) << r.output;
  ASSERT_EQ(::access((out + "/PointCloud.ply").c_str(), F_OK), 0) << r.output;
  EXPECT_GT(pvb::slam::dense::read_ply(out + "/PointCloud.ply").size(), 1000u);
}

}  // namespace
