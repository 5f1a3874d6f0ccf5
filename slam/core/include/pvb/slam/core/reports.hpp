#pragma once
// What the core reports, as plain values: per-frame tracking figures,
// relocalisations, the totals of local mapping and loop closing, and the
// bytes that frames, keyframes and the map hold.  Needs none of the
// algorithms' headers, so users of System (system.hpp) see these types
// without the tracker, the map or the mappers.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/pematch/fundamental.hpp"

namespace pvb::slam {

/// Bytes a frame holds, by structure: heap blocks as malloc sizes them
/// (pvb/common/memory.hpp) plus the object itself.  The pyramid is shared
/// by the frame and the keyframe made from it; each counts it.
struct FrameMemory {
  std::size_t pyramid = 0;       ///< grey image pyramid (patch alignment)
  std::size_t keypoints = 0;     ///< keys and keys_un
  std::size_t descriptors = 0;
  std::size_t per_keypoint = 0;  ///< depth, u_right, map-point links, outlier flags, aligned_for
  std::size_t grid = 0;          ///< the area-search index
  std::size_t object = 0;        ///< sizeof(Frame)
  std::size_t spilled = 0;       ///< keypoints, descriptors, depths and grid in the feature file (not in total)
  std::size_t total() const { return pyramid + keypoints + descriptors + per_keypoint + grid + object; }
  FrameMemory& operator+=(const FrameMemory& o);
};

/// Bytes a keyframe holds, by structure (heap blocks as malloc sizes them,
/// plus the objects themselves); docs/slam.md, "Keyframe memory".
struct KeyFrameMemory {
  FrameMemory frame;       ///< its frame's data
  std::size_t bow = 0;     ///< bag of words and the direct index
  std::size_t graph = 0;   ///< covisibility, spanning tree, loop edges
  std::size_t object = 0;  ///< the KeyFrame beyond its Frame, with make_shared's control block
  std::size_t total() const { return frame.total() + bow + graph + object; }
  KeyFrameMemory& operator+=(const KeyFrameMemory& o);
};

/// What the map holds: its keyframes (by structure, summed) and points.
struct MapMemory {
  std::size_t keyframes = 0;
  KeyFrameMemory keyframe_bytes;
  /// Keyframes outside the local map (their pyramid released) and what
  /// they hold: the part of keyframe_bytes that grows with the route.
  std::size_t keyframes_outside = 0;
  KeyFrameMemory outside_bytes;
  std::size_t points = 0;
  std::size_t point_bytes = 0;
  std::size_t keyframes_spilled = 0;  ///< their features in the feature file (FrameMemory::spilled)
};

/// kDeadReckoning: vision has failed and the IMU (and wheels) carry the
/// pose, for at most TrackingOptions::blind_max_s / blind_max_m.
enum class TrackingState { kNotInitialized, kOk, kLost, kDeadReckoning };
const char* to_string(TrackingState s);

/// How the pose of a frame was found.
enum class TrackingMethod {
  kNone,
  kInitialization,
  kMotionModel,
  kReferenceKeyFrame,
  kRelocalization,
  kDeadReckoning,  ///< the pose predicted by the motion sensors alone
  kAfterBlind,     ///< the local map found again from the dead-reckoned pose
  kCarriedRestart, ///< lost: a new keyframe at the pose the wheels carried
};
/// The method as timing.csv writes it: "none", "init", "motion", "refkf",
/// "reloc", "dead_reckoning", "after_blind", "carried_restart".
const char* to_string(TrackingMethod m);

/// Per-frame figures for timing.csv and the tests.
struct TrackingStats {
  TrackingMethod method = TrackingMethod::kNone;
  int coarse_matches = 0;       ///< motion-model matches after the orientation check
  int matches_kept = 0;         ///< after PE-match (== coarse without it)
  double pe_match_ms = 0;       ///< time in PE-match
  /// With TrackingOptions::pe_skip_low_parallax on (else 0 / false): the
  /// median pixel displacement that the predicted translation alone causes
  /// at the motion model's matches with depth (+inf when unknown), and
  /// whether PE-match was skipped because it is below the epipolar threshold.
  double translation_parallax_px = 0;
  bool pe_skipped = false;
  int inliers = 0;              ///< map-point inliers after the local-map optimisation
  int align_tried = 0;          ///< map-point matches patch alignment was tried on
  int aligned = 0;              ///< of those, the ones it moved (the others keep the keypoint)
  double align_ms = 0;          ///< time in patch alignment
  bool new_keyframe = false;
  /// Inputs of the keyframe decision (ORB-SLAM2 NeedNewKeyFrame), filled
  /// whenever the frame was tracked: close keypoints (depth under ThDepth)
  /// tracked and not tracked, and the reference keyframe's points with at
  /// least 3 observations (2 while the map has at most 2 keyframes).
  int kf_tracked_close = 0;
  int kf_untracked_close = 0;
  int kf_ref_points = 0;
  /// The reference keyframe's map points (any number of observations) and
  /// how many of them this frame tracks.
  int kf_ref_all = 0;
  int kf_ref_shared = 0;
  /// The local map the frame was tracked against (0 when it was not):
  /// its keyframes and its points, before the projection search.
  int local_keyframes = 0;
  int local_points = 0;
  /// The motion model's coarse matches (empty when it did not run), for
  /// scoring PE-match against ground truth: pixel pairs (last frame,
  /// this frame), undistorted and as detected, the octaves of both
  /// keypoints, PE-match's keep mask (all 1 in baseline mode or with no
  /// model) and whether the pose optimisation kept the match as an inlier.
  struct MotionMatches {
    std::vector<PointMatch> undistorted;
    std::vector<PointMatch> raw;
    std::vector<std::array<int, 2>> octaves;
    std::vector<std::uint8_t> pe_keep;
    std::vector<std::uint8_t> pose_inlier;
  };
  MotionMatches motion;
  /// On a lost frame where relocalisation was tried: the step at which it
  /// failed (kNone when it was not tried or the frame was tracked).
  enum class RelocFailure {
    kNone,
    kNoCandidates,   ///< no keyframe to try (place recognition returned none)
    kFewMatches,     ///< no candidate had 15 descriptor matches
    kPnp,            ///< no candidate gave a PnP RANSAC pose with 10 inliers
    kFewInliers,     ///< no candidate reached 50 pose inliers
    kAmbiguous,      ///< two candidates matched at places apart
    kLookalike,      ///< a look-alike keyframe matched at another place
    kOdometry,       ///< every match lay where the wheels say the robot cannot be
    kLocalMap,       ///< relocalised, then the local map gave too few inliers
  };
  RelocFailure reloc_failure = RelocFailure::kNone;
  /// A start from two views on this frame (0 otherwise): its points, and
  /// the measured depths whose median ratio gave its scale.
  int two_view_points = 0;
  int two_view_scale_points = 0;
  /// Why the frame was not tracked (empty when it was): each attempted
  /// step's failure, "; "-separated, e.g. "motion model: only 7 map matches
  /// after pose optimisation (need 10); reference keyframe: only 9 matches (need 15)".
  std::string failure;
};

/// A short name of the step, e.g. "no candidates", "too few pose inliers".
const char* to_string(TrackingStats::RelocFailure f);

/// One relocalisation: a frame tracked again after a loss, and the
/// keyframe whose points found it.
struct RelocEvent {
  std::uint64_t frame_id = 0;
  std::int64_t t_ns = 0;
  std::uint64_t keyframe_id = 0, keyframe_frame_id = 0;
  std::int64_t keyframe_t_ns = 0;
  int candidates = 0;  ///< keyframes tried
  int inliers = 0;     ///< after the local-map optimisation
  /// The frame's pose relative to the keyframe's, as estimated when it was
  /// found (T_f_w * T_kf_w^-1): what ground truth can judge.
  geom::SE3d T_f_kf;
};

/// What local mapping has done so far (for stats and reports).
struct LocalMappingStats {
  std::int64_t keyframes = 0;         ///< keyframes processed
  std::int64_t local_ba = 0;          ///< local bundle adjustments started
  std::int64_t local_ba_stopped = 0;  ///< of which cut short by a new keyframe (worker mode only)
  double busy_ms = 0;                 ///< time spent processing keyframes
  double local_ba_ms = 0;             ///< of which in the local BAs' solver
};
/// {"keyframes", "local_ba", "local_ba_stopped", "busy_ms", "local_ba_ms"} for stats.json and metrics.json.
std::string to_json(const LocalMappingStats& stats);

/// One closed loop.
struct LoopEvent {
  std::uint64_t keyframe_id = 0, frame_id = 0;            ///< the new keyframe
  std::uint64_t loop_keyframe_id = 0, loop_frame_id = 0;  ///< the old keyframe it matched
  std::int64_t t_ns = 0, loop_t_ns = 0;                   ///< their frames' times
  /// The new keyframe's pose relative to the old one as the verification
  /// found it (T_cur_w' * T_loop_w^-1, before the correction): what ground
  /// truth can judge.
  geom::SE3d T_cur_loop;
  int inliers = 0;            ///< after the guided search
  double correction_m = 0;    ///< how far the new keyframe moved
  double correction_deg = 0;
  int fused_points = 0;       ///< current-side points replaced or joined by loop-side ones
  int graph_keyframes = 0;    ///< nodes of the essential graph
  int graph_edges = 0;
  double detect_ms = 0;       ///< detection and verification for this keyframe
  double correct_ms = 0;      ///< correction (fusion, pose graph, points)
  /// Of correct_ms, the time with the map locked (tracking waits): all of
  /// it but the essential graph's optimisation.
  double correct_locked_ms = 0;
  double global_ba_ms = 0;    ///< global bundle adjustment afterwards (0 when off)
  int global_ba_outliers = 0; ///< observations it removed
  bool merge = false;         ///< a provisional map merged into the map (correction_m: how far it moved)
};

/// A consistent detection that closed no loop: the candidate that got
/// furthest through the checks, and the check that refused it.
struct LoopRefusal {
  std::uint64_t keyframe_id = 0, loop_keyframe_id = 0;
  std::int64_t t_ns = 0, loop_t_ns = 0;
  /// "matches", "ransac", "inliers" (geometry), "correction" (the hard
  /// caps), "drift" (the drift bound) or "ambiguous" (verified at two places).
  std::string reason;
  bool verified = false;  ///< it passed geometry: T_cur_loop and the correction are its own
  geom::SE3d T_cur_loop;  ///< as LoopEvent's (verified only)
  int inliers = 0;
  double correction_m = 0, correction_deg = 0;
  double drift_bound_m = 0;  ///< the bound a "drift" refusal exceeded
};

/// Running totals (all keyframes).
/// Loop detection's running totals: keyframes through detection and the
/// time it took, cheap to read while a run goes on.
struct LoopDetectTotals {
  std::size_t detections = 0;
  double detect_ms = 0;
};

/// Durations summarised in fixed memory, however many are added: bins of
/// a 16th of an octave (4.4 %) from 0.001 ms to 4.3e6 ms (values beyond
/// fall in the end bins); a quantile is its bin's geometric centre, within
/// 2.2 % of the nearest-rank value.
class DurationHistogram {
 public:
  void add(double ms);
  std::size_t count() const { return count_; }
  double total_ms() const { return total_ms_; }
  /// The q-quantile (0..1) by nearest rank; 0 with no values.
  double quantile(double q) const;

