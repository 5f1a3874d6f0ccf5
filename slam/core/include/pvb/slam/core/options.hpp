#pragma once
// The options of the core's parts: tracking, local mapping, loop closing
// and the System facade.  System fills the first two from the settings
// file (settings.hpp), whose LoopClosing.* section is LoopClosingOptions
// itself; its caller gives SystemOptions.  Tests set them directly.
#include <cstdint>

#include "pvb/slam/core/sensor_settings.hpp"
#include "pvb/slam/features/patch_align.hpp"
#include "pvb/slam/optim/optimizer.hpp"
#include "pvb/slam/pematch/pe_match.hpp"

namespace pvb::slam {

/// A start from two views (two_view_start.hpp): what it asks of them.
struct TwoViewOptions {
  int min_points = 100;            ///< triangulated points that every check keeps
  double min_parallax_deg = 1.0;   ///< median angle between a point's two rays
  int min_scale_points = 5;        ///< of them, measured depths in either view
  double max_scale_spread = 0.15;  ///< median absolute deviation of the depth ratios, over their median
  double search_radius_px = 100;   ///< where a first-view keypoint is looked for in the second
  double max_reprojection_px = 2.0;  ///< in both views, at the keypoint's octave
};

struct TrackingOptions {
  bool use_pe_match = true;    ///< false: ORB-SLAM2 baseline motion model
  PeMatchParams pe_match = PeMatchParams::for_slam();
  /// Beyond the paper: skip PE-match when the predicted translation moves
  /// the matched points by less than its own inlier threshold (median over
  /// the matches with depth).  There the epipole is not determined by the
  /// matches (the motion is a homography within the noise), so an F from
  /// eight of them says little about the others.  Off by default: on
  /// fast_turns it changed neither the turn-frame errors nor the ATE
  /// (docs/experiments/2026-11-21-pe-match-on-fast-turns.md).
  bool pe_skip_low_parallax = false;
  double motion_th = 7.0;      ///< ORB-SLAM2 window for stereo / RGB-D, x scale of the octave
  double motion_ratio = 0.9;   ///< paper sec. 3 step 1
  int min_init_points = 500;   ///< keypoints with depth needed to initialise
  /// Tracking.twoViewStart: with fewer, start from two views whose points
  /// are triangulated and scaled by the few measured depths
  /// (two_view_start.hpp); false: wait for a frame with enough depth.
  bool two_view_start = true;
  TwoViewOptions two_view;
  int max_frames = 30;         ///< keyframe spacing limit (= fps)
  int min_frames = 0;
  int kf_min_tracked_close = 200;    ///< KeyFrame.minTrackedClose (ORB-SLAM2: 100)
  int kf_min_untracked_close = 70;   ///< KeyFrame.minUntrackedClose
  double kf_ref_overlap = 0.0;       ///< KeyFrame.refOverlap (0: ORB-SLAM2's 75 % rule)
  /// The local map's keyframes that observe the frame's points: at most
  /// this many, those sharing the most points (ties: the newer).  ORB-SLAM2
  /// takes every one, and along a plant aisle the points at the rows'
  /// vanishing end are seen by hundreds of keyframes, so its local map
  /// grows with the aisle.  0: every one.
  int max_observing_keyframes = 60;
  int max_local_keyframes = 80;  ///< with their covisibles, children and parents (ORB-SLAM2: 80)
  /// Beyond ORB-SLAM2: before the local-map pose optimisation, move each
  /// map-point match to where the point's reference-keyframe patch,
  /// warped by the predicted pose, aligns (needs Frame::pyramid; frames
  /// without one are not aligned).  docs/slam.md, "Patch alignment".
  bool align_patches = true;
  PatchAlignParams patch_align;
  /// Relocalisation against look-alike places: every candidate is tried,
  /// and when two match at camera positions more than this apart the frame
  /// stays lost (LoopClosing.ambiguityCheck / ambiguityDistance).
  bool reloc_ambiguity_check = true;
  double reloc_ambiguity_distance_m = 0.3;
  /// Tracking.relocLookalikes: with the ambiguity check, a relocalisation
  /// is also tried against this many best-scoring keyframes one by one
  /// (not grouped), and refused when one of them matches at another place;
  /// 0 turns it off.
  int reloc_lookalikes = 10;
  /// Tracking.newMapAfter: in a loaded map that is being extended, after
  /// this many frames lost in a row a provisional map begins at the next
  /// frame (the robot started or went outside the map); loop closing
  /// merges it into the map when it finds the map.  0: never.
  int new_map_after_lost = 30;
  /// Tracking.mergeRelocEvery: while tracking in a provisional map, every
  /// this many frames tracked the frame is also relocalised among the
  /// loaded map's keyframes alone (with the look-alike checks); a success
  /// is a merge hypothesis for loop closing (take_merge_hint).  0: never.
  int merge_reloc_every = 5;
  /// With an IMU whose state is trusted: how long, and how far, the motion
  /// sensors may carry the pose while vision fails before tracking
  /// declares itself lost and relocalises globally.
  double blind_max_s = 5.0;
  double blind_max_m = 3.0;
  /// A blind stretch is a kidnap (lost at once) when the IMU says the robot
  /// rose more than this (a ground robot does not), or with wheels when
  /// the IMU's and the wheels' positions part by more than kidnap_disagree_m.
  double kidnap_lift_m = 0.15;
  double kidnap_disagree_m = 0.25;
  /// The parting allowed grows by 0.5 a t^2 over t seconds blind: the
  /// IMU's double integration drifts with the residual accelerometer bias
  /// a (m/s^2), most in a turn.
  double kidnap_disagree_accel_mps2 = 0.05;
  /// With the wheels and a trusted IMU, while lost: the motion sensors
  /// carry a pose on from the last one, and a relocalisation farther from
  /// it than reloc_odometry_floor_m + reloc_odometry_rate x the distance
  /// carried is refused (the wheels say the robot cannot be there).  The
  /// bound is lifted when the IMU shows the robot lifted (a carry) within
  /// reloc_odometry_lift_window_s of the loss, and after
  /// reloc_odometry_max_s lost.  reloc_odometry_rate 0: off.
  double reloc_odometry_floor_m = 0.5;
  double reloc_odometry_rate = 0.1;
  double reloc_odometry_lift_window_s = 6.0;
  double reloc_odometry_max_s = 120.0;
  /// Under that bound, after this many frames lost in a row without a
  /// relocalisation, tracking begins again at the carried pose: a new
  /// keyframe with points from the frame's depth, chained in time to the
  /// last one (Tracking.carriedRestartAfter; 0: never).  A lost robot
  /// among look-alike rows keeps a pose whose error is the wheels'
  /// instead of waiting for a place it may never see again; loop closing
  /// joins the new points to the old when the robot comes back.
  int carried_restart_after = 15;
  /// Search radius (px at level 0) for the local map's points in the
  /// first frame after a blind stretch, around the dead-reckoned pose.
  double after_blind_radius_px = 12.0;
};

struct LocalMappingOptions {
  int covisible_for_triangulation = 10;  ///< neighbours searched for new points (RGB-D: 10)
  double redundant_ratio = 0.9;          ///< keyframe culling: share of points seen by >= 3 others
  int redundant_observers = 3;
  bool local_ba = true;
  /// Before local BA, align the observations of the new keyframe and its
  /// covisible keyframes not yet aligned (those that fusion and
  /// triangulation added) to their points' reference patches
  /// (patch_refine.hpp); the tracker aligns the rest.
  bool align_patches = true;
  PatchAlignParams patch_align;
  /// A keyframe's grey pyramid (about 1 MB at 640 x 480) is kept while it
  /// is in the local map, that is among the newest `pyramid_window`
  /// keyframes or covisible with the newest; then it is released, and its
  /// points are no longer aligned to its patches (leave_local_map).  Its
  /// features go to the feature spill then, when there is one.
  int pyramid_window = 10;
  /// The spill's pages are written out and dropped from memory after this
  /// many keyframes have gone into it.
  int spill_release_every = 32;
  /// Local BA iterations and gates; its abort_flag is local mapping's own
  /// (set on the worker thread only), whatever is given here.
  BaOptions ba;
  /// The motion sensors fused (inertial initialisation, inertial and wheel
  /// terms in local BA; docs/slam_inertial.md).
  MotionSensorSettings motion;
  /// Inertial initialisation: keyframes in the chain and seconds it spans.
  int init_min_keyframes = 10;
  double init_min_span_s = 3.0;
  /// A keyframe is not culled when its neighbours in time would be this
  /// far apart (their IMU interval would grow too long).
  double max_inertial_gap_s = 3.0;
  /// Zero-mean priors of the initialisation on the biases (an IMU's
  /// turn-on biases: BMI088's datasheet gives 1 deg/s and 20 mg per axis).
  double init_gyro_bias_sigma_radps = 0.02;
  double init_accel_bias_sigma_mps2 = 0.3;
  /// Noise of vision's keyframe poses in the initialisation, which holds
  /// them fixed (about a keyframe pair's RPE over the square root of two
  /// on the shipped scenes).
  double init_pose_sigma_m = 0.002;
  double init_pose_sigma_rad = 0.0005;
  /// Local BA refines gravity's direction under a prior of this standard
  /// deviation about the last estimate (0: gravity held after initialisation).
  double gravity_sigma_rad = 0.005;
};

/// LoopClosing.* settings (docs/slam.md, "Loop closing").
struct LoopClosingOptions {
  bool enabled = true;             ///< LoopClosing.enabled (0/1)
  double search_radius_m = 3.0;    ///< LoopClosing.searchRadius: camera centre distance, metres
  double max_angle_deg = 30.0;     ///< LoopClosing.maxAngle: angle between the optical axes
  int min_keyframe_gap = 30;       ///< LoopClosing.minKeyFrameGap: candidate this many keyframe ids older
  int max_candidates = 5;          ///< LoopClosing.maxCandidates: closest first
  int min_matches = 20;            ///< LoopClosing.minMatches: appearance check, descriptor matches
  int consistency = 2;             ///< LoopClosing.consistency: consecutive consistent detections needed
  int min_inliers = 40;            ///< LoopClosing.minInliers: after the guided search
  double max_correction_m = 20;    ///< LoopClosing.maxCorrection: larger corrections are refused, metres
  /// LoopClosing.lookalikeCheckAbove: a loop correcting the keyframe by more
  /// than this (metres) is closed only if the keyframe, verified against the
  /// map's best-scoring keyframes one by one, verifies at no other place
  /// (the ambiguity check); 10000 turns the look-alike check off.
  double lookalike_check_above_m = 0.5;
  double max_correction_deg = 10;  ///< LoopClosing.maxCorrectionAngle, degrees
  /// LoopClosing.maxCorrectionAnglePerKm: the angle cap grows by this much
  /// a kilometre of path driven between the two keyframes (as estimated),
  /// as the drift bound does: heading drifts with distance (12° on a 2 km
  /// day route with camera, IMU and wheels).  0: a fixed cap.
  double max_correction_deg_per_km = 5;
  int essential_weight = 100;      ///< LoopClosing.essentialWeight: covisibility edges in the essential graph
  int keyframes_between_loops = 10;  ///< no detection for this many keyframes after a loop (ORB-SLAM2: 10)
  double rotation_weight = 1.0;    ///< LoopClosing.rotationWeight: pose-graph rotation rows (rad) against translation (m)
  bool global_ba = false;          ///< LoopClosing.globalBA (0/1): bundle adjustment of the whole map after a loop
  /// LoopClosing.poseProximity (0/1): candidates by pose proximity (step 1
  /// above) instead of the bag of words.  Off by default: it cannot find a
  /// loop after a drift larger than searchRadius.
  bool pose_proximity = false;
  /// Beyond ORB-SLAM2, against look-alike places (docs/place_recognition.md):
  /// LoopClosing.maxDriftRate / driftFloor: a correction moving the camera
  /// centre further than driftFloor + maxDriftRate x the path driven between
  /// the two keyframes (as estimated) + the swing of the correction's own
  /// turn about the keyframe's scene (2 sin(angle / 2) x its median depth)
  /// is implausible and refused; 0 turns the check off.
  double max_drift_rate = 0.01;
  double drift_floor_m = 0.05;
  /// LoopClosing.ambiguityCheck (0/1) / ambiguityDistance: when two
  /// candidates verify at camera positions more than ambiguityDistance
  /// apart, the place is ambiguous (a repeated structure) and the loop is refused.
  bool ambiguity_check = true;
  double ambiguity_distance_m = 0.3;
  /// LoopClosing.ambiguityInlierShare: a look-alike (checked for a large
  /// correction or a merge) that verifies is a rival place only with at
  /// least this share of the best verified candidate's inliers; 0: every
  /// one is.  Consistent candidates are always rivals.
  double ambiguity_inlier_share = 0.5;
  /// LoopClosing.mergeConfirmations: keyframes of a provisional map in a
  /// row (the first match included) verified at the pose the merge
  /// transform predicts before the maps are merged.
  int merge_confirmations = 3;
};

struct SystemOptions {
  bool synchronous = false;    ///< no worker threads: bit-identical runs
  std::uint32_t seed = 1;      ///< PE-match seed (and any other randomness)
};

}  // namespace pvb::slam
