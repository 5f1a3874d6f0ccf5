#pragma once
// Accuracy and completeness of a point-cloud map against a ground-truth
// surface sampled from the scene (both in the world frame, metres).
//
//   accuracy       distance from each map point to the nearest surface point
//   completeness   share of surface points with a map point within tau
//   precision      share of map points within tau of the surface
//   F-score        2 P R / (P + R) at each tau
//   Chamfer        (mean accuracy distance + mean completeness distance) / 2
//   ghosting       share of the surface points whose map points (those
//                  nearest to a surface point within ghost_radius of it)
//                  form two layers more than 2 tau_ghost apart along the
//                  normal, each of at least ghost_min_points (a surface
//                  mapped twice); judged where there are that many at all
//   ghosting between maps
//                  for a map merged from several (sessions in one frame):
//                  share of the surface points where two of them, each
//                  with ghost_min_points there, lie more than 2 tau_ghost
//                  apart along the normal (their median offsets); judged
//                  where two maps have that many
//
// Each figure is given for the whole map, per surface class (a map point
// takes the class of its nearest surface point) and per range bin (map
// points by the range they were measured at, surface points by the nearest
// range they were seen from).  Nearest neighbours come from nanoflann.
#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <vector>

namespace pvb::eval {

/// One sample of the true surface.
struct SurfacePoint {
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
  Eigen::Vector3d n_w = Eigen::Vector3d::UnitZ();  ///< unit normal
  int class_id = 0;
  double range_m = -1;  ///< nearest camera distance it was seen from; < 0 unknown
};

/// One point of the map under test.
struct MapPoint {
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
  double range_m = -1;  ///< camera distance it was measured at; < 0 unknown
  int source = 0;       ///< which of several merged maps it came from
};

struct MapAccuracyOptions {
  std::vector<double> tau_m = {0.01, 0.02, 0.05, 0.10};
  std::vector<double> range_edges_m = {0, 1, 2, 3, 4, 5, 10};  ///< bins [e_i, e_i+1)
  double ghost_tau_m = 0.02;     ///< layers more than 2 * this apart count as two
  double ghost_radius_m = 0.02;  ///< lateral radius of the neighbourhood judged
  int ghost_min_points = 3;      ///< map points each layer needs
};

/// Distances, metres: mean, median, RMSE, 95th percentile.
struct DistanceSummary {
  double mean = 0, median = 0, rmse = 0, p95 = 0;
  std::size_t count = 0;
};

struct MapScores {
  DistanceSummary accuracy;      ///< map -> surface
  DistanceSummary completeness;  ///< surface -> map
  std::vector<double> completeness_at;  ///< per tau, share of surface points
  std::vector<double> precision_at;     ///< per tau, share of map points
  std::vector<double> fscore_at;        ///< per tau
  double chamfer_m = 0;
  double ghosting = 0;                ///< share of the judged surface points
  std::size_t ghosting_judged = 0;    ///< surface points with enough map points around
  double ghosting_between = 0;                ///< share of the surface points judged between maps
  std::size_t ghosting_between_judged = 0;    ///< surface points with two maps around
};

struct MapAccuracy {
  MapScores all;
  std::map<int, MapScores> per_class;
  std::vector<MapScores> per_range;  ///< one per range bin
  MapAccuracyOptions options;
  int sources = 1;  ///< distinct MapPoint::source values (maps merged)
};

/// What one map point scored: the class of its nearest surface point and
/// its distance to it.
struct MapPointScore {
  int class_id = 0;
  double error_m = 0;
};

/// Scores `map` against `surface`.  A map point of unknown range takes the
/// range of its nearest surface point.  `per_point`, when given, receives
/// one score per map point.  Throws std::invalid_argument when the surface
/// is empty.
MapAccuracy evaluate_map(const std::vector<MapPoint>& map, const std::vector<SurfacePoint>& surface,
                         const MapAccuracyOptions& options = {}, std::vector<MapPointScore>* per_point = nullptr);

}  // namespace pvb::eval
