#include "pvb/slam/dense/dense_mapper.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstring>

#include "pvb/common/clock.hpp"
#include "pvb/common/memory.hpp"
#include "pvb/common/threads.hpp"
#include "pvb/slam/dense/ply.hpp"

namespace pvb::slam::dense {

namespace {
constexpr std::size_t kPointBytes = 15;  // x y z as float, r g b

std::string pack(const PointCloud& cloud) {
  std::string s(cloud.size() * kPointBytes, '\0');
  char* p = s.data();
  for (const CloudPoint& q : cloud) {
    std::memcpy(p, &q.x, 4), std::memcpy(p + 4, &q.y, 4), std::memcpy(p + 8, &q.z, 4);
    p[12] = static_cast<char>(q.r), p[13] = static_cast<char>(q.g), p[14] = static_cast<char>(q.b);
    p += kPointBytes;
  }
  return s;
}

PointCloud unpack(const std::string& s) {
  PointCloud cloud(s.size() / kPointBytes);
  const char* p = s.data();
  for (CloudPoint& q : cloud) {
    std::memcpy(&q.x, p, 4), std::memcpy(&q.y, p + 4, 4), std::memcpy(&q.z, p + 8, 4);
    q.r = static_cast<std::uint8_t>(p[12]), q.g = static_cast<std::uint8_t>(p[13]),
    q.b = static_cast<std::uint8_t>(p[14]);
    p += kPointBytes;
  }
  return cloud;
}
}  // namespace

DenseMapper::DenseMapper(const DenseMapperOptions& options)
    : options_(options), live_(options.leaf_m, map_spill()), corrected_(options.leaf_m, map_spill()) {}

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
  e.points = e.cloud_c.size();
  const PointCloud cloud_w = transform(e.cloud_c, e.T_w_c);
  std::lock_guard<std::mutex> lock(mutex_);
  e.last_use = ++tick_;
  auto it = entries_.find(kf.id);
  const bool replaces = it != entries_.end();
  if (replaces) {
    Entry& old = it->second;
    corrected_.remove(transform(cloud_of(old), old.T_w_c_binned));
    cloud_bytes_ -= vector_heap_bytes(old.cloud_c);
    if (old.on_disk) spill_->release(*old.on_disk);
    stats_.points -= old.points;
    --stats_.keyframes;
  }
  corrected_.add(cloud_w);
  stats_.points += e.points;
  ++stats_.keyframes;
  cloud_bytes_ += vector_heap_bytes(e.cloud_c);
  entries_[kf.id] = std::move(e);
  if (replaces) {
    // Rare (a keyframe handed over twice): the live map is rebuilt.
    live_ = VoxelMap(options_.leaf_m, map_spill());
    for (const auto& [id, entry] : entries_) live_.add(transform(peek_cloud(entry), entry.T_w_c));
  } else {
    live_.add(cloud_w);
  }
  enforce_cloud_budget();
  stats_.total_ms += ms_since(t0);
}

const PointCloud& DenseMapper::cloud_of(Entry& e) {
  e.last_use = tick_;
  if (!e.resident) {
    e.cloud_c = unpack(spill_->read(*e.on_disk));
    e.resident = true;
    cloud_bytes_ += vector_heap_bytes(e.cloud_c);
  }
  return e.cloud_c;
}

PointCloud DenseMapper::peek_cloud(const Entry& e) const {
  return e.resident ? e.cloud_c : unpack(spill_->read(*e.on_disk));
}

void DenseMapper::enforce_cloud_budget() {
  if (options_.memory_budget_bytes == 0 || cloud_bytes_ <= clouds_budget()) return;
  std::vector<std::pair<std::uint64_t, Entry*>> by_age;  // last use, entry
  for (auto& [id, e] : entries_)
    if (e.resident && !e.cloud_c.empty()) by_age.emplace_back(e.last_use, &e);
  std::sort(by_age.begin(), by_age.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  if (!spill_) spill_ = std::make_unique<SpillFile>(options_.spill_dir);
  for (const auto& [use, e] : by_age) {
    if (cloud_bytes_ <= clouds_budget() / 8 * 7) break;
    if (!e->on_disk) e->on_disk = spill_->write(pack(e->cloud_c));
    cloud_bytes_ -= vector_heap_bytes(e->cloud_c);
    PointCloud().swap(e->cloud_c);
    e->resident = false;
  }
}

bool DenseMapper::moved(const geom::SE3d& from, const geom::SE3d& to, bool exact) const {
  if (exact) return from.matrix() != to.matrix();
  const geom::SE3d d = from.inverse() * to;
  return d.translation().norm() > options_.update_min_translation_m ||
         Eigen::AngleAxisd(d.linear()).angle() > options_.update_min_rotation_rad;
}

void DenseMapper::apply(const PoseUpdate& update) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++tick_;
  const bool snapshot = update.loop_correction && !first_loop_;
  Snapshot snap;
  if (snapshot) snap.before = store(corrected_);
  const auto t0 = std::chrono::steady_clock::now();
  std::size_t n_moved = 0;
  for (const auto& [id, T_w_c] : update.T_w_c_by_id) {
    auto it = entries_.find(id);
    if (it == entries_.end() || !moved(it->second.T_w_c_binned, T_w_c, update.exact)) continue;
    Entry& e = it->second;
    const PointCloud& cloud_c = cloud_of(e);
    corrected_.remove(transform(cloud_c, e.T_w_c_binned));
    corrected_.add(transform(cloud_c, T_w_c));
    e.T_w_c_binned = T_w_c;
    ++n_moved;
    enforce_cloud_budget();
  }
  const double ms = ms_since(t0);
  ++stats_.pose_updates;
  stats_.keyframes_moved += n_moved;
  stats_.update_ms.push_back(ms);
  if (update.loop_correction) stats_.loop_update_ms.push_back(ms);
  if (snapshot) {
    snap.after = store(corrected_);
    snap.keyframes_moved = n_moved;
    first_loop_ = std::move(snap);
  }
}

