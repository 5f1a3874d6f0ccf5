// Loop correction (step 4): a verified loop's neighbourhood moved, its points
// fused, the essential graph optimised, and a provisional map merged.
// LoopClosing's detection and verification are in loop_closing.cpp.
#include "pvb/slam/core/loop_closing.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include "loop_correction.hpp"
#include "pvb/common/clock.hpp"
#include "pvb/slam/core/local_mapping.hpp"
#include "pvb/slam/core/matcher.hpp"
#include "pvb/slam/optim/optimizer.hpp"

namespace pvb::slam {
namespace {

using KeyFramePtr = std::shared_ptr<KeyFrame>;
/// New covisibility links of the corrected neighbourhood, by keyframe id.
using LoopLinks = std::map<std::uint64_t, std::vector<KeyFramePtr>>;

/// Step 4.1: the new keyframe's covisibility neighbourhood, moved with it.
struct MovedGroup {
  std::vector<KeyFramePtr> keyframes;                   ///< the new keyframe, then its covisibles
  std::map<std::uint64_t, geom::SE3d> uncorrected;      ///< T_c_w before the move, by keyframe id
  std::map<std::uint64_t, std::uint64_t> corrected_by;  ///< point id -> keyframe id it moved with
};

/// Moves the new keyframe's neighbourhood with it (ORB-SLAM2 CorrectLoop,
/// scale 1): T_iw' = T_i_cur * T_cur_w', points with the keyframe that
/// corrected them first.  `T_cur_w` is the new keyframe's verified pose.
MovedGroup move_neighbourhood(const KeyFramePtr& kf, const geom::SE3d& T_cur_w) {
  MovedGroup g;
  g.keyframes = {kf};
  for (const auto& n : kf->best_covisibles(-1))
    if (!n->fixed()) g.keyframes.push_back(n);  // a loaded map being extended stays where it is
  const geom::SE3d T_w_cur = kf->T_c_w().inverse();
  std::map<std::uint64_t, geom::SE3d> corrected;  // T_c_w by keyframe id
  for (const auto& k : g.keyframes) {
    g.uncorrected[k->id()] = k->T_c_w();
    corrected[k->id()] = k->T_c_w() * T_w_cur * T_cur_w;
  }
  for (const auto& k : g.keyframes) {
    const geom::SE3d move = corrected.at(k->id()).inverse() * g.uncorrected.at(k->id());
    for (const auto& mp : k->map_points()) {
      if (!mp || mp->bad() || g.corrected_by.count(mp->id())) continue;
      if (const auto ref = mp->reference_keyframe(); ref && ref->fixed()) continue;
      mp->set_p_w(move * mp->p_w());
      g.corrected_by[mp->id()] = k->id();
    }
  }
  for (const auto& k : g.keyframes) k->correct_T_c_w(corrected.at(k->id()));
  for (const auto& k : g.keyframes)
    for (const auto& mp : k->map_points())
      if (mp && !mp->bad()) mp->update_normal_and_depth();
  return g;
}

/// Covisible keyframe ids of each keyframe of `group`.
std::map<std::uint64_t, std::set<std::uint64_t>> neighbour_ids(const std::vector<KeyFramePtr>& group) {
  std::map<std::uint64_t, std::set<std::uint64_t>> ids;
  for (const auto& k : group)
    for (const auto& n : k->best_covisibles(-1)) ids[k->id()].insert(n->id());
  return ids;
}

/// The verified matches: the loop-side point replaces the current one, or
/// joins the new keyframe where it has none.  Returns how many.
int fuse_verified_matches(const KeyFramePtr& kf, const LoopMatch& m) {
  int fused = 0;
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const auto& lp = m.points[i];
    if (!lp || lp->bad()) continue;
    const auto existing = kf->map_points()[i];
    if (existing == lp) continue;
    if (existing && !existing->bad()) {
      existing->replace(lp, existing);
      ++fused;
    } else if (lp->index_in(kf->id()) < 0) {
      kf->set_map_point(i, lp);
      lp->add_observation(kf, i);
      lp->compute_distinctive_descriptor();
      ++fused;
    }
  }
  return fused;
}

/// Step 4.2: fuses the duplicated points: the verified matches first, then
/// the loop neighbourhood's points projected into the corrected
/// neighbourhood.  Returns how many.
int fuse_loop_points(Map& map, const KeyFramePtr& kf, const KeyFramePtr& loop_kf, const LoopMatch& m,
                     const std::vector<KeyFramePtr>& group) {
  int fused = fuse_verified_matches(kf, m);
  std::vector<std::shared_ptr<MapPoint>> loop_points;
  std::set<std::uint64_t> seen;
  std::vector<KeyFramePtr> loop_group = {loop_kf};
  for (const auto& n : loop_kf->best_covisibles(-1)) loop_group.push_back(n);
  for (const auto& g : loop_group)
    for (const auto& mp : g->map_points())
      if (mp && !mp->bad() && seen.insert(mp->id()).second) loop_points.push_back(mp);
  for (const auto& k : group)
    if (!k->bad()) fused += fuse(map, k, loop_points, 4.0, FusePolicy::kIncomingWins);
  map.remove_bad_points();
  return fused;
}

/// Step 4.3: the neighbours each keyframe of the group has gained, outside the group.
LoopLinks new_loop_links(const std::vector<KeyFramePtr>& group,
                         std::map<std::uint64_t, std::set<std::uint64_t>> neighbours_before) {
  std::set<std::uint64_t> group_ids;
  for (const auto& k : group) group_ids.insert(k->id());
  LoopLinks links;
  for (const auto& k : group) {
    if (k->bad()) continue;
    k->update_connections();
    for (const auto& n : k->best_covisibles(-1))
      if (!neighbours_before[k->id()].count(n->id()) && !group_ids.count(n->id()))
        links[k->id()].push_back(n);
  }
  return links;
}

/// Step 4.4: the essential graph as an SE(3) pose graph.  Nodes: keyframes
/// in the spanning tree (and the loop keyframe, held fixed: the gauge).
/// Measurements come from the poses before the correction (the odometry as
/// it was); the new loop links from the corrected poses.  An edge between
/// two nodes is added once.
class EssentialGraph {
 public:
  EssentialGraph(const Map& map, const KeyFramePtr& loop_kf, double rotation_weight)
      : rotation_weight_(rotation_weight) {
    const std::uint32_t own = map.map_of(*loop_kf);
    for (const auto& [id, k] : map.keyframes()) {
      if (k->bad() || map.map_of(*k) != own) continue;  // other maps lie in frames of their own
      const bool in_tree = id == 0 || k->root() || k->parent() != nullptr || k == loop_kf;
      initial[id] = k->T_c_w();
      if (!in_tree) continue;  // queued, not yet processed by local mapping: moved in step 4.5
      node[id] = problem.nodes.size();
      problem.nodes.push_back({id, k->T_c_w(), k == loop_kf || k->fixed()});
      node_kf.push_back(k);
    }
  }

