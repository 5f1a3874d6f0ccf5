#pragma once
// Tracking (ORB-SLAM2 Tracking for RGB-D) with PE-match in the motion model
// (paper sec. 3).  Runs on the caller's thread; takes Map::mutex() while it
// reads or writes the map.  Loss of tracking is a state, never an error.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "pvb/slam/core/map.hpp"
#include "pvb/slam/core/matcher.hpp"
#include "pvb/slam/core/motion_integrator.hpp"
#include "pvb/slam/core/options.hpp"
#include "pvb/slam/core/place_recognition.hpp"
#include "pvb/slam/core/reports.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/two_view_start.hpp"
#include "pvb/slam/pematch/pe_match.hpp"

namespace pvb::slam {

/// A provisional map's frame in the map's own, from one frame tracked in
/// the provisional map and relocalised in the map (a merge hypothesis,
/// LoopClosing::suggest_merge).
struct MergeHint {
  std::uint32_t from = 0;            ///< the provisional map
  geom::SE3d T_into_from;            ///< its frame into the map's own
  std::shared_ptr<KeyFrame> anchor;  ///< the map's keyframe the relocalisation matched
};

/// Of the keyframes observing a frame's points, given as (points shared,
/// keyframe id), the pair of the last one kept when at most n are kept:
/// those sharing the most first, the newer on ties.  A keyframe is kept
/// when its pair is not less.  (0, 0), which keeps every one, when n <= 0
/// or no more than n are given.
std::pair<int, std::uint64_t> least_shared_kept(std::vector<std::pair<int, std::uint64_t>> shared, int n);

/// "Already seen in this pass" marks for map-point ids: a pass stamp per
/// id, so a new pass is O(1) and a look-up an array access (map-point ids
/// are dense from 0).  Ids from kDenseLimit up (visual-odometry points)
/// go to a small ordered set.  Scratch state of an algorithm, never stored
/// on the points (ORB-SLAM2's mnTrackReferenceForFrame).
class IdMarks {
 public:
  /// Starts a pass: nothing is marked.
  void new_pass();
  /// Marks id; true when it was not marked yet in this pass.
  bool mark(std::uint64_t id);
  bool marked(std::uint64_t id) const;

 private:
  static constexpr std::uint64_t kDenseLimit = std::uint64_t(1) << 32;
  std::vector<std::uint32_t> stamp_;  ///< pass in which each dense id was last marked
  std::uint32_t pass_ = 0;
  std::set<std::uint64_t> sparse_;    ///< ids >= kDenseLimit marked in this pass
};

class Tracking {
 public:
  /// `place` (may be null) gives relocalisation candidates anywhere in the map.
  Tracking(Map& map, std::shared_ptr<const CameraModel> cam, const TrackingOptions& options,
           const PlaceRecognizer* place = nullptr);

  /// Fuses the motion sensors of `sensors` (checked; none for a camera-only
  /// setup); before the first frame.
  void use_motion_sensors(const MotionSensorSettings& sensors);
  /// The readings that came with the next frame (before track()).
  void add_motion(std::int64_t t_ns, const std::vector<sensor::ImuSample>& imu,
                  const std::vector<sensor::WheelTicks>& ticks);
  /// The motion sensors' state (null for a camera-only setup).
  const MotionIntegrator* motion() const { return motion_.get(); }

  /// Tracks one frame (features extracted).  `mapping_idle` and
  /// `mapping_queue` describe the local mapper for the keyframe decision.
  /// Returns the new keyframe when one was created (for the local mapper).
  std::shared_ptr<KeyFrame> track(Frame frame, bool mapping_idle, std::size_t mapping_queue);

  /// Starts in a loaded map: lost until a global relocalisation finds the
  /// first pose in it.  `localise_only`: the map stays as it is, no
  /// keyframe is ever made (localisation mode); otherwise a long loss
  /// begins a provisional map (TrackingOptions::new_map_after_lost).
  /// Before the first frame.
  void start_in_map(bool localise_only);
  bool localise_only() const { return localise_only_; }