DenseMapper::StoredCloud DenseMapper::store(const VoxelMap& map) {
  StoredCloud c;
  map.for_each_slab([&](const PointCloud& slab) {
    c.points += slab.size();
    if (options_.memory_budget_bytes == 0) {
      c.pieces.push_back(slab);
      return;
    }
    if (!spill_) spill_ = std::make_unique<SpillFile>(options_.spill_dir);
    c.extents.push_back(spill_->write(pack(slab)));
  });
  return c;
}

void DenseMapper::for_each_piece(const StoredCloud& c, const std::function<void(const PointCloud&)>& sink) const {
  for (const PointCloud& piece : c.pieces) sink(piece);
  for (const SpillFile::Extent& e : c.extents) sink(unpack(spill_->read(e)));
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
  if (!first_loop_) return std::nullopt;
  LoopSnapshot snap;
  for_each_piece(first_loop_->before, [&](const PointCloud& p) { append(snap.before, p); });
  for_each_piece(first_loop_->after, [&](const PointCloud& p) { append(snap.after, p); });
  snap.keyframes_moved = first_loop_->keyframes_moved;
  return snap;
}

std::size_t DenseMapper::write_corrected_ply(const std::string& path) const {
  std::lock_guard<std::mutex> lock(mutex_);
  write_ply(path, corrected_.voxels(), [&](const auto& sink) { corrected_.for_each_slab(sink); });
  return corrected_.voxels();
}

std::size_t DenseMapper::write_live_ply(const std::string& path) const {
  std::lock_guard<std::mutex> lock(mutex_);
  write_ply(path, live_.voxels(), [&](const auto& sink) { live_.for_each_slab(sink); });
  return live_.voxels();
}

bool DenseMapper::write_first_loop_ply(const std::string& before_path, const std::string& after_path) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!first_loop_) return false;
  write_ply(before_path, first_loop_->before.points,
            [&](const auto& sink) { for_each_piece(first_loop_->before, sink); });
  write_ply(after_path, first_loop_->after.points, [&](const auto& sink) { for_each_piece(first_loop_->after, sink); });
  return true;
}

PointCloud DenseMapper::global_cloud(const std::map<std::uint64_t, geom::SE3d>& T_w_c_by_id) const {
  PointCloud all;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::size_t n = 0;
    for (const auto& [id, e] : entries_) n += e.points;
    all.reserve(n);
    for (const auto& [id, e] : entries_) {
      const auto pose = T_w_c_by_id.find(id);
      append(all, transform(peek_cloud(e), pose != T_w_c_by_id.end() ? pose->second : e.T_w_c));
    }
  }
  return voxel_filter(all, options_.leaf_m);
}

PointCloud DenseMapper::keyframe_cloud(std::uint64_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = entries_.find(id);
  return it == entries_.end() ? PointCloud{} : peek_cloud(it->second);
}

DenseMemory DenseMapper::memory() const {
  std::lock_guard<std::mutex> lock(mutex_);
  DenseMemory m;
  m.keyframes = entries_.size();
  m.keyframe_bytes = map_node_bytes(entries_) + cloud_bytes_;
  m.map_bytes = live_.memory_bytes() + corrected_.memory_bytes();
  if (first_loop_)
    for (const StoredCloud* c : {&first_loop_->before, &first_loop_->after})
      for (const PointCloud& p : c->pieces) m.map_bytes += vector_heap_bytes(p);
  if (spill_) m.spilled_keyframe_bytes = spill_->live_bytes();
  m.spilled_map_bytes = live_.spill_stats().disk_bytes + corrected_.spill_stats().disk_bytes;
  for (const auto& [id, e] : entries_) m.keyframes_spilled += e.resident ? 0 : 1;
  return m;
}

DenseMapperStats DenseMapper::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace pvb::slam::dense
