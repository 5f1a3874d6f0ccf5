#pragma once
// The PE-SLAM RGB-D system: ORB extraction and tracking on the caller's
// thread, local mapping and dense point-cloud mapping inline (synchronous
// mode) or on worker threads.  The parts are only declared here: their
// headers (tracking.hpp, local_mapping.hpp, loop_closing.hpp, map.hpp,
// dense_mapper.hpp) are for code that works with them directly.
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pvb/geometry/se3.hpp"
#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/sensor/rgbd_frame.hpp"
#include "pvb/slam/core/feature_spill.hpp"
#include "pvb/slam/core/keyframe_motion.hpp"
#include "pvb/slam/core/map_settings.hpp"
#include "pvb/slam/core/map_snapshot.hpp"
#include "pvb/slam/core/options.hpp"
#include "pvb/slam/core/reports.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/dense/point_cloud.hpp"
#include "pvb/slam/dense/reports.hpp"

namespace pvb::slam {

struct CameraModel;
class KeyFrame;
class LocalMapping;
class LoopClosing;
class Map;
class OrbExtractor;
class PlaceRecognizer;
class Tracking;
namespace dense {
class DenseMapper;
}  // namespace dense

/// How a run starts from a saved map (System::load_map).
enum class MapStart {
  kLocalise,  ///< the map is fixed: tracked against, never changed
  kExtend,    ///< new keyframes join it; its own keyframes stay where they are
};

/// A loaded map: what the file held, and how long it took.
struct MapLoadInfo {
  std::uint32_t sessions = 0;  ///< mapping sessions in the file
  std::size_t keyframes = 0, points = 0, bytes = 0;
  std::string app_json;        ///< the application's data saved with it
  double load_ms = 0;          ///< reading, checking, linking and bags of words
  /// The wheels' calibration saved with the map: taken over (this run
  /// reads its encoders with it and goes on fitting), or why not ("" when
  /// the map holds none).
  bool wheel_fit_taken = false;
  std::string wheel_fit_note;
};

struct MapSaveInfo {
  std::uint32_t sessions = 0;
  std::size_t keyframes = 0, points = 0, bytes = 0;
  /// Keyframes of provisional maps never merged into the map: not saved
  /// (they lie in frames of their own).
  std::size_t unmerged_keyframes = 0;
  double save_ms = 0;          ///< encoding and the atomic write
};

/// What track() reports for one frame.
struct FrameResult {
  std::int64_t t_ns = 0;
  TrackingState state = TrackingState::kNotInitialized;
  std::optional<geom::SE3d> T_w_c;  ///< when state == kOk, in the map's frame
  /// Tracked in a provisional map not merged yet (extending a loaded map,
  /// begun while lost): its pose in the map's frame is not known, so
  /// T_w_c is empty although state == kOk.
  bool provisional = false;
  /// Gravity in the map's frame as the core held it for this frame, once
  /// the inertial state is trusted (empty before, and without an IMU).
  std::optional<Eigen::Vector3d> g_w;
  TrackingStats tracking;
  double tracking_ms = 0;           ///< extraction + tracking (not inline mapping)
  double orb_ms = 0;                ///< of which ORB extraction
  double mapping_ms = 0;            ///< inline local mapping (synchronous mode)
  int num_features = 0;
  int features_with_depth = 0;      ///< keypoints whose depth the frame gives
  double depth_valid = 0;           ///< the depth image's share of pixels with depth
};

/// What the system holds, by part (docs/slam.md, "Keyframe memory").
struct SystemMemory {
  MapMemory map;                       ///< keyframes and points in the map
  /// Keyframes culled from the map but kept for the trajectory (their
  /// poses follow their spanning-tree parents), and what they hold.
  std::size_t culled_keyframes = 0;
  KeyFrameMemory culled_bytes;
  std::size_t place_database_bytes = 0;  ///< the keyframes' bags of words (0 without a vocabulary)
  std::size_t place_database_words = 0;     ///< words with a list in it
  std::size_t place_database_postings = 0;  ///< (keyframe, word) entries
  dense::DenseMemory dense;            ///< empty when dense mapping is off
  /// Far keyframes' features in the feature file (Map.spillFeatures), and
  /// how much of it is in memory now (in the process or the page cache).
  FeatureSpillStats feature_spill;
  std::size_t feature_spill_resident_bytes = 0;
};
/// {"keyframes": .., "keyframe_bytes": {"pyramid": .., ...}, ...} for stats.json.
std::string to_json(const SystemMemory& m);

class System {
 public:
  System(const Settings& settings, const SystemOptions& options);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  /// Starts from the map saved at `path` (map_file.hpp), before the first
  /// frame: tracking is lost until it relocalises in it, and poses are in
  /// its frame.  A map made with other camera or ORB settings, or another
  /// vocabulary, is refused (ConfigError); a bad file throws IoError.
  MapLoadInfo load_map(const std::string& path, MapStart start);
  /// Saves the map (after shutdown(): the final one) atomically, with the
  /// caller's JSON; a map that was loaded to localise in is refused.
  MapSaveInfo save_map(const std::string& path, const std::string& app_json);
  /// The settings a map of this system records (and a loaded one must match).
  MapSettings map_settings() const;

