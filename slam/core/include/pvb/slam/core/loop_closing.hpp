#pragma once
// Loop closing for RGB-D (ORB-SLAM2 LoopClosing with the scale known: SE(3)
// instead of Sim(3)).  Runs after local mapping has
// processed a keyframe, on the same thread (the local-mapping worker, or
// inline in synchronous mode), holding the map mutex:
//
//   1. candidates by pose proximity: keyframes at least `min_keyframe_gap`
//      ids older, outside the new keyframe's covisibility neighbourhood,
//      whose camera centre lies within `search_radius_m` and whose optical
//      axis within `max_angle_deg` of the new keyframe's estimate; each
//      verified by appearance (brute-force ORB matching of its map points,
//      ratio 0.75, orientation check, >= `min_matches`);
//   2. consistency: a candidate's group (it and its covisibles) must meet a
//      group of the previous keyframe's candidates `consistency` times in a
//      row (ORB-SLAM2 DetectLoop);
//   3. geometric verification: EPnP RANSAC on the brute-force matches, pose
//      optimisation, guided search by projection of the candidate's
//      neighbourhood, pose optimisation again; >= `min_inliers` inliers and
//      a correction within `max_correction_m` / `max_correction_deg` (plus
//      `max_correction_deg_per_km` a kilometre of path between the two); a
//      correction over `lookalike_check_above_m` also verifies the keyframe
//      against the map's best-scoring keyframes one by one, and any that
//      verifies at another place, with at least `ambiguity_inlier_share`
//      of the best one's inliers, makes it ambiguous;
//   4. correction: the new keyframe's covisibility neighbourhood is moved
//      with it, duplicated points fused (the loop side replaces the current
//      side), loop edges added, the essential graph (spanning tree, loop
//      edges, covisibility edges of weight >= `essential_weight`) optimised
//      as an SE(3) pose graph, and every map point moved with its reference
//      keyframe.  The graph is optimised on a copy of the poses with the
//      map mutex free, so tracking goes on meanwhile; keyframes not yet in
//      the graph (queued, or made by tracking in the meantime) move with
//      the new keyframe, before and after;
//   5. optionally (`global_ba`, off by default) a bundle adjustment of the
//      whole map, inline, with the map locked (tracking waits).
//
// A keyframe of a provisional map (begun while lost in a loaded map that
// is being extended, Tracking) is also checked against the map's own
// keyframes.  A verified match there merges the two (ORB-SLAM3's map
// merge with the scale known): the provisional map moves rigidly to where
// the verification put the keyframe, its spanning tree is hung under the
// matched keyframe, and step 4 welds the seam.  The correction bounds and
// the drift check do not apply to a merge (the two frames are unrelated);
// the ambiguity check does.  Without a bound on the transform, one view
// is not enough (a place outside the map can look like one in it): the
// transform is held back until `merge_confirmations` keyframes of the
// provisional map in a row have been verified at the pose it predicts, by
// projecting the map's points around the last match (ORB-SLAM3 asks for
// three).  Tracking offers a second way in (suggest_merge): a frame of the
// provisional map relocalised among the map's keyframes, with the
// relocalisation's look-alike checks, counts as the first match.
//
// Step 1 by default asks the bag-of-words database (PlaceRecognizer:
// ORB-SLAM2's DetectLoopCandidates) instead of pose proximity, and step 3
// verifies every consistent candidate, refusing the loop when the
// correction is implausible for the path driven or when two candidates
// verify at different places (docs/place_recognition.md).  Pose proximity
// only works while the drift is small compared with the search radius.
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "pvb/slam/core/map.hpp"
#include "pvb/slam/core/options.hpp"
#include "pvb/slam/core/place_recognition.hpp"
#include "pvb/slam/core/reports.hpp"