  TrackingState state() const { return state_; }
  const TrackingStats& stats() const { return stats_; }
  /// Pose of the last frame tracked (valid when state() == kOk).
  const Frame& last_frame() const { return last_; }
  /// Every relocalisation so far, in order.
  const std::vector<RelocEvent>& relocalisations() const { return relocs_; }
  /// Reference keyframe of the last frame tracked.
  std::shared_ptr<KeyFrame> reference_keyframe() const { return ref_kf_; }
  /// The merge hypothesis found since the last call, if any
  /// (TrackingOptions::merge_reloc_every).
  std::optional<MergeHint> take_merge_hint() { return std::exchange(merge_hint_, std::nullopt); }
  /// The first of the two keyframes a two-view start made, once, for local
  /// mapping to take before the keyframe track() returned (null otherwise).
  std::shared_ptr<KeyFrame> take_start_keyframe() { return std::exchange(start_kf_, nullptr); }

 private:
  /// Not initialised: begins the map at f when it can (the first keyframe
  /// made, returned; null otherwise).
  std::shared_ptr<KeyFrame> start_map(Frame& f);
  /// f's pose by the way the state allows (after a blind stretch; motion
  /// model, else reference keyframe; relocalisation when lost), before the
  /// local map; stats_.method says which succeeded.
  bool track_by_state(Frame& f);
  /// f tracked: the velocity, its map points cleaned, and the keyframe
  /// decision; returns the new keyframe (or null).
  std::shared_ptr<KeyFrame> after_tracked(Frame& f, bool mapping_idle, std::size_t mapping_queue);
  bool initialize(Frame& f);
  /// Without enough depth in one frame: the start from a first view kept
  /// and f (TwoViewOptions); `why` is the one-frame start's reason.
  bool start_from_two_views(Frame& f, const std::string& why);
  /// The two keyframes and the points of a two-view start.
  void build_two_view_map(Frame& f, const TwoViewStart& s);
  bool track_with_motion_model(Frame& f);
  /// Median translational parallax of the motion-model matches m (last
  /// keypoint with depth) under the predicted motion T_cur_last; +inf with
  /// fewer than 8 such matches.
  double translation_parallax_px(const std::vector<IndexMatch>& m, const geom::SE3d& T_cur_last) const;
  bool track_reference_keyframe(Frame& f);

  // Relocalisation (relocalisation.cpp) -------------------------------------------
  bool relocalize(Frame& f);
  /// Global relocalisation of f among the keyframes of map `only_map` (of
  /// any map without one), with the ambiguity and look-alike checks:
  /// empty with f at its pose, *kf the keyframe matched and *candidates
  /// the candidates tried, or why it failed (f's matches cleared) with
  /// the step in *kind (when given).
  std::string relocalise_in(Frame& f, std::optional<std::uint32_t> only_map, std::shared_ptr<KeyFrame>* kf,
                            int* candidates, TrackingStats::RelocFailure* kind = nullptr);
  /// While tracking in a provisional map: relocalises a copy of f in the
  /// loaded map every merge_reloc_every frames; a success is kept as
  /// merge_hint_.
  void probe_merge(const Frame& f);
  /// Relocalisation candidates without a vocabulary.
  std::vector<std::shared_ptr<KeyFrame>> recent_keyframes() const;
  /// Matches f against kf (through the direct index when f_features is
  /// given), PnP RANSAC and pose optimisation; returns the pose inliers
  /// (0 when a step failed) and the descriptor matches in *matches.
  /// *pnp (when given) receives PnP RANSAC's inliers (0 when not run).
  int relocalize_against(Frame& f, const KeyFrame& kf, const place::FeatureVector* f_features, int* matches,
                         int* pnp = nullptr);
  /// After a relocalisation to `found`: why it is ambiguous against the
  /// best-scoring keyframes not among `tried` (and the best covisibles of
  /// those at another place), or empty.
  std::string lookalike(const Frame& f, const Frame& found, const place::BowVector& bow,
                        const place::FeatureVector& f_features, const std::vector<std::shared_ptr<KeyFrame>>& tried,
                        std::optional<std::uint32_t> only_map);
  static constexpr std::size_t kMaxRelocCandidates = 20;
  /// Pose inliers a relocalisation candidate needs (ORB-SLAM2: 50).
  static constexpr int kRelocMinInliers = 50;
  /// Covisibles tried for a look-alike keyframe at another place that does
  /// not match itself.
  static constexpr int kLookalikeNeighbours = 5;
  /// Appends the RelocEvent of f, just relocalised and tracked.
  void record_relocalisation(const Frame& f);