  FrameResult track(const sensor::RgbdFrame& frame);
  /// Lets local and dense mapping finish their queues and stops the workers;
  /// then rethrows what a worker thread threw, if one did (track() rethrows
  /// it at the next keyframe handed over).
  void shutdown();

  /// Every tracked frame's pose recomputed from its reference keyframe's
  /// current (bundle-adjusted) pose, as ORB-SLAM2 saves its trajectory
  /// (frames of a provisional map never merged are left out).
  std::vector<geom::StampedPose> refined_trajectory();
  /// Poses of the keyframes still in the map, by id (T_w_c; not those of a
  /// provisional map never merged), every session's: this session's
  /// stamps plus session_clock_offset_ns(), as the saved map has them.
  std::vector<geom::StampedPose> keyframe_trajectory();
  /// What this session's time stamps gain in the map's clock, so that the
  /// stamps of a multi-session map are unique: 0, unless the session began
  /// from a saved map whose last keyframe is not before its first frame;
  /// then the whole seconds that put that frame at least one second after
  /// it (docs/map_file.md).  Set by the first frame tracked.
  std::int64_t session_clock_offset_ns() const { return session_offset_ns_; }
  /// This session's first frame, in its own clock; nullopt before one.
  std::optional<std::int64_t> session_first_t_ns() const { return session_first_t_ns_; }
  std::size_t num_keyframes();
  std::size_t num_map_points();
  /// The sparse map with every measurement (map_snapshot.hpp), under the
  /// map lock; call after shutdown() for the final map.
  MapSnapshot map_snapshot();
  /// Positions of the map points (world frame), by point id.
  std::vector<Eigen::Vector3d> map_point_positions();
  /// Every map point with the number of frames that matched it so far
  /// (ORB-SLAM2's mnFound): the difference over a session says which
  /// landmarks that session used.
  struct LandmarkUse {
    std::uint64_t id = 0;
    Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
    int found = 0;
  };
  std::vector<LandmarkUse> landmark_uses();
  /// Keyframes processed, local BAs started (and cut short) and the time
  /// spent so far (inline or on its worker).
  LocalMappingStats mapping_stats() const;
  TrackingState state() const;
  /// Loops closed so far and detection totals (empty when LoopClosing.enabled is 0).
  LoopClosingStats loop_stats() const;
  /// Loop detection's running totals (zero when loop closing is off).
  LoopDetectTotals loop_detect_totals() const;
  bool loop_closing_enabled() const { return loop_ != nullptr; }
  /// What the map, the culled keyframes and the dense mapper hold now (call
  /// from the thread that calls track(); after shutdown() for the final figures).
  SystemMemory memory();
  /// Gravity in the map's frame and when the inertial state became
  /// trusted (MapGravity::ready false: not yet, or a camera-only setup).
  MapGravity gravity();
  /// The wheels' online calibration so far (as described without wheels).
  WheelFit wheels();
  /// The sensors this system fuses.
  sensor::SensorSetup sensors() const { return settings_.motion.setup; }
  /// The wheels are fused and calibrated online (Robot.CalibrateWheels).
  bool calibrates_wheels() const {
    return sensor::uses_wheels(settings_.motion.setup) && settings_.motion.robot.wheel_calibration.enabled;
  }
  /// Each keyframe in the map with an inertial state: its time, velocity
  /// and biases (for reports against the true biases).
  struct KeyFrameState {
    std::uint64_t id = 0;
    std::int64_t t_ns = 0;
    Eigen::Vector3d v_w_mps = Eigen::Vector3d::Zero();
    ImuBias bias;
  };
  std::vector<KeyFrameState> keyframe_states();
  /// Every relocalisation so far (call from the thread that calls track()).
  const std::vector<RelocEvent>& relocalisations() const;

