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
// With a memory budget the mapper stays within it however long the drive:
// the keyframe clouds and the voxel blocks used longest ago go to a spill
// file (compressed) and come back when a pose update or the robot's return
// needs them; the maps and the PLY files written from them are the same,
// bit for bit, as without a budget.  The PLY writers stream the maps, so
// exporting one never holds it whole.
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
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "pvb/common/closable_queue.hpp"
#include "pvb/common/worker_error.hpp"
#include "pvb/geometry/pinhole.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/slam/dense/point_cloud.hpp"
#include "pvb/slam/dense/reports.hpp"
#include "pvb/slam/dense/spill_file.hpp"
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
  /// Heap bytes the keyframe clouds and the two maps may keep in memory
  /// (a quarter for the clouds, the rest split between the maps); 0: no
  /// bound, nothing is spilled.
  std::size_t memory_budget_bytes = 0;
  std::string spill_dir;  ///< spill files' folder ("": the system's temporary folder)
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

  /// The corrected map, the live map and the corrected map around the first
  /// loop correction written as PLY (write_ply()), streamed a slab at a
  /// time; each returns the points written.  The first-loop writer writes
  /// nothing and returns false when no loop was corrected.  Throws
  /// pvb::IoError when a file cannot be written.
  std::size_t write_corrected_ply(const std::string& path) const;
  std::size_t write_live_ply(const std::string& path) const;
  bool write_first_loop_ply(const std::string& before_path, const std::string& after_path) const;

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
    PointCloud cloud_c;  ///< voxel-filtered, camera frame; empty while out of memory
    std::size_t points = 0;  ///< the cloud's size, in memory or not
    /// Its copy in the spill file, once written: a cloud never changes, so
    /// the copy stays valid when it is read back, and dropping it from
    /// memory again costs no write.
    std::optional<SpillFile::Extent> on_disk;
    bool resident = true;  ///< cloud_c holds the cloud
    std::uint64_t last_use = 0;
  };
  /// A cloud kept in pieces: in memory without a budget, else in the spill file.
  struct StoredCloud {
    std::size_t points = 0;
    std::vector<PointCloud> pieces;
    std::vector<SpillFile::Extent> extents;
  };
  struct Snapshot {
    StoredCloud before, after;
    std::size_t keyframes_moved = 0;
  };
  using Message = std::variant<DenseKeyFrame, PoseUpdate>;
  void run();
  void process(const DenseKeyFrame& kf);
  void apply(const PoseUpdate& update);
  bool moved(const geom::SE3d& from, const geom::SE3d& to, bool exact) const;
  /// The entry's cloud, read back into memory when it was spilled.
  const PointCloud& cloud_of(Entry& e);
  /// The entry's cloud without keeping it in memory.
  PointCloud peek_cloud(const Entry& e) const;
  void enforce_cloud_budget();
  StoredCloud store(const VoxelMap& map);
  void for_each_piece(const StoredCloud& c, const std::function<void(const PointCloud&)>& sink) const;
  std::size_t clouds_budget() const { return options_.memory_budget_bytes / 4; }
  SpillOptions map_spill() const { return {options_.memory_budget_bytes / 8 * 3, options_.spill_dir}; }

  DenseMapperOptions options_;
  mutable std::mutex mutex_;  ///< guards entries_, the maps, the spill file, first_loop_ and stats_
  std::map<std::uint64_t, Entry> entries_;
  std::size_t cloud_bytes_ = 0;  ///< heap bytes of the clouds in memory
  std::uint64_t tick_ = 0;       ///< one per message: an entry's last use
  std::unique_ptr<SpillFile> spill_;  ///< keyframe clouds and the first loop's maps, once spilled
  VoxelMap live_;
  VoxelMap corrected_;
  std::optional<Snapshot> first_loop_;
  DenseMapperStats stats_;
  ClosableQueue<Message> queue_;
  WorkerError worker_error_;  ///< what ended the worker, for the owner's thread
  std::thread worker_;
  bool stopped_ = false;  ///< stop() has closed the queue
};

}  // namespace pvb::slam::dense
