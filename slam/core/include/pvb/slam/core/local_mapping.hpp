#pragma once
// Local mapping (ORB-SLAM2 LocalMapping): keyframe insertion, culling of
// recent map points, new points by triangulation with neighbours, fusion
// of duplicates, local bundle adjustment and culling of redundant
// keyframes.  Synchronous mode runs each keyframe inline on the caller's
// thread; otherwise a worker thread started with start() takes keyframes
// from a closable blocking queue until stop().
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pvb/common/closable_queue.hpp"
#include "pvb/common/worker_error.hpp"
#include "pvb/slam/core/map.hpp"
#include "pvb/slam/core/options.hpp"
#include "pvb/slam/core/reports.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/features/patch_align.hpp"
#include "pvb/slam/optim/optimizer.hpp"

namespace pvb::slam {

/// Map-point culling rule (ORB-SLAM2 MapPointCulling, RGB-D): returns
/// kErase for a point to remove, kKeep to keep watching, kDone when it has
/// survived its trial period.
enum class CullDecision { kKeep, kErase, kDone };
CullDecision recent_point_rule(double found_ratio, int num_observations, std::uint64_t first_kf_id,
                               std::uint64_t current_kf_id);

/// Keyframe culling rule: a keyframe is redundant when more than `ratio` of
/// its close points (depth in (0, th_depth]) with more than 3 observations
/// are seen by at least `observers` other keyframes at the same or a finer
/// scale.  Exposed for tests.
bool is_redundant_keyframe(const KeyFrame& kf, double th_depth_m, double ratio = 0.9, int observers = 3);

/// After a bundle adjustment: unlinks each outlier edge's point from its
/// keyframe (both directions), as local and global BA do.  `kfs` and `pts`
/// are the keyframes and points behind problem.keyframes / problem.points,
/// index for index.  The caller holds the map mutex.
void erase_outlier_observations(const BaProblem& problem, const std::vector<std::size_t>& outlier_edges,
                                const std::vector<std::shared_ptr<KeyFrame>>& kfs,
                                const std::vector<std::shared_ptr<MapPoint>>& pts);

class LocalMapping {
 public:
  LocalMapping(Map& map, std::shared_ptr<const CameraModel> cam, const LocalMappingOptions& options = {});
  ~LocalMapping();
  LocalMapping(const LocalMapping&) = delete;
  LocalMapping& operator=(const LocalMapping&) = delete;

  /// Work to run on the same thread after each processed keyframe (loop
  /// closing); set before start().
  void set_after_keyframe(std::function<void(const std::shared_ptr<KeyFrame>&)> hook) { after_keyframe_ = std::move(hook); }
  /// The keyframes culled since the last call (for the place database to
  /// forget them); on the mapping thread, as the after-keyframe hook runs.
  std::vector<std::uint64_t> take_culled() { return std::exchange(culled_, {}); }
  /// Where keyframes that leave the local map put their features (none:
  /// they stay on the heap); set before start().
  void set_feature_spill(std::shared_ptr<FeatureSpill> spill) { spill_ = std::move(spill); }

  /// Starts the worker thread (asynchronous mode).
  void start();
  /// Processes the keyframes still queued, then joins the worker.  Never
  /// throws (the destructor calls it): rethrow_error() says how it ended.
  void stop();
  /// Rethrows what the worker thread threw (an exception of OpenCV, Ceres
  /// or Eigen), once; insert() does too.
  void rethrow_error() { worker_error_.rethrow(); }
  bool running() const { return worker_.joinable(); }

  /// Hands a keyframe over: processed now (synchronous) or queued.  A
  /// keyframe queued while the worker runs a local BA stops that BA after
  /// its current iteration (ORB-SLAM2's InsertKeyFrame / InterruptBA): the
  /// estimate reached so far is kept and the second pass is skipped, so the
  /// worker gets to the new keyframe sooner.
  void insert(std::shared_ptr<KeyFrame> kf);
  /// True when no keyframe is waiting or being processed.
  bool idle() const { return pending_.load() == 0; }
  std::size_t queue_size() const { return queue_.size(); }