namespace pvb::slam {

/// Result of the geometric verification of one candidate.
struct LoopMatch {
  /// How far the verification got: the stage that refused the candidate, or kAccepted.
  enum class Stage { kMatches, kRansac, kInliers, kAccepted };
  Stage stage = Stage::kMatches;
  bool accepted = false;
  geom::SE3d T_c_w;  ///< the new keyframe's pose in the candidate's map frame
  /// Per keypoint of the new keyframe: the matched loop-side point (inliers only), or null.
  std::vector<std::shared_ptr<MapPoint>> points;
  int initial_matches = 0;  ///< brute-force matches
  int ransac_inliers = 0;
  int inliers = 0;          ///< after the guided search and pose optimisation
};

/// Where a verified candidate put the new keyframe's camera, with how many
/// inliers, and whether it was a look-alike (a best-scoring keyframe tried
/// one by one) rather than a consistent candidate.
struct VerifiedPlace {
  Eigen::Vector3d centre_w;
  int inliers = 0;
  bool lookalike = false;
};

/// The ambiguity check: two rival places among `places` lie more than
/// `distance_m` apart.  Every consistent candidate is a rival; a
/// look-alike is one only with at least `inlier_share` x the most inliers
/// among them.  A view that shares a part of its scene with a keyframe
/// elsewhere (the far end of an aisle, seen from along it) verifies there
/// with a few inliers at a pose those few hardly fix: no rival place.
bool places_apart(const std::vector<VerifiedPlace>& places, double distance_m, double inlier_share);

/// Pose-proximity candidates for `kf` (step 1 without the appearance
/// check), closest first, at most options.max_candidates.  Call with the
/// map mutex held.
std::vector<std::shared_ptr<KeyFrame>> pose_candidates(const Map& map, const KeyFrame& kf,
                                                       const LoopClosingOptions& options);

/// Geometric verification of `cand` for `kf` (step 3).  Call with the map
/// mutex held.  Deterministic (fixed RANSAC seed).
LoopMatch verify_loop(const KeyFrame& kf, const std::shared_ptr<KeyFrame>& cand, const LoopClosingOptions& options);
/// verify_loop in two steps.  `probe` starts as `kf`'s frame without map
/// points (loop_probe).  The first step matches descriptors, runs EPnP
/// RANSAC and optimises the pose: false when that refuses `cand`
/// (out->stage says where), else probe->T_c_w is the first pose.  The
/// second adds the guided search and the final pose and inliers.
Frame loop_probe(const KeyFrame& kf);
bool verify_by_descriptors(const KeyFrame& kf, const KeyFrame& cand, const LoopClosingOptions& options,
                           Frame* probe, LoopMatch* out);
void verify_by_projection(const std::shared_ptr<KeyFrame>& cand, const LoopClosingOptions& options,
                          Frame* probe, LoopMatch* out);
/// Verification of `kf` at a predicted pose `T_c_w` in `cand`'s map (a
/// held-back merge): the points of `cand`, its covisibles and theirs,
/// projected and matched, then a pose optimisation; accepted with
/// min_inliers inliers within 0.5 m (or max_correction_m, if smaller) of
/// the prediction.
LoopMatch verify_at(const KeyFrame& kf, const std::shared_ptr<KeyFrame>& cand, const geom::SE3d& T_c_w,
                    const LoopClosingOptions& options);

class LoopClosing {
 public:
  /// `place` (may be null: pose proximity only) finds BoW candidates.
  LoopClosing(Map& map, const LoopClosingOptions& options, PlaceRecognizer* place = nullptr);

  /// Detects and, when verified, closes a loop for a keyframe local mapping
  /// has just processed.  Takes the map mutex.  Returns true when a loop
  /// was closed.
  bool process(const std::shared_ptr<KeyFrame>& kf);

  /// A merge hypothesis from tracking: provisional map `from` lies at
  /// T_into_from in the map's own frame, found around the map's keyframe
  /// `anchor` (a frame relocalised there).  Held back as a first match
  /// that the provisional map's next keyframes confirm, unless a merge
  /// transform is held back already.  Takes the map mutex.
  void suggest_merge(std::uint32_t from, const geom::SE3d& T_into_from, std::shared_ptr<KeyFrame> anchor);

  LoopClosingStats stats() const;
  /// The detections so far and their time, without copying the stats.
  LoopDetectTotals detect_totals() const;
  const LoopClosingOptions& options() const { return options_; }

  /// Called on the loop-closing thread while a correction's essential
  /// graph is optimised, with the map mutex free (what tracking does
  /// meanwhile, for tests).
  void set_while_optimising(std::function<void()> f) { while_optimising_ = std::move(f); }

