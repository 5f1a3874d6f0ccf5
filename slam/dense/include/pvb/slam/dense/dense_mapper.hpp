#pragma once
// PE-SLAM's dense point-cloud mapping thread (paper sec. 3, "DENSE POINT
// CLOUD MAPPING"): every new keyframe's RGB-D image is back-projected,
// voxel-filtered and kept in its own camera frame.  Two maps are kept:
//
//   live       each keyframe cloud at the pose it was made with, never moved
//              (the paper's map: "not corrected after back-end optimisation")
//   corrected  a VoxelMap that follows the poses: after each local BA and
//              loop correction the caller posts the keyframes' current poses
//              (update_poses()); every keyframe that moved by more than a
//              threshold leaves the map at its old pose and re-enters at its
//              new one, so an update costs in proportion to what moved.
//
// Knows nothing of the tracker: keyframes come in as images plus a pose.
//
// Threads: start() runs a worker that takes keyframes and pose updates, in
// the order posted, from a closable blocking queue; stop() closes the queue, lets the worker finish what is
// queued and joins it.  Without start() (synchronous mode) insert()
// processes the keyframe (update_poses() the update) inline, so runs are
// bit-identical.  Either way the same messages are applied in the same order
// by the same code, so the maps after stop() are the same in both modes.
#include <cstdint>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <thread>
#include <variant>
#include <vector>

#include "pvb/common/closable_queue.hpp"
#include "pvb/common/worker_error.hpp"
#include "pvb/geometry/pinhole.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/slam/dense/point_cloud.hpp"
#include "pvb/slam/dense/reports.hpp"
#include "pvb/slam/dense/voxel_map.hpp"

namespace pvb::slam::dense {

/// What the mapper needs of a keyframe.  The images must not be written to
/// after insert() (clone them when the source reuses its buffers).
struct DenseKeyFrame {
  std::uint64_t id = 0;                       ///< keyframe id (unique, orders the global cloud)
  std::int64_t t_ns = 0;                      ///< capture time
  cv::Mat rgb;                                ///< CV_8UC3 R, G, B (or CV_8UC1 grey)
  cv::Mat depth_m;                            ///< CV_32FC1 metres, 0 = invalid
  geom::SE3d T_w_c = geom::SE3d::Identity();  ///< pose when the keyframe was made
};

struct DenseMapperOptions {
  geom::PinholeIntrinsics K;  ///< camera of the depth (registered) images
  BackProjectionParams back_projection;
  double leaf_m = 0.02;  ///< voxel size of the keyframe and global clouds
  /// A keyframe is re-binned when its pose moved by more than either bound
  /// since it was last binned (1 mm; 0.25 mrad is 1 mm at 4 m range).
  double update_min_translation_m = 0.001;
  double update_min_rotation_rad = 0.00025;
};

/// The keyframes' current poses, posted after bundle adjustment or a loop
/// correction.  Ids the mapper does not know are ignored.
struct PoseUpdate {
  std::map<std::uint64_t, geom::SE3d> T_w_c_by_id;
  bool loop_correction = false;  ///< the first one keeps the map before and after it
  bool exact = false;            ///< re-bin every keyframe whose pose changed at all
};

class DenseMapper {
 public:
  explicit DenseMapper(const DenseMapperOptions& options);
  /// Stops the worker (processing what is queued) if it runs.
  ~DenseMapper();
  DenseMapper(const DenseMapper&) = delete;
  DenseMapper& operator=(const DenseMapper&) = delete;

  /// Starts the worker thread (asynchronous mode).  Does nothing when it
  /// runs already or after stop() (the queue stays closed).
  void start();
  /// Closes the queue, processes the keyframes still in it and joins the
  /// worker.  Later insert() calls are processed inline.  Never throws
  /// (the destructor calls it): rethrow_error() says how it ended.
  void stop();
  /// Rethrows what the worker thread threw, once; insert() and
  /// update_poses() do too.
  void rethrow_error() { worker_error_.rethrow(); }
  bool running() const { return worker_.joinable(); }

  /// Hands a keyframe over: queued for the worker, or processed now when no
  /// worker runs.  A second keyframe with the same id replaces the first.
  void insert(DenseKeyFrame kf);
  /// Hands new keyframe poses over (queued behind the keyframes already
  /// handed over, or applied now when no worker runs).
  void update_poses(PoseUpdate update);

  /// The corrected map (world frame) as the updates so far left it.
  PointCloud corrected_cloud() const;
  /// Every keyframe cloud at the pose it was inserted with, voxel-filtered.
  PointCloud live_cloud() const;
  /// The corrected map around the first loop correction, if there was one.
  std::optional<LoopSnapshot> first_loop() const;

  /// Built from scratch: each keyframe cloud moved by T_w_c_by_id[id] when
  /// present, else by the pose it was inserted with; concatenated in id
  /// order and voxel-filtered.  Keyframes still queued are not included.
  PointCloud global_cloud(const std::map<std::uint64_t, geom::SE3d>& T_w_c_by_id = {}) const;

  /// The cloud of keyframe `id` in its camera frame (empty when unknown).
  PointCloud keyframe_cloud(std::uint64_t id) const;
  DenseMapperStats stats() const;
  /// What the mapper holds now (not counting keyframes still queued).
  DenseMemory memory() const;
  const DenseMapperOptions& options() const { return options_; }

 private:
  struct Entry {
    std::int64_t t_ns = 0;
    geom::SE3d T_w_c = geom::SE3d::Identity();   ///< pose at insertion (the live map's)
    geom::SE3d T_w_c_binned = geom::SE3d::Identity();  ///< pose it has in the corrected map
    PointCloud cloud_c;  ///< voxel-filtered, camera frame
    VoxelMap::Handle handle;  ///< its voxels in the corrected map
  };
  using Message = std::variant<DenseKeyFrame, PoseUpdate>;
  void run();
  void process(const DenseKeyFrame& kf);
  void apply(const PoseUpdate& update);
  bool moved(const geom::SE3d& from, const geom::SE3d& to, bool exact) const;

  DenseMapperOptions options_;
  mutable std::mutex mutex_;  ///< guards entries_, the maps, first_loop_ and stats_
  std::map<std::uint64_t, Entry> entries_;
  VoxelMap live_;
  VoxelMap corrected_;
  std::optional<LoopSnapshot> first_loop_;
  DenseMapperStats stats_;
  ClosableQueue<Message> queue_;
  WorkerError worker_error_;  ///< what ended the worker, for the owner's thread
  std::thread worker_;
  bool stopped_ = false;  ///< stop() has closed the queue
};

}  // namespace pvb::slam::dense
