#include "pvb/eval/map_accuracy.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <tuple>
#include <memory>
#include <stdexcept>

namespace pvb::eval {
namespace {

/// nanoflann's view of a point list.
struct Cloud {
  const std::vector<Eigen::Vector3d>& pts;
  std::size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(std::size_t i, std::size_t d) const { return pts[i][static_cast<int>(d)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3, std::size_t>;

/// For each of `from`: the index of and distance to its nearest of `to`.
struct Nearest {
  std::vector<std::size_t> index;
  std::vector<double> dist_m;
};

Nearest nearest(const std::vector<Eigen::Vector3d>& from, const Tree* to) {
  Nearest n;
  n.index.assign(from.size(), 0);
  n.dist_m.assign(from.size(), std::numeric_limits<double>::infinity());
  if (!to) return n;
  for (std::size_t i = 0; i < from.size(); ++i) {
    double d2 = 0;
    if (to->knnSearch(from[i].data(), 1, &n.index[i], &d2) == 1) n.dist_m[i] = std::sqrt(d2);
  }
  return n;
}

/// The median of n sorted values, value k being at(k).
template <typename At>
double sorted_median(std::size_t n, At at) {
  return n % 2 ? at(n / 2) : 0.5 * (at(n / 2 - 1) + at(n / 2));
}

DistanceSummary summarise(std::vector<double> d) {
  DistanceSummary s;
  s.count = d.size();
  if (d.empty()) return s;
  double sum = 0, sum2 = 0;
  for (double x : d) {
    sum += x;
    sum2 += x * x;
  }
  s.mean = sum / static_cast<double>(d.size());
  s.rmse = std::sqrt(sum2 / static_cast<double>(d.size()));
  std::sort(d.begin(), d.end());
  const std::size_t n = d.size();
  s.median = sorted_median(n, [&](std::size_t k) { return d[k]; });
  s.p95 = d[static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(n))) - 1];
  return s;
}

double share_within(const std::vector<double>& d, double tau) {
  if (d.empty()) return 0;
  return static_cast<double>(std::count_if(d.begin(), d.end(), [tau](double x) { return x <= tau; })) /
         static_cast<double>(d.size());
}

/// The ghost flags of one surface point: 0 no, 1 yes, -1 not judged.
struct GhostFlags {
  int within = -1;   ///< any two layers
  int between = -1;  ///< two source maps apart
};

/// Two layers: a gap wider than 2 tau in the sorted offsets with k points on each side.
int two_layers(std::vector<double>* offsets, const MapAccuracyOptions& o) {
  const auto k = static_cast<std::size_t>(o.ghost_min_points);
  if (offsets->size() < k) return -1;
  std::sort(offsets->begin(), offsets->end());
  for (std::size_t i = k; i + k <= offsets->size(); ++i)
    if ((*offsets)[i] - (*offsets)[i - 1] > 2.0 * o.ghost_tau_m) return 1;
  return 0;
}

/// Two source maps apart: the median offsets of the sources with k points
/// span more than 2 tau.  `by_source` holds (source, offset) pairs.
int maps_apart(std::vector<std::pair<int, double>>* by_source, const MapAccuracyOptions& o) {
  // Sorted by source, then offset: each source's offsets lie in a sorted run.
  const std::vector<std::pair<int, double>>& v = *by_source;
  std::sort(by_source->begin(), by_source->end());
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  int judged = 0;
  for (std::size_t i = 0; i < v.size();) {
    std::size_t j = i;
    while (j < v.size() && v[j].first == v[i].first) ++j;
    if (j - i >= static_cast<std::size_t>(o.ghost_min_points)) {
      const double median = sorted_median(j - i, [&](std::size_t k) { return v[i + k].second; });
      lo = std::min(lo, median);
      hi = std::max(hi, median);
      ++judged;
    }
    i = j;
  }
  if (judged < 2) return -1;
  return hi - lo > 2.0 * o.ghost_tau_m ? 1 : 0;
}

/// What ghosted() fills for each surface point, kept between points.
struct GhostScratch {
  std::vector<std::pair<std::size_t, double>> near;
  std::vector<double> offsets;
  std::vector<std::pair<int, double>> by_source;
};

/// Ghosting of one surface point from the map points whose nearest surface
/// point lies within the lateral radius: their offsets along this point's
/// normal, split by a gap wider than 2 tau with enough points on each side;
/// and, for merged maps, split by source.
GhostFlags ghosted(std::size_t at, const std::vector<SurfacePoint>& surface, const Tree& surface_tree,
                   const std::vector<std::vector<std::size_t>>& map_by_surface, const std::vector<MapPoint>& map,
                   const MapAccuracyOptions& o, bool merged, GhostScratch* scratch) {
  const SurfacePoint& s = surface[at];
  nanoflann::SearchParams unsorted;  // the offsets are sorted below, whatever order they come in
  unsorted.sorted = false;
  surface_tree.radiusSearch(s.p_w.data(), o.ghost_radius_m * o.ghost_radius_m, scratch->near, unsorted);
  scratch->offsets.clear();
  scratch->by_source.clear();
  for (const auto& [j, d2] : scratch->near)
    for (std::size_t m : map_by_surface[j]) {
      scratch->offsets.push_back((map[m].p_w - s.p_w).dot(s.n_w));
      if (merged) scratch->by_source.emplace_back(map[m].source, scratch->offsets.back());
    }
  return {two_layers(&scratch->offsets, o), merged ? maps_apart(&scratch->by_source, o) : -1};
}

/// The share of judged flags that are set, and how many were judged.
std::pair<double, std::size_t> share_flagged(const std::vector<int>& flags) {
  std::size_t judged = 0, yes = 0;
  for (int g : flags) {
    if (g < 0) continue;
    ++judged;
    yes += static_cast<std::size_t>(g);
  }
  return {judged ? static_cast<double>(yes) / static_cast<double>(judged) : 0.0, judged};
}

/// The scores of a subset: accuracy distances of its map points,
/// completeness distances and ghost flags of its surface points.
MapScores score(const std::vector<double>& acc, const std::vector<double>& comp, const std::vector<int>& ghosts,
                const std::vector<int>& ghosts_between, const MapAccuracyOptions& o) {
  MapScores s;
  s.accuracy = summarise(acc);
  s.completeness = summarise(comp);
  for (double tau : o.tau_m) {
    const double p = share_within(acc, tau), r = share_within(comp, tau);
    s.precision_at.push_back(p);
    s.completeness_at.push_back(r);
    s.fscore_at.push_back(p + r > 0 ? 2 * p * r / (p + r) : 0.0);
  }
  s.chamfer_m = 0.5 * (s.accuracy.mean + s.completeness.mean);
  std::tie(s.ghosting, s.ghosting_judged) = share_flagged(ghosts);
  std::tie(s.ghosting_between, s.ghosting_between_judged) = share_flagged(ghosts_between);
  return s;
}

int range_bin(double range_m, const std::vector<double>& edges) {
  if (range_m < 0) return -1;
  for (std::size_t i = 0; i + 1 < edges.size(); ++i)
    if (range_m >= edges[i] && range_m < edges[i + 1]) return static_cast<int>(i);
  return -1;
}

/// Keeps the values whose key equals `key`.
template <class T>
std::vector<T> select(const std::vector<T>& v, const std::vector<int>& keys, int key) {
  std::vector<T> out;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (keys[i] == key) out.push_back(v[i]);
  return out;
}

}  // namespace

MapAccuracy evaluate_map(const std::vector<MapPoint>& map, const std::vector<SurfacePoint>& surface,
                         const MapAccuracyOptions& options, std::vector<MapPointScore>* per_point) {
  if (surface.empty()) throw std::invalid_argument("evaluate_map: the ground-truth surface is empty");
  std::vector<Eigen::Vector3d> map_p, surf_p;
  for (const MapPoint& m : map) map_p.push_back(m.p_w);
  for (const SurfacePoint& s : surface) surf_p.push_back(s.p_w);
  const Cloud map_cloud{map_p}, surf_cloud{surf_p};
  Tree surf_tree(3, surf_cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  surf_tree.buildIndex();
  std::unique_ptr<Tree> map_tree;
  if (!map_p.empty()) {
    map_tree = std::make_unique<Tree>(3, map_cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    map_tree->buildIndex();
  }
  const Nearest acc = nearest(map_p, &surf_tree);
  const Nearest comp = nearest(surf_p, map_tree.get());
  std::vector<std::vector<std::size_t>> map_by_surface(surface.size());
  for (std::size_t i = 0; i < map.size(); ++i) map_by_surface[acc.index[i]].push_back(i);
  std::set<int> sources;
  for (const MapPoint& m : map) sources.insert(m.source);
  std::vector<int> ghosts(surface.size(), -1), between(surface.size(), -1);
  GhostScratch scratch;
  for (std::size_t i = 0; i < surface.size(); ++i) {
    const GhostFlags g = ghosted(i, surface, surf_tree, map_by_surface, map, options, sources.size() > 1, &scratch);
    ghosts[i] = g.within;
    between[i] = g.between;
  }

  MapAccuracy out;
  out.options = options;
  out.sources = std::max<int>(1, static_cast<int>(sources.size()));
  out.all = score(acc.dist_m, comp.dist_m, ghosts, between, options);
  std::vector<int> map_class(map.size()), surf_class(surface.size()), map_bin(map.size()), surf_bin(surface.size());
  for (std::size_t i = 0; i < map.size(); ++i) {
    const SurfacePoint& nearest_surface = surface[acc.index[i]];
    map_class[i] = nearest_surface.class_id;
    map_bin[i] = range_bin(map[i].range_m >= 0 ? map[i].range_m : nearest_surface.range_m, options.range_edges_m);
  }
  if (per_point) {
    per_point->resize(map.size());
    for (std::size_t i = 0; i < map.size(); ++i) (*per_point)[i] = {map_class[i], acc.dist_m[i]};
  }
  for (std::size_t i = 0; i < surface.size(); ++i) {
    surf_class[i] = surface[i].class_id;
    surf_bin[i] = range_bin(surface[i].range_m, options.range_edges_m);
  }
  for (int c : surf_class)
    if (!out.per_class.count(c))
      out.per_class[c] = score(select(acc.dist_m, map_class, c), select(comp.dist_m, surf_class, c),
                               select(ghosts, surf_class, c), select(between, surf_class, c), options);
  for (int b = 0; b + 1 < static_cast<int>(options.range_edges_m.size()); ++b)
    out.per_range.push_back(score(select(acc.dist_m, map_bin, b), select(comp.dist_m, surf_bin, b),
                                  select(ghosts, surf_bin, b), select(between, surf_bin, b), options));
  return out;
}

}  // namespace pvb::eval