 private:
  /// A merge transform held back until confirmed (merge_confirmations).
  struct PendingMerge {
    std::uint32_t from = 0;            ///< the provisional map
    geom::SE3d T_into_from;            ///< its frame into the map's own
    std::shared_ptr<KeyFrame> anchor;  ///< the map's keyframe around which the last match lay
    int confirmed = 0;                 ///< keyframes verified so far
  };
  /// For a keyframe of a provisional map with a held-back transform: its
  /// verification at the predicted pose; true (with *best and *loop_kf)
  /// when that makes merge_confirmations and the maps are to be merged.
  bool confirm_merge(const std::shared_ptr<KeyFrame>& kf, LoopMatch* best, std::shared_ptr<KeyFrame>* loop_kf);
  /// A candidate and its covisibles, with how many times in a row it was consistent.
  struct Group {
    std::set<std::uint64_t> ids;
    int consistency = 0;
  };
  /// Steps 1-2; returns the candidates consistent enough for verification.
  std::vector<std::shared_ptr<KeyFrame>> detect(const std::shared_ptr<KeyFrame>& kf);
  /// Step 1: pose-proximity candidates with the appearance check, or BoW candidates.
  std::vector<std::shared_ptr<KeyFrame>> propose(const std::shared_ptr<KeyFrame>& kf);
  /// Step 3 over every consistent candidate, with the drift and ambiguity
  /// checks (for a merge, the ambiguity check only); the accepted candidate
  /// (most inliers) or null.
  std::shared_ptr<KeyFrame> verify(const std::shared_ptr<KeyFrame>& kf,
                                   const std::vector<std::shared_ptr<KeyFrame>>& consistent, bool merge,
                                   LoopMatch* best);
  /// What one verify() saw, added to the stats at its end.
  struct VerifyTally {
    int verified = 0, refused_correction = 0, drift = 0, refused_first_pose = 0;
    std::array<int, 3> refused_at{};  ///< by LoopMatch::Stage: matches, RANSAC, inliers
    bool lookalike_checked = false, ambiguous = false;
    double verify_ms = 0;
    int refusal_rank = -1;  ///< how far the furthest refused candidate got (-1: none refused)
    LoopRefusal refusal;
  };
  void add_tally(const VerifyTally& t, bool found);
  /// What verify() has found so far: the verified places, the best loop.
  struct VerifyState;
  /// A candidate past RANSAC whose first pose lies this far beyond the hard
  /// cap or the drift bound (1.5 x + 0.5 m; the guided search moves a pose
  /// by centimetres): its guided search waits until a loop is in reach.
  bool far_beyond_bounds(const KeyFrame& kf, const LoopMatch& first, double path_m) const;
  /// Judges a verified `cand` (or one refused on its first pose,
  /// `first_pose`) against the caps, the drift bound and the best so far;
  /// true when verification stops (the ambiguity check off).
  bool judge(const KeyFrame& kf, const std::shared_ptr<KeyFrame>& cand, LoopMatch m, double path_m,
             bool merge, bool first_pose, VerifyState* st) const;
  /// Camera path length (current estimates) over the keyframes from `from` to `to` by id.
  double path_length_m(std::uint64_t from, std::uint64_t to) const;
  /// The cap on a loop correction's angle over `path_m` of path between
  /// the two keyframes: max_correction_deg + max_correction_deg_per_km x it.
  double max_correction_deg(double path_m) const;
  /// The drift bound on moving `kf`'s camera centre to close a loop with a
  /// keyframe `path_m` of path away by a correction turning it through
  /// `angle_deg`.
  double drift_bound_m(const KeyFrame& kf, double path_m, double angle_deg) const;
  /// Step 5 (optional): bundle adjustment of every keyframe and point,
  /// keyframe 0 fixed, map locked throughout.
  void global_bundle_adjustment(LoopEvent* event, std::uint32_t map_id);
  /// Steps 1-3 for a keyframe: the verified candidate (or null), whether it
  /// merges a provisional map, and the detection figures.
  std::shared_ptr<KeyFrame> find(const std::shared_ptr<KeyFrame>& kf, LoopMatch* best, bool* merge,
                                 std::chrono::steady_clock::time_point t0);
  /// Steps 4-6 (a merge first moves the provisional map) and the event.
  /// `lock` holds the map mutex; the correction lets go of it for a while.
  void close(const std::shared_ptr<KeyFrame>& kf, const std::shared_ptr<KeyFrame>& loop_kf, const LoopMatch& best,
             bool merge, double detect_ms, std::unique_lock<std::mutex>& lock);
  /// Step 4, with `lock` let go while the essential graph is optimised;
  /// returns how long it was let go (ms).
  double correct(const std::shared_ptr<KeyFrame>& kf, const std::shared_ptr<KeyFrame>& loop_kf, const LoopMatch& m,
                 LoopEvent* event, std::unique_lock<std::mutex>& lock);

  Map& map_;
  LoopClosingOptions options_;
  PlaceRecognizer* place_ = nullptr;
  std::vector<Group> groups_;  ///< consistency groups of the previous keyframe
  std::optional<PendingMerge> pending_merge_;
  std::uint64_t last_loop_kf_id_ = 0;
  bool any_loop_ = false;
  std::function<void()> while_optimising_;
  mutable std::mutex stats_mutex_;
  LoopClosingStats stats_;
};

}  // namespace pvb::slam