  /// The new links of weight >= essential_weight, and the loop itself, from the corrected poses.
  void add_loop_links(const LoopLinks& links, const KeyFramePtr& kf, const KeyFramePtr& loop_kf,
                      int essential_weight) {
    for (const auto& [id, linked] : links) {
      auto it = node.find(id);
      if (it == node.end()) continue;
      const auto& k = node_kf[it->second];
      for (const auto& n : linked) {
        auto jt = node.find(n->id());
        if (jt == node.end()) continue;
        const bool the_loop = k == kf && n == loop_kf;
        if (!the_loop && k->weight(n->id()) < essential_weight) continue;
        add_edge(it->second, jt->second, k->T_c_w(), n->T_c_w());
      }
    }
    if (node.count(kf->id()) && node.count(loop_kf->id()))
      add_edge(node.at(kf->id()), node.at(loop_kf->id()), kf->T_c_w(), loop_kf->T_c_w());
  }

  /// Spanning tree, earlier loop edges and covisibility edges of weight >=
  /// essential_weight, measured from `uncorrected` poses where given.
  void add_odometry_edges(const std::map<std::uint64_t, geom::SE3d>& uncorrected, int essential_weight) {
    const auto measured = [&](const KeyFramePtr& k) {
      auto it = uncorrected.find(k->id());
      return it != uncorrected.end() ? it->second : k->T_c_w();
    };
    for (std::size_t i = 0; i < node_kf.size(); ++i) {
      const auto& k = node_kf[i];
      const geom::SE3d T_iw = measured(k);
      if (auto p = k->parent()) {
        auto jt = node.find(p->id());
        if (jt != node.end()) add_edge(i, jt->second, T_iw, measured(p));
      }
      for (const auto& l : k->loop_edges()) {
        auto jt = node.find(l->id());
        if (jt != node.end() && l->id() < k->id()) add_edge(i, jt->second, T_iw, measured(l));
      }
      for (const auto& n : k->best_covisibles(-1)) {
        if (k->weight(n->id()) < essential_weight) break;  // sorted by weight
        if (n->id() >= k->id()) continue;
        auto jt = node.find(n->id());
        if (jt != node.end()) add_edge(i, jt->second, T_iw, measured(n));
      }
    }
  }

  PoseGraphProblem problem;
  std::map<std::uint64_t, std::size_t> node;    ///< keyframe id -> node index
  std::vector<KeyFramePtr> node_kf;             ///< node index -> keyframe
  std::map<std::uint64_t, geom::SE3d> initial;  ///< T_c_w of every good keyframe at the start

