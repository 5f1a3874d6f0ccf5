#include "pvb/slam/dense/dense_mapper.hpp"

#include <chrono>

#include "pvb/common/threads.hpp"

namespace pvb::slam::dense {

DenseMapper::DenseMapper(const DenseMapperOptions& options) : options_(options) {}

DenseMapper::~DenseMapper() { stop(); }

void DenseMapper::start() {
  if (worker_.joinable() || stopped_) return;
  worker_ = std::thread([this] {
    set_thread_name("pvb-dense");
    run();
  });
}

void DenseMapper::stop() {
  if (!worker_.joinable()) return;
  queue_.close();
  worker_.join();
  stopped_ = true;
}

void DenseMapper::insert(DenseKeyFrame kf) {
  if (worker_.joinable()) {
    queue_.push(std::move(kf));
    return;
  }
  process(kf);  // synchronous mode, or after stop(): on the caller's thread
}

void DenseMapper::run() {
  while (std::optional<DenseKeyFrame> kf = queue_.pop()) process(*kf);
}

void DenseMapper::process(const DenseKeyFrame& kf) {
  const auto t0 = std::chrono::steady_clock::now();
  Entry e;
  e.t_ns = kf.t_ns;
  e.T_w_c = kf.T_w_c;
  e.cloud_c =
      voxel_filter(back_project(kf.rgb, kf.depth_m, options_.K, options_.back_projection), options_.leaf_m);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = entries_.find(kf.id);
  if (it != entries_.end()) {
    stats_.points -= it->second.cloud_c.size();
    --stats_.keyframes;
  }
  stats_.points += e.cloud_c.size();
  ++stats_.keyframes;
  stats_.total_ms += ms;
  entries_[kf.id] = std::move(e);
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

DenseMapperStats DenseMapper::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace pvb::slam::dense