  /// Processes one keyframe (takes the map lock as needed).
  void process(const std::shared_ptr<KeyFrame>& kf);
  /// Total time spent in process() so far, milliseconds (for profiles).
  double busy_ms() const { return static_cast<double>(busy_us_.load()) / 1000.0; }
  LocalMappingStats stats() const;
  /// True from a keyframe queued in worker mode until the worker clears it
  /// before it decides on its next local BA (exposed for tests).
  bool ba_stop_requested() const { return stop_ba_.load(); }

 private:
  void run();
  void process_new_keyframe(const std::shared_ptr<KeyFrame>& kf);
  void cull_recent_points(const std::shared_ptr<KeyFrame>& kf);
  void create_new_points(const std::shared_ptr<KeyFrame>& kf);
  void fuse_with_neighbors(const std::shared_ptr<KeyFrame>& kf);
  void local_bundle_adjustment(const std::shared_ptr<KeyFrame>& kf);
  void cull_keyframes(const std::shared_ptr<KeyFrame>& kf);
  void leave_local_map(const std::shared_ptr<KeyFrame>& kf);
  // Motion sensors (local_mapping_inertial.cpp)
  /// Estimates gravity, velocities and biases from the keyframes so far,
  /// once there are enough of them (MapGravity::ready).
  void initialize_inertial(const std::shared_ptr<KeyFrame>& kf);
  /// Adds the inertial, wheel and tilt terms of the keyframes in `problem`
  /// (kfs index for index); keyframes the chain needs are appended fixed.
  void add_motion_terms(BaProblem* problem, std::vector<std::shared_ptr<KeyFrame>>* kfs);
  /// Writes the optimised velocities and biases back.
  void write_motion_states(const BaProblem& problem, const std::vector<std::shared_ptr<KeyFrame>>& kfs);
  /// Culling kf keeps the IMU chain's intervals short enough.
  bool may_cull_in_time(const KeyFrame& kf) const;
  /// Fits the wheels' calibration to one more keyframe interval, the one
  /// that ends kWheelLag keyframes before kf (its poses have been through
  /// several local BAs), and publishes the fit in the map.
  void calibrate_wheels(const std::shared_ptr<KeyFrame>& kf);
  static constexpr int kWheelLag = 5;

  Map& map_;
  std::shared_ptr<const CameraModel> cam_;
  LocalMappingOptions options_;
  std::list<std::shared_ptr<MapPoint>> recent_points_;  ///< points on trial
  std::deque<std::weak_ptr<KeyFrame>> in_window_;  ///< keyframes with a pyramid or features not yet spilled, oldest first
  std::shared_ptr<FeatureSpill> spill_;
  int spilled_since_release_ = 0;
  ClosableQueue<std::shared_ptr<KeyFrame>> queue_;
  std::atomic<int> pending_{0};  ///< keyframes inserted and not yet processed
  std::atomic<std::int64_t> busy_us_{0};  ///< time in process(), microseconds
  std::atomic<std::int64_t> ba_us_{0};    ///< of which in the local BAs' solver
  /// Between start() and the end of stop(); set before the worker exists,
  /// so the worker may read it too (insert() from a hook, its local BA).
  bool on_worker_ = false;
  std::mutex stop_mutex_;                 ///< insert(): push + raise; worker: clear + look at the queue
  std::atomic<bool> stop_ba_{false};      ///< set by insert() in worker mode, cleared before each local BA
  std::atomic<std::int64_t> processed_{0}, ba_runs_{0}, ba_stopped_{0};
  std::function<void(const std::shared_ptr<KeyFrame>&)> after_keyframe_;
  std::vector<std::uint64_t> culled_;  ///< culled since take_culled()
  std::optional<WheelCalibrator> wheel_calibrator_;  ///< with the wheels and Robot.CalibrateWheels
  std::uint64_t wheels_fitted_to_ = 0;               ///< the last interval's end keyframe
  bool wheels_resumed_ = false;                      ///< a loaded map's fit taken over (or none to take)
  WorkerError worker_error_;  ///< what ended the worker, for the owner's thread
  std::thread worker_;
};

}  // namespace pvb::slam