 private:
  void add_edge(std::size_t i, std::size_t j, const geom::SE3d& T_iw, const geom::SE3d& T_jw) {
    if (!inserted_.insert(std::minmax(i, j)).second) return;
    problem.edges.push_back({i, j, T_iw * T_jw.inverse(), 1.0, rotation_weight_});
  }

  double rotation_weight_;
  std::set<std::pair<std::size_t, std::size_t>> inserted_;
};

/// Poses T_c_w of keyframes before and after a move, by id.
struct PoseMoves {
  std::map<std::uint64_t, geom::SE3d> before, after;
};

/// Every point of the map moves with its reference keyframe (or the
/// keyframe that corrected it in step 4.1), when that keyframe moved.
void move_points(Map& map, const PoseMoves& moves, const MovedGroup& moved) {
  for (const auto& [id, mp] : map.points()) {
    if (mp->bad()) continue;
    std::uint64_t ref_id;
    auto cb = moved.corrected_by.find(id);
    if (cb != moved.corrected_by.end()) {
      ref_id = cb->second;
    } else {
      auto ref = mp->reference_keyframe();
      if (!ref) continue;
      ref_id = ref->id();
    }
    auto it0 = moves.before.find(ref_id);
    auto it1 = moves.after.find(ref_id);
    if (it0 == moves.before.end() || it1 == moves.after.end()) continue;
    mp->set_p_w(it1->second.inverse() * (it0->second * mp->p_w()));
  }
}

/// The moves of the good keyframes of `map_id` that are not in the graph
/// (queued for local mapping, or made by tracking since) nor in `skip`:
/// each as the new keyframe moved, T_c_w' = T_c_w * kf_move^-1 with
/// kf_move = T_kf_w'^-1 * T_kf_w.
PoseMoves move_off_graph(const Map& map, const EssentialGraph& g, std::uint32_t map_id, const geom::SE3d& kf_move,
                         const std::map<std::uint64_t, geom::SE3d>& skip = {}) {
  PoseMoves moves;
  for (const auto& [id, k] : map.keyframes()) {
    if (k->bad() || g.node.count(id) || skip.count(id) || map.map_of(*k) != map_id) continue;
    moves.before[id] = k->T_c_w();
    moves.after[id] = k->T_c_w() * kf_move.inverse();
  }
  return moves;
}

/// Before the graph is optimised with the map unlocked: the keyframes
/// local mapping has not processed yet follow the new keyframe's move in
/// step 4.1, so that tracking, which goes on meanwhile, finds the recent
/// map in one frame.  (The neighbourhood moved in step 4.1 already.)
void move_queued(Map& map, const EssentialGraph& g, const KeyFramePtr& kf, const MovedGroup& moved) {
  const geom::SE3d kf_move = kf->T_c_w().inverse() * moved.uncorrected.at(kf->id());
  const PoseMoves moves = move_off_graph(map, g, map.map_of(*kf), kf_move, moved.uncorrected);
  move_points(map, moves, moved);
  for (const auto& [id, T_c_w] : moves.after) map.keyframes().at(id)->correct_T_c_w(T_c_w);
}

/// Step 4.5: writes the optimised poses back; every point moves with its
/// reference keyframe (or the keyframe that corrected it in step 4.1).
/// Keyframes not in the graph (queued, or made by tracking while the graph
/// was optimised) move as the new keyframe did in the optimisation.
void write_back(Map& map, const EssentialGraph& g, const KeyFramePtr& kf, const MovedGroup& moved) {
  geom::SE3d kf_move = geom::SE3d::Identity();
  if (auto it = g.node.find(kf->id()); it != g.node.end())
    kf_move = g.problem.nodes[it->second].T_c_w.inverse() * g.initial.at(kf->id());
  PoseMoves moves = move_off_graph(map, g, map.map_of(*kf), kf_move);
  for (std::size_t i = 0; i < g.node_kf.size(); ++i) {
    if (g.node_kf[i]->bad()) continue;
    const std::uint64_t id = g.node_kf[i]->id();
    moves.before[id] = g.initial.at(id);
    moves.after[id] = g.problem.nodes[i].T_c_w;
  }
  move_points(map, moves, moved);
  for (const auto& [id, T_c_w] : moves.after) map.keyframes().at(id)->correct_T_c_w(T_c_w);
  for (const auto& [id, mp] : map.points())
    if (!mp->bad()) mp->update_normal_and_depth();
}

}  // namespace