  bool track_local_map(Frame& f);
  /// Patch alignment of f's map-point matches at its current pose.
  void align_matches(Frame& f);
  void update_last_frame();
  void update_local_map(const Frame& f);
  /// ORB-SLAM2's keyframe decision; also fills stats_.kf_* with its inputs.
  bool need_new_keyframe(const Frame& f, bool mapping_idle, std::size_t mapping_queue);
  std::shared_ptr<KeyFrame> create_keyframe(Frame& f);
  /// A keyframe of `f` in the map the reference keyframe belongs to (a
  /// provisional one, or the map's own), chained to the last keyframe by
  /// the motion readings since.
  std::shared_ptr<KeyFrame> add_keyframe_in_own_map(const Frame& f);
  /// A new map point at keypoint i of f, from its depth, observed by kf (made from f).
  void add_point_from_depth(Frame& f, const std::shared_ptr<KeyFrame>& kf, std::size_t i);
  void discard_outliers(Frame& f, int* map_matches);
  void replace_in_last_frame();
  /// Appends one step's failure to stats_.failure; returns false.
  bool fail(const std::string& why);

  // Motion sensors (motion_tracking.cpp) ------------------------------------------
  /// The IMU's state is trusted: predictions and dead reckoning may use it.
  bool inertial_ready() const;
  /// A setup with an accelerometer whose readings have not come yet or
  /// are not quiet (for at most kAccelWaitNs after the first frame): the
  /// map waits for them, to begin level.  Returns what it waits for ("the
  /// accelerometer's first readings", or a quiet accelerometer with the
  /// figures that are not), or nullopt when the map may begin.
  std::optional<std::string> waiting_for_accelerometer(const Frame& f);
  static constexpr std::int64_t kAccelWaitNs = 1'000'000'000;
  static constexpr double kQuietMps2 = 0.5;  ///< spread and departure from g of a quiet accelerometer
  std::optional<std::int64_t> first_frame_t_ns_;
  /// The first frame's pose: levelled by the accelerometer (z against
  /// gravity, the camera's heading kept) when the setup has one.
  geom::SE3d first_pose() const;
  /// The pose the motion sensors predict for f from the last frame.
  geom::SE3d predicted_pose(Eigen::Vector3d* v_w) const;
  /// After a frame is tracked or dead-reckoned: the last frame's IMU
  /// velocity, and the bias the readings are integrated at.
  void update_motion_state(const Frame& f, bool tracked);
  /// Links kf in time after the previous keyframe and hands it the
  /// readings since, and its inertial state when known.
  void attach_motion(const std::shared_ptr<KeyFrame>& kf);
  /// Vision failed on f: carries the pose by the motion sensors when it
  /// may (true), or says why not.
  bool dead_reckon(Frame& f);
  /// The first frames after a blind stretch: the local map's points
  /// searched around the dead-reckoned pose, then the local map tracked.
  bool track_after_blind(Frame& f);

