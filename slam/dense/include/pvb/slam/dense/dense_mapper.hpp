#pragma once
// PE-SLAM's dense point-cloud mapping thread (paper sec. 3, "DENSE POINT
// CLOUD MAPPING"): every new keyframe's RGB-D image is back-projected,
// voxel-filtered and kept in its own camera frame.  The global coloured
// cloud is built on request from the keyframe clouds and the keyframe poses
// the caller passes in (the latest, bundle-adjusted ones), then voxel-
// filtered again.  Knows nothing of the tracker: keyframes come in as
// images plus a pose.
//
// Threads: start() runs a worker that takes keyframes from a closable
// blocking queue; stop() closes the queue, lets the worker finish what is
// queued and joins it.  Without start() (synchronous mode) insert()
// processes the keyframe inline, so runs are bit-identical.  Either way the
// per-keyframe clouds are computed by the same code from the same input, so
// the cloud after stop() is the same in both modes.
#include <cstdint>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <thread>

#include "pvb/common/closable_queue.hpp"
#include "pvb/geometry/pinhole.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/slam/dense/point_cloud.hpp"

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
};

/// Figures for reports.
struct DenseMapperStats {
  std::size_t keyframes = 0;  ///< keyframes processed
  std::size_t points = 0;     ///< points over all keyframe clouds (before the global filter)
  double total_ms = 0;        ///< back-projection + voxel filter, summed over keyframes
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
  /// worker.  Later insert() calls are processed inline.
  void stop();
  bool running() const { return worker_.joinable(); }

  /// Hands a keyframe over: queued for the worker, or processed now when no
  /// worker runs.  A second keyframe with the same id replaces the first.
  void insert(DenseKeyFrame kf);

  /// The global cloud in the world frame: each keyframe cloud moved by
  /// T_w_c_by_id[id] when present, else by the pose it was inserted with;
  /// concatenated in id order and voxel-filtered.  Keyframes still queued
  /// are not included (call stop() first for the complete cloud).
  PointCloud global_cloud(const std::map<std::uint64_t, geom::SE3d>& T_w_c_by_id = {}) const;

  /// The cloud of keyframe `id` in its camera frame (empty when unknown).
  PointCloud keyframe_cloud(std::uint64_t id) const;
  DenseMapperStats stats() const;
  const DenseMapperOptions& options() const { return options_; }

 private:
  struct Entry {
    std::int64_t t_ns = 0;
    geom::SE3d T_w_c = geom::SE3d::Identity();
    PointCloud cloud_c;  ///< voxel-filtered, camera frame
  };
  void run();
  void process(const DenseKeyFrame& kf);

  DenseMapperOptions options_;
  mutable std::mutex mutex_;  ///< guards entries_ and stats_
  std::map<std::uint64_t, Entry> entries_;
  DenseMapperStats stats_;
  ClosableQueue<DenseKeyFrame> queue_;
  std::thread worker_;
  bool stopped_ = false;  ///< stop() has closed the queue
};

}  // namespace pvb::slam::dense