void detail::merge_into(Map& map, const std::shared_ptr<KeyFrame>& kf, const std::shared_ptr<KeyFrame>& loop_kf,
                        const geom::SE3d& T_c_w_into) {
  const std::uint32_t from = map.map_of(*kf), into = map.map_of(*loop_kf);
  const geom::SE3d T_into_from = frame_into(T_c_w_into, *kf);
  const geom::SE3d T_from_into = T_into_from.inverse();
  std::vector<std::shared_ptr<MapPoint>> moved;
  std::set<std::uint64_t> seen;
  for (const auto& [id, k] : map.keyframes()) {
    if (k->bad() || map.map_of(*k) != from) continue;
    for (const auto& mp : k->map_points())
      if (mp && !mp->bad() && seen.insert(mp->id()).second) moved.push_back(mp);
    k->correct_T_c_w(k->T_c_w() * T_from_into);
  }
  for (const auto& mp : moved) mp->set_p_w(T_into_from * mp->p_w());
  map.merge_provisional(from, into);
  kf->reroot_under(loop_kf);
  for (const auto& mp : moved) mp->update_normal_and_depth();
}

double LoopClosing::correct(const std::shared_ptr<KeyFrame>& kf, const std::shared_ptr<KeyFrame>& loop_kf,
                            const LoopMatch& m, LoopEvent* event, std::unique_lock<std::mutex>& lock) {
  kf->update_connections();
  const MovedGroup moved = move_neighbourhood(kf, m.T_c_w);
  auto neighbours_before = neighbour_ids(moved.keyframes);
  event->fused_points = fuse_loop_points(map_, kf, loop_kf, m, moved.keyframes);
  const LoopLinks links = new_loop_links(moved.keyframes, std::move(neighbours_before));
  EssentialGraph graph(map_, loop_kf, options_.rotation_weight);
  graph.add_loop_links(links, kf, loop_kf, options_.essential_weight);
  graph.add_odometry_edges(moved.uncorrected, options_.essential_weight);
  event->graph_keyframes = static_cast<int>(graph.problem.nodes.size());
  event->graph_edges = static_cast<int>(graph.problem.edges.size());
  move_queued(map_, graph, kf, moved);
  kf->add_loop_edge(loop_kf);
  loop_kf->add_loop_edge(kf);
  // The graph is a copy of the poses: tracking goes on while it is
  // optimised (local mapping, on this thread, waits).
  const auto t0 = std::chrono::steady_clock::now();
  lock.unlock();
  if (while_optimising_) while_optimising_();
  optimize_pose_graph(&graph.problem);
  lock.lock();
  const double unlocked_ms = ms_since(t0);
  write_back(map_, graph, kf, moved);
  return unlocked_ms;
}

void LoopClosing::global_bundle_adjustment(LoopEvent* event, std::uint32_t map_id) {
  BaProblem problem;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  std::vector<std::shared_ptr<MapPoint>> pts;
  std::map<std::uint64_t, std::size_t> kf_index;
  for (const auto& [id, k] : map_.keyframes()) {
    if (k->bad() || map_.map_of(*k) != map_id) continue;  // a provisional map lies in a frame of its own
    kf_index[id] = kfs.size();
    // keyframe 0 (or a provisional map's root) fixes the gauge (the world frame), a loaded map its own
    problem.keyframes.push_back({id, k->T_c_w(), id == 0 || k->root() || k->fixed()});
    kfs.push_back(k);
  }
  if (kfs.size() < 2) return;
  for (const auto& [id, mp] : map_.points()) {
    if (mp->bad()) continue;
    const std::size_t p = pts.size();
    bool any = false;
    for (const auto& [kid, o] : mp->observations()) {
      auto it = kf_index.find(kid);
      if (it == kf_index.end()) continue;
      if (!any) {
        problem.points.push_back({id, mp->p_w()});
        pts.push_back(mp);
        any = true;
      }
      problem.edges.push_back({it->second, p, kfs[it->second]->frame().observation(o.idx)});
    }
  }
  if (problem.edges.empty()) return;
  BaOptions options;
  options.sparse_schur = true;
  const BaResult result = slam::local_bundle_adjustment(&problem, kfs[0]->frame().cam->K, options);
  erase_outlier_observations(problem, result.outlier_edges, kfs, pts);
  event->global_ba_outliers = static_cast<int>(result.outlier_edges.size());
  for (std::size_t k = 0; k < kfs.size(); ++k)
    if (!problem.keyframes[k].fixed) kfs[k]->set_T_c_w(problem.keyframes[k].T_c_w);
  for (std::size_t p = 0; p < pts.size(); ++p)
    if (!pts[p]->bad()) {
      pts[p]->set_p_w(problem.points[p].p_w);
      pts[p]->update_normal_and_depth();
    }
  map_.remove_bad_points();
}

}  // namespace pvb::slam