  std::unique_ptr<MotionIntegrator> motion_;  ///< null: camera only
  Eigen::Vector3d v_last_ = Eigen::Vector3d::Zero();  ///< the IMU's velocity at the last frame
  bool v_last_known_ = false;
  std::shared_ptr<KeyFrame> last_kf_;         ///< the newest keyframe in time (the chain's end)
  /// The IMU's position integrated alone from where vision was lost (the
  /// prediction may follow the wheels): it rises when the robot is carried.
  struct ImuAlone {
    std::int64_t start_t_ns = 0;
    Eigen::Vector3d p_start_w = Eigen::Vector3d::Zero();
    Eigen::Vector3d p_w = Eigen::Vector3d::Zero(), v_w = Eigen::Vector3d::Zero();
    /// One frame's readings, the base turned by R_w_b (lost_odometry.cpp).
    void carry(const MotionIntegrator& motion, const Eigen::Vector3d& g_w, const Eigen::Matrix3d& R_w_b);
    double rise_m(const Eigen::Vector3d& g_w) const { return (p_w - p_start_w).dot(-g_w.normalized()); }
  };
  /// The blind stretch so far: the distance carried and the IMU alone
  /// (kidnap check).
  struct Blind {
    double distance_m = 0;
    ImuAlone imu;
  };
  std::optional<Blind> blind_;
  /// While lost (lost_odometry.cpp): the pose the wheels and the gyro carry
  /// on from the last one, and what bounds a relocalisation by it.
  struct LostOdometry {
    geom::SE3d T_c_w;                                   ///< the carried camera pose
    Eigen::Vector3d v_w = Eigen::Vector3d::Zero();      ///< the IMU's velocity (wheels)
    double distance_m = 0;                              ///< carried so far
    ImuAlone imu;                                       ///< from where vision was lost
    bool lifted = false;  ///< the IMU rose kidnap_lift_m: carried, no bound
  };
  std::optional<LostOdometry> lost_odom_;
  /// The frame being tracked is lost after a tracked or dead-reckoned one
  /// (last_): the carried pose begins at last_'s and takes this frame's
  /// readings (with the wheels and a trusted IMU; none otherwise).
  void begin_lost_odometry();
  /// The next lost frame's readings, before it is relocalised.
  void carry_lost_odometry(const Frame& f);
  /// How far from the carried pose a relocalisation may be (+inf: no bound).
  double lost_odometry_bound_m(const Frame& f) const;
  /// Why the motion sensors refuse the relocalised pose of f, or empty.
  std::string odometry_refuses(const Frame& f, const Frame& found) const;
  /// Lost for carried_restart_after frames under the wheels' bound, with
  /// enough depth: f becomes a keyframe at the carried pose (returned;
  /// null when not due).
  std::shared_ptr<KeyFrame> restart_at_carried_pose(Frame& f);

  Map& map_;
  std::shared_ptr<const CameraModel> cam_;
  TrackingOptions options_;
  PeMatcher pe_matcher_;
  const PlaceRecognizer* place_ = nullptr;
  TrackingState state_ = TrackingState::kNotInitialized;
  TrackingStats stats_;
  bool localise_only_ = false;
  bool may_begin_map_ = false;     ///< extending a loaded map: a long loss begins a provisional map
  int lost_in_row_ = 0;            ///< frames lost since the last one tracked
  std::uint32_t provisional_ = 0;  ///< the provisional map the next initialisation begins (0: none)
  int since_merge_probe_ = 0;      ///< frames tracked in a provisional map since the last probe_merge
  std::optional<MergeHint> merge_hint_;
  std::optional<Frame> start_ref_;      ///< a two-view start's first view, at its levelled pose
  std::shared_ptr<KeyFrame> start_kf_;  ///< its keyframe, until System takes it

  Frame last_;
  bool last_is_keyframe_ = false;
  std::optional<geom::SE3d> velocity_;          ///< T_c_w(k) * T_c_w(k-1)^-1
  std::shared_ptr<KeyFrame> ref_kf_;
  geom::SE3d T_last_ref_ = geom::SE3d::Identity();  ///< last frame relative to its reference keyframe
  std::uint64_t last_kf_frame_id_ = 0;
  std::uint64_t last_reloc_frame_id_ = 0;
  std::shared_ptr<KeyFrame> reloc_kf_;  ///< the keyframe the last relocalize() matched
  int reloc_candidates_ = 0;
  std::vector<RelocEvent> relocs_;
  int matches_inliers_ = 0;
  std::uint64_t next_temp_point_id_ = std::uint64_t(1) << 62;  ///< ids of visual-odometry points (not in the map)

  // Local map (scratch state of this algorithm, rebuilt per frame)
  std::vector<std::shared_ptr<KeyFrame>> local_kfs_;
  std::vector<std::shared_ptr<MapPoint>> local_points_;
  IdMarks local_marks_;  ///< points already in local_points_ (update_local_map)
  IdMarks frame_marks_;  ///< points already matched in the frame (track_local_map)
};

}  // namespace pvb::slam
