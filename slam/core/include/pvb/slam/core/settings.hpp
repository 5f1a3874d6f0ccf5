#pragma once
// SLAM settings: ORB-SLAM2 RGB-D YAML files read unchanged (Camera.*,
// ThDepth, DepthMapFactor, ORBextractor.*) plus optional PEMatch.*,
// PointCloudMapping.* and LoopClosing.* sections.  A missing required key is a pvb::ConfigError naming it; an
// unknown key is a warning (returned, not printed: the app prints it).
#include <string>
#include <vector>

#include "pvb/geometry/pinhole.hpp"
#include "pvb/slam/core/options.hpp"
#include "pvb/slam/core/sensor_settings.hpp"
#include "pvb/slam/features/orb_extractor.hpp"

namespace pvb::slam {

/// KeyFrame.* section (optional): the close-point rule of the keyframe
/// decision, which ORB-SLAM2 hard-codes at 100 / 70.
struct KeyFrameSettings {
  /// KeyFrame.minTrackedClose: a keyframe is needed when fewer close points
  /// than this are tracked (and more than minUntrackedClose are not).
  /// ORB-SLAM2: 100. Default 200: with a Kinect-range sensor every depth
  /// point is close, and at 100 a forward drive waits until tracking is down
  /// to about 100 inliers before each keyframe
  /// (docs/experiments/2026-11-21-keyframe-spacing-and-drift.md).
  int min_tracked_close = 200;
  int min_untracked_close = 70;  ///< KeyFrame.minUntrackedClose (ORB-SLAM2: 70)
  /// KeyFrame.refOverlap, in (0, 1); 0 (the default) keeps ORB-SLAM2's rule.
  /// When set, the "tracking has fallen below 75 % of the reference
  /// keyframe's points with three observations" test becomes "this frame
  /// tracks fewer than refOverlap of the reference keyframe's map points".
  /// ORB-SLAM2's count depends on how often keyframes were made before,
  /// which makes the decision bistable; this one depends on the view
  /// overlap only (docs/slam.md, "A keyframe rule on view overlap").
  double ref_overlap = 0.0;
};

/// PEMatch.* section; defaults are the paper's SLAM values (sec. 5.2.2).
struct PeMatchSettings {
  bool enabled = true;             ///< PEMatch.enabled (0/1): off = ORB-SLAM2 baseline motion model
  int population = 20;             ///< PEMatch.population: particles
  int num_fitness_samples = 50;    ///< PEMatch.j: matches scored per fitness evaluation
  int stall_iterations = 6;        ///< PEMatch.stallIterations: stop after this many without improvement
  // Defaults below differ from the paper's (eq. 8 point-line distance, 3 px,
  // no refinement): scored against ground truth on the motion model's coarse
  // matches of the simulated sequences (bench/pematch_tracking_eval,
  // docs/experiments/2026-11-21-pe-match-in-tracking.md),
  // Sampson 2 px + refinement discards half as many correct matches for the
  // same share of wrong ones removed.
  double threshold_px = 2.0;       ///< PEMatch.threshold: epipolar distance threshold, pixels
  bool sampson = true;             ///< PEMatch.sampson (0/1): 1 = Sampson distance, 0 = eq. 8 point-line distance
  bool refine = true;              ///< PEMatch.refine (0/1): IRLS refinement of gbest's F
  /// PEMatch.skipLowParallax (0/1): skip PE-match on frames whose predicted
  /// translation moves the matches by less than the threshold (an
  /// experiment; it did not help on fast_turns,
  /// docs/experiments/2026-11-21-pe-match-on-fast-turns.md).
  bool skip_low_parallax = false;
};

/// PointCloudMapping.* section: the dense point-cloud mapping thread (paper
/// sec. 3).  The paper gives no values; these follow the ORB-SLAM2
/// point-cloud forks (every 3rd pixel) with a 2 cm voxel and a depth limit
/// where the Kinect's depth noise is still below about 3 cm.
struct PointCloudMappingSettings {
  bool enabled = true;         ///< PointCloudMapping.Enabled (0/1)
  double resolution_m = 0.02;  ///< PointCloudMapping.Resolution: voxel leaf size, metres
  int stride_px = 3;           ///< PointCloudMapping.Stride: every n-th pixel in rows and columns
  double min_depth_m = 0.1;    ///< PointCloudMapping.MinDepth, metres
  double max_depth_m = 4.0;    ///< PointCloudMapping.MaxDepth, metres
  /// PointCloudMapping.Reassemble (0/1): the map follows local BA and loop
  /// corrections as they happen (0: only when the final map is asked for).
  bool reassemble = true;
  /// PointCloudMapping.MemoryBudget: megabytes the keyframe clouds and the
  /// voxel maps may keep in memory; past it the least recently used go to a
  /// spill file in the temporary folder ($TMPDIR) and come back when needed
  /// (0: no bound).
  double memory_budget_mb = 512;
};

/// The default vocabulary, trained by the build (docs/place_recognition.md).
inline constexpr const char* kDefaultVocabularyPath = PVB_DEFAULT_VOCABULARY;

/// Everything the SLAM system reads from its settings file.
struct Settings {
  std::string source;               ///< file it came from
  geom::PinholeIntrinsics K;        ///< Camera.fx/fy/cx/cy/width/height
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;  ///< OpenCV radial-tangential distortion
  double fps = 30.0;                ///< Camera.fps
  double bf = 40.0;                 ///< Camera.bf: virtual baseline (m) x fx (pixels)
  bool rgb_order = true;            ///< Camera.RGB: true = colour images are R,G,B
  double th_depth = 40.0;           ///< ThDepth: close/far threshold in baselines
  double depth_map_factor = 5000.0; ///< DepthMapFactor: raw depth units per metre
  OrbParams orb;                    ///< ORBextractor.*
  /// Tracking.alignPatches (0/1, ours, optional): align map-point matches
  /// to their reference keyframe's patch before the local-map pose
  /// optimisation (TrackingOptions::align_patches).
  bool align_patches = true;
  /// Map.spillFeatures (0/1, ours, optional): a keyframe that leaves the
  /// local map puts its keypoints, descriptors, depths and grid into a file
  /// in the temporary folder ($TMPDIR), read back where it is used again
  /// (FeatureSpill).  Values and results are the same either way.
  bool spill_features = true;
  /// Tracking.relocLookalikes (ours, optional): best-scoring keyframes a
  /// relocalisation is also checked against (TrackingOptions::reloc_lookalikes).
  int reloc_lookalikes = 10;
  /// Tracking.maxObservingKeyFrames (ours, optional): the local map's
  /// keyframes that observe the frame's points, those sharing the most
  /// (TrackingOptions::max_observing_keyframes); 0: every one (ORB-SLAM2).
  int max_observing_keyframes = 60;
  /// Tracking.twoViewStart (ours, optional): a start from two views when a
  /// frame has too little depth (TrackingOptions::two_view_start).
  bool two_view_start = true;
  /// Tracking.newMapAfter (ours, optional): frames lost in a row after
  /// which an extending run begins a provisional map
  /// (TrackingOptions::new_map_after_lost); 0: never.
  int new_map_after_lost = 30;
  /// Tracking.mergeRelocEvery (ours, optional): while in a provisional
  /// map, frames between tries to relocalise in the loaded map
  /// (TrackingOptions::merge_reloc_every); 0: never.
  int merge_reloc_every = 5;
  /// Tracking.relocOdometryFloor and Tracking.relocOdometryRate (ours,
  /// optional): while lost with the wheels, a relocalisation farther from
  /// the pose they carried than floor + rate x the distance is refused
  /// (TrackingOptions::reloc_odometry_*); rate 0: off.
  double reloc_odometry_floor_m = 0.5;
  double reloc_odometry_rate = 0.1;
  /// Tracking.carriedRestartAfter (ours, optional): lost frames under that
  /// bound after which tracking begins again at the carried pose
  /// (TrackingOptions::carried_restart_after); 0: never.
  int carried_restart_after = 15;
  PeMatchSettings pe_match;         ///< PEMatch.* (optional section)
  KeyFrameSettings keyframe;        ///< KeyFrame.* (optional section)
  PointCloudMappingSettings dense;  ///< PointCloudMapping.* (optional section)
  LoopClosingOptions loop;          ///< LoopClosing.* (optional section)
  /// Vocabulary.path (ours, optional): the place-recognition vocabulary
  /// (our binary format or ORB-SLAM2's ORBvoc.txt); relative to the
  /// settings file's folder; "none" for none (pose-proximity loops and
  /// relocalisation against recent keyframes only).  Absent: the default,
  /// kDefaultVocabularyPath.
  std::string vocabulary_path = kDefaultVocabularyPath;
  /// System.Sensors, IMU.* and Robot.* (ours and ORB-SLAM3's, optional).
  MotionSensorSettings motion;
  std::vector<std::string> warnings;  ///< unknown keys and similar, one line each

  /// Close/far depth threshold in metres (ORB-SLAM2: bf * ThDepth / fx).
  double th_depth_m() const { return bf * th_depth / K.fx; }
  /// True when any distortion coefficient is non-zero.
  bool has_distortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }
};

/// Reads an ORB-SLAM2 RGB-D settings file.  Throws IoError when the file
/// cannot be opened or parsed (with the line and OpenCV's reason for a
/// syntax error) and ConfigError naming the first missing or invalid key and
/// the range it accepts.  Every key is range-checked here, so that the
/// values the SLAM code sees are safe: intrinsics finite and positive with
/// cx, cy inside Camera.width x height, distortion within +-100,
/// ORBextractor.nLevels small enough that the coarsest pyramid level keeps
/// 8 px, nFeatures at most 100000, FAST thresholds in [1, 255], and bounded
/// counts and distances in the optional sections.
Settings read_settings(const std::string& path);

/// The same from settings text held in memory (a run's own camera.yaml
/// before it is written); `name` stands for the file in messages and is
/// the folder a relative Vocabulary.path is taken from.
Settings read_settings_text(const std::string& text, const std::string& name);

}  // namespace pvb::slam
