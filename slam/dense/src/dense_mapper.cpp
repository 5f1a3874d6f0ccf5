#include "pvb/slam/dense/dense_mapper.hpp"

#include <Eigen/Geometry>

#include "pvb/common/clock.hpp"
#include "pvb/common/memory.hpp"
#include "pvb/common/threads.hpp"

namespace pvb::slam::dense {

DenseMapper::DenseMapper(const DenseMapperOptions& options)
    : options_(options), live_(options.leaf_m), corrected_(options.leaf_m) {}

DenseMapper::~DenseMapper() { stop(); }

void DenseMapper::start() {
  if (worker_.joinable() || stopped_) return;
  worker_ = std::thread([this] {
    set_thread_name("pvb-dense");
    if (!worker_error_.run([this] { run(); })) queue_.close();  // later keyframes are refused
  });
}

void DenseMapper::stop() {
  if (!worker_.joinable()) return;
  queue_.close();
  worker_.join();
  stopped_ = true;
}

void DenseMapper::insert(DenseKeyFrame kf) {
  worker_error_.rethrow();
  if (worker_.joinable()) {
    queue_.push(Message(std::move(kf)));
    return;
  }
  process(kf);  // synchronous mode, or after stop(): on the caller's thread
}

void DenseMapper::update_poses(PoseUpdate update) {
  worker_error_.rethrow();
  if (worker_.joinable()) {
    queue_.push(Message(std::move(update)));
    return;
  }
  apply(update);
}

void DenseMapper::run() {
  while (std::optional<Message> m = queue_.pop()) {
    if (const auto* kf = std::get_if<DenseKeyFrame>(&*m)) process(*kf);
    else apply(std::get<PoseUpdate>(*m));
  }
}

void DenseMapper::process(const DenseKeyFrame& kf) {
  const auto t0 = std::chrono::steady_clock::now();
  Entry e;
  e.t_ns = kf.t_ns;
  e.T_w_c = kf.T_w_c;
  e.T_w_c_binned = kf.T_w_c;
  e.cloud_c =
      voxel_filter(back_project(kf.rgb, kf.depth_m, options_.K, options_.back_projection), options_.leaf_m);
  const PointCloud cloud_w = transform(e.cloud_c, e.T_w_c);
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = entries_.find(kf.id);
  const bool replaces = it != entries_.end();
  if (replaces) {
    corrected_.remove(transform(it->second.cloud_c, it->second.T_w_c_binned), it->second.handle);
    stats_.points -= it->second.cloud_c.size();
    --stats_.keyframes;
  }
  e.handle = corrected_.add(cloud_w);
  stats_.points += e.cloud_c.size();
  ++stats_.keyframes;
  entries_[kf.id] = std::move(e);
  if (replaces) {
    // Rare (a keyframe handed over twice): the live map is rebuilt.
    live_ = VoxelMap(options_.leaf_m);
    for (const auto& [id, entry] : entries_) live_.add(transform(entry.cloud_c, entry.T_w_c));
  } else {
    live_.add(cloud_w);
  }
  stats_.total_ms += ms_since(t0);
}

bool DenseMapper::moved(const geom::SE3d& from, const geom::SE3d& to, bool exact) const {
  if (exact) return from.matrix() != to.matrix();
  const geom::SE3d d = from.inverse() * to;
  return d.translation().norm() > options_.update_min_translation_m ||
         Eigen::AngleAxisd(d.linear()).angle() > options_.update_min_rotation_rad;
}

void DenseMapper::apply(const PoseUpdate& update) {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool snapshot = update.loop_correction && !first_loop_;
  LoopSnapshot snap;
  if (snapshot) snap.before = corrected_.cloud();
  const auto t0 = std::chrono::steady_clock::now();
  std::size_t n_moved = 0;
  for (const auto& [id, T_w_c] : update.T_w_c_by_id) {
    auto it = entries_.find(id);
    if (it == entries_.end() || !moved(it->second.T_w_c_binned, T_w_c, update.exact)) continue;
    Entry& e = it->second;
    corrected_.remove(transform(e.cloud_c, e.T_w_c_binned), e.handle);
    e.handle = corrected_.add(transform(e.cloud_c, T_w_c));
    e.T_w_c_binned = T_w_c;
    ++n_moved;
  }
  const double ms = ms_since(t0);
  ++stats_.pose_updates;
  stats_.keyframes_moved += n_moved;
  stats_.update_ms.push_back(ms);
  if (update.loop_correction) stats_.loop_update_ms.push_back(ms);
  if (snapshot) {
    snap.after = corrected_.cloud();
    snap.keyframes_moved = n_moved;
    first_loop_ = std::move(snap);
  }
}

PointCloud DenseMapper::corrected_cloud() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return corrected_.cloud();
}

PointCloud DenseMapper::live_cloud() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return live_.cloud();
}

std::optional<LoopSnapshot> DenseMapper::first_loop() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return first_loop_;
}

PointCloud DenseMapper::global_cloud(const std::map<std::uint64_t, geom::SE3d>& T_w_c_by_id) const {
  PointCloud all;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::size_t n = 0;
    for (const auto& [id, e] : entries_) n += e.cloud_c.size();
    all.reserve(n);
    for (const auto& [id, e] : entries_) {
      const auto pose = T_w_c_by_id.find(id);
      append(all, transform(e.cloud_c, pose != T_w_c_by_id.end() ? pose->second : e.T_w_c));
    }
  }
  return voxel_filter(all, options_.leaf_m);
}

PointCloud DenseMapper::keyframe_cloud(std::uint64_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = entries_.find(id);
  return it == entries_.end() ? PointCloud{} : it->second.cloud_c;
}

DenseMemory DenseMapper::memory() const {
  std::lock_guard<std::mutex> lock(mutex_);
  DenseMemory m;
  m.keyframes = entries_.size();
  m.keyframe_bytes = map_node_bytes(entries_);
  for (const auto& [id, e] : entries_) m.keyframe_bytes += vector_heap_bytes(e.cloud_c) + vector_heap_bytes(e.handle);
  m.map_bytes = live_.memory_bytes() + corrected_.memory_bytes();
  return m;
}

DenseMapperStats DenseMapper::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace pvb::slam::dense
