#pragma once
// The PE-SLAM RGB-D system: ORB extraction and tracking on the caller's
// thread, local mapping inline (synchronous mode) or on a worker thread.
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/sensor/rgbd_frame.hpp"
#include "pvb/slam/core/local_mapping.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/tracking.hpp"

namespace pvb::slam {

struct SystemOptions {
  bool synchronous = false;    ///< no worker threads: bit-identical runs
  std::uint32_t seed = 1;      ///< PE-match seed (and any other randomness)
};

/// What track() reports for one frame.
struct FrameResult {
  std::int64_t t_ns = 0;
  TrackingState state = TrackingState::kNotInitialized;
  std::optional<geom::SE3d> T_w_c;  ///< when state == kOk
  TrackingStats tracking;
  double tracking_ms = 0;           ///< extraction + tracking (not inline mapping)
  double orb_ms = 0;                ///< of which ORB extraction
  double mapping_ms = 0;            ///< inline local mapping (synchronous mode)
  int num_features = 0;
};

class System {
 public:
  System(const Settings& settings, const SystemOptions& options);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  FrameResult track(const sensor::RgbdFrame& frame);
  /// Lets local mapping finish its queue and stops the worker.
  void shutdown();

  /// Every tracked frame's pose recomputed from its reference keyframe's
  /// current (bundle-adjusted) pose, as ORB-SLAM2 saves its trajectory.
  std::vector<geom::StampedPose> refined_trajectory();
  /// Poses of the keyframes still in the map, by id (T_w_c).
  std::vector<geom::StampedPose> keyframe_trajectory();
  std::size_t num_keyframes();
  std::size_t num_map_points();
  /// Time local mapping has spent on keyframes so far (inline or on its worker), ms.
  double mapping_busy_ms() const { return mapping_->busy_ms(); }
  TrackingState state() const { return tracking_->state(); }

 private:
  Settings settings_;
  SystemOptions options_;
  std::shared_ptr<const CameraModel> cam_;
  OrbExtractor extractor_;
  Map map_;
  std::unique_ptr<Tracking> tracking_;
  std::unique_ptr<LocalMapping> mapping_;
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