  // Dense point-cloud mapping (Settings::dense; off: the functions below
  // return empty results) ----------------------------------------------------
  bool dense_enabled() const { return dense_ != nullptr; }
  /// The corrected map: every keyframe the dense mapper has processed at
  /// its current (bundle-adjusted, loop-corrected) pose, culled keyframes at
  /// their pose through the spanning tree.  Posts the current poses first
  /// (every change re-binned); call after shutdown() for the complete map.
  dense::PointCloud point_cloud();
  /// The live map: each keyframe at the pose it was made with.
  dense::PointCloud live_point_cloud() const;
  /// The corrected map just before and after the first loop correction
  /// (PointCloudMapping.Reassemble 1 and a loop closed).
  std::optional<dense::LoopSnapshot> dense_first_loop() const;
  /// Keyframes processed, points and time spent (empty when disabled).
  dense::DenseMapperStats dense_stats() const;
  /// The same maps written as PLY, streamed (never held whole in memory):
  /// the corrected map (posting the current poses first, as point_cloud()),
  /// the live map, and the corrected map around the first loop (false and
  /// nothing written when there was none).  The first two return the points
  /// written (0 when disabled).  Throw pvb::IoError when a file cannot be
  /// written.
  std::size_t write_point_cloud(const std::string& path);
  std::size_t write_live_point_cloud(const std::string& path) const;
  bool write_dense_first_loop(const std::string& before_path, const std::string& after_path) const;

 private:
  Settings settings_;
  SystemOptions options_;
  std::shared_ptr<const CameraModel> cam_;
  std::unique_ptr<OrbExtractor> extractor_;
  /// Far keyframes' features (Map.spillFeatures); before the map, so it
  /// is destroyed after every keyframe.
  std::shared_ptr<FeatureSpill> feature_spill_;
  std::unique_ptr<Map> map_;
  std::unique_ptr<PlaceRecognizer> place_;  ///< null with Vocabulary.path none
  std::uint64_t vocabulary_fingerprint_ = 0;
  std::optional<MapStart> map_start_;       ///< set when the run started from a saved map
  std::uint32_t loaded_sessions_ = 0;
  std::optional<std::int64_t> loaded_last_t_ns_;  ///< the loaded map's last keyframe stamp
  std::optional<std::int64_t> session_first_t_ns_;
  std::int64_t session_offset_ns_ = 0;  ///< session_clock_offset_ns()
  /// Sets the session's first frame and its clock's offset (once).
  void start_session_clock(std::int64_t t_ns);
  /// Keeps a loaded map's wheel fit when this run's wheels are those it
  /// was fitted to and calibrated, else drops it; says which in *info.
  void take_wheel_fit(MapLoadInfo* info);
  std::unique_ptr<Tracking> tracking_;
  std::unique_ptr<LoopClosing> loop_;  ///< null when loop closing is disabled; runs on the mapping thread
  std::unique_ptr<LocalMapping> mapping_;
  std::unique_ptr<dense::DenseMapper> dense_;  ///< null when dense mapping is disabled
  /// Keyframes handed to the dense mapper, by id (for their current poses);
  /// written by track(), read by the mapping thread.
  std::map<std::uint64_t, std::shared_ptr<KeyFrame>> dense_keyframes_;
  std::mutex dense_keyframes_mutex_;
  /// Hands every dense keyframe's current pose to the dense mapper.
  void post_dense_poses(bool loop_correction, bool exact);
  std::uint64_t next_frame_id_ = 0;
  /// Per tracked frame: time, reference keyframe and T_c_r (for refined_trajectory()).
  struct FrameRecord {
    std::int64_t t_ns;
    std::shared_ptr<KeyFrame> ref;
    geom::SE3d T_c_r;
  };
  std::vector<FrameRecord> records_;
};

}  // namespace pvb::slam