 private:
  static constexpr int kBinsPerOctave = 16, kBins = 32 * kBinsPerOctave;
  static constexpr double kLowestMs = 1e-3;
  std::array<std::uint32_t, kBins> counts_{};
  std::size_t count_ = 0;
  double total_ms_ = 0;
};

struct LoopClosingStats {
  /// Refusals are kept up to this many; later ones are only counted.
  static constexpr std::size_t kMaxRefusals = 5000;
  std::vector<LoopEvent> loops;
  int keyframes = 0;              ///< keyframes examined
  int candidates = 0;             ///< pose candidates that passed the appearance check
  int consistent = 0;             ///< keyframes with a consistent candidate
  int rejected = 0;               ///< consistent detections refused by geometry or the correction bound
  int refused_drift = 0;          ///< of those, verified but implausible against the drift bound
  int refused_ambiguous = 0;      ///< of those, verified at two places apart
  int lookalike_checked = 0;      ///< loops over lookalikeCheckAbove sent to the look-alike check
  int merge_confirmed = 0;        ///< keyframes that confirmed a held-back merge transform
  int merge_unconfirmed = 0;      ///< held-back merge transforms the next keyframe did not confirm (dropped)
  int merge_suggested = 0;        ///< merge transforms held back from a relocalisation (suggest_merge)
  /// Per candidate verified (step 3), the stage that refused it.
  int verified = 0;               ///< candidates verified
  int refused_matches = 0;        ///< fewer than min_matches descriptor matches
  int refused_ransac = 0;         ///< too few EPnP RANSAC / pose-optimisation inliers
  int refused_inliers = 0;        ///< fewer than min_inliers after the guided search
  int refused_correction = 0;     ///< a correction over max_correction_m / max_correction_deg (hard caps)
  /// Of the candidates past RANSAC, those refused on the pose RANSAC gave,
  /// without the guided search: a correction that far beyond the hard cap
  /// or the drift bound (1.5 x the bound + 0.5 m), with no loop in reach.
  int refused_first_pose = 0;
  double verify_ms_total = 0;     ///< the part of detect_ms_total spent in step 3
  double detect_ms_total = 0;     ///< all detection work
  DurationHistogram detect_ms;    ///< detection and verification per keyframe examined
  /// Consistent detections refused, in order, at most kMaxRefusals: past
  /// that, one that passed geometry takes the place of the oldest that did
  /// not (a day's drive refuses thousands of look-alike candidates; the
  /// verified refusals, the dock's among them, are the ones to read).
  std::vector<LoopRefusal> refusals;
  int refusals_dropped = 0;  ///< refused and not in `refusals`
  /// Adds a refusal under the rule above, with `cap` for kMaxRefusals.
  void keep_refusal(LoopRefusal r, std::size_t cap = kMaxRefusals);
};

/// The stats as one JSON object for stats.json / metrics.json:
/// {"loops": n, "events": [{keyframe, frame, loop_keyframe, loop_frame,
/// inliers, correction_m, correction_deg, fused_points, graph_keyframes,
/// graph_edges, detect_ms, correct_ms, correct_locked_ms}], "keyframes", "candidates",
/// "consistent", "rejected", "detect_ms_total"}.
std::string to_json(const LoopClosingStats& stats);

}  // namespace pvb::slam
