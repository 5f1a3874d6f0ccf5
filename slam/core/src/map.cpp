#include "pvb/slam/core/map.hpp"

#include <algorithm>
#include <climits>
#include <stdexcept>

#include "pvb/common/memory.hpp"

namespace pvb::slam {

// MapPoint ------------------------------------------------------------------

MapPoint::MapPoint(std::uint64_t id, const Eigen::Vector3d& p_w, const std::shared_ptr<KeyFrame>& ref_kf)
    : id_(id), p_w_(p_w), ref_kf_(ref_kf), first_kf_id_(ref_kf ? ref_kf->id() : 0) {}

std::shared_ptr<MapPoint> MapPoint::replaced() const {
  std::shared_ptr<MapPoint> r = replaced_;
  while (r && r->replaced_) r = r->replaced_;
  return r;
}

MapPoint::Observations::const_iterator MapPoint::Observations::find(std::uint64_t kf_id) const {
  const auto it = std::lower_bound(list_.begin(), list_.end(), kf_id,
                                   [](const value_type& o, std::uint64_t id) { return o.first < id; });
  return it != list_.end() && it->first == kf_id ? it : list_.end();
}

bool MapPoint::Observations::insert(std::uint64_t kf_id, Obs o) {
  const auto it = std::lower_bound(list_.begin(), list_.end(), kf_id,
                                   [](const value_type& v, std::uint64_t id) { return v.first < id; });
  if (it != list_.end() && it->first == kf_id) return false;
  list_.insert(it, value_type(kf_id, std::move(o)));
  return true;
}

bool MapPoint::Observations::erase(std::uint64_t kf_id) {
  const auto it = find(kf_id);
  if (it == list_.end()) return false;
  list_.erase(it);
  return true;
}

std::size_t MapPoint::Observations::heap_bytes() const { return vector_heap_bytes(list_); }

void MapPoint::add_observation(const std::shared_ptr<KeyFrame>& kf, std::size_t idx) {
  const Frame& f = kf->frame();
  const Obs o{kf, static_cast<std::uint32_t>(idx), static_cast<std::int16_t>(f.keys_un[idx].octave),
              f.u_right[idx] >= 0};
  if (!obs_.insert(kf->id(), o)) return;
  num_obs_ += o.stereo ? 2 : 1;
}

void MapPoint::erase_observation(std::uint64_t kf_id) {
  auto it = obs_.find(kf_id);
  if (it == obs_.end()) return;
  num_obs_ -= !it->second.kf.expired() && it->second.stereo ? 2 : 1;
  obs_.erase(it);
  if (ref_kf_.expired() || (ref_kf_.lock() && ref_kf_.lock()->id() == kf_id)) {
    ref_kf_.reset();
    for (const auto& [id, o] : obs_)
      if (auto k = o.kf.lock()) {
        ref_kf_ = k;
        break;
      }
  }
  if (num_obs_ <= 2) set_bad();
}

long MapPoint::index_in(std::uint64_t kf_id) const {
  auto it = obs_.find(kf_id);
  return it == obs_.end() ? -1 : static_cast<long>(it->second.idx);
}

void MapPoint::set_bad() {
  if (bad_) return;
  bad_ = true;
  for (const auto& [id, o] : obs_)
    if (auto kf = o.kf.lock())
      if (kf->map_points()[o.idx].get() == this) kf->set_map_point(o.idx, nullptr);
  obs_.clear();
  num_obs_ = 0;
}

void MapPoint::replace(const std::shared_ptr<MapPoint>& other, const std::shared_ptr<MapPoint>& self) {
  if (other.get() == this || bad_) return;
  const auto obs = obs_;
  obs_.clear();
  num_obs_ = 0;
  bad_ = true;
  replaced_ = other;
  for (const auto& [id, o] : obs) {
    auto kf = o.kf.lock();
    if (!kf) continue;
    if (other->index_in(id) < 0) {
      kf->set_map_point(o.idx, other);
      other->add_observation(kf, o.idx);
    } else if (kf->map_points()[o.idx] == self) {
      kf->set_map_point(o.idx, nullptr);
    }
  }
  other->increase_found(found_);
  other->increase_visible(visible_);
  other->compute_distinctive_descriptor();
}

void MapPoint::compute_distinctive_descriptor() {
  std::vector<const unsigned char*> descs;  // rows of the observing keyframes' descriptors, newest first
  for (auto it = obs_.end(); it != obs_.begin() && descs.size() < kMaxDescriptorViews;) {
    const Obs& o = (--it)->second;
    if (auto kf = o.kf.lock())
      if (!kf->bad()) descs.push_back(kf->frame().descriptors.ptr<unsigned char>(static_cast<int>(o.idx)));
  }
  if (descs.empty()) return;
  std::reverse(descs.begin(), descs.end());  // in ascending keyframe ids, as ORB-SLAM2 takes them
  const std::size_t n = descs.size();
  std::vector<int> dist(n * n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) dist[i * n + j] = dist[j * n + i] = descriptor_distance(descs[i], descs[j]);
  int best = INT_MAX;
  std::size_t best_i = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<int> row(dist.begin() + i * n, dist.begin() + (i + 1) * n);
    std::sort(row.begin(), row.end());
    const int median = row[(n - 1) / 2];
    if (median < best) {
      best = median;
      best_i = i;
    }
  }
  std::copy(descs[best_i], descs[best_i] + descriptor_.size(), descriptor_.begin());
  has_descriptor_ = true;
}

void MapPoint::update_normal_and_depth() {
  auto ref = ref_kf_.lock();
  if (obs_.empty() || !ref) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& [id, o] : obs_)
    if (auto kf = o.kf.lock()) {
      const Eigen::Vector3d d = p_w_ - kf->camera_center_w();
      normal += d.normalized();
      ++n;
    }
  if (n == 0) return;
  normal_ = normal / n;
  const auto ref_obs = obs_.find(ref->id());
  if (ref_obs == obs_.end()) return;
  const double dist = (p_w_ - ref->camera_center_w()).norm();
  const int level = ref_obs->second.octave;
  const auto& cam = *ref->frame().cam;
  max_dist_m_ = dist * cam.scale[level];
  min_dist_m_ = max_dist_m_ / cam.scale[cam.num_levels - 1];
}

std::size_t MapPoint::memory_bytes() const {
  // make_shared puts the object after a control block of two counts and a vtable pointer.
  return heap_block_bytes(sizeof(MapPoint) + 2 * sizeof(long)) + obs_.heap_bytes();
}

// KeyFrame ------------------------------------------------------------------

KeyFrameMemory& KeyFrameMemory::operator+=(const KeyFrameMemory& o) {
  frame += o.frame;
  bow += o.bow;
  graph += o.graph;
  object += o.object;
  return *this;
}

KeyFrameMemory KeyFrame::memory() const {
  KeyFrameMemory m;
  m.frame = frame_.memory();
  m.bow = vector_heap_bytes(bow_) + vector_heap_bytes(features_by_node_);
  for (const auto& [node, indices] : features_by_node_) m.bow += vector_heap_bytes(indices);
  m.graph = map_node_bytes(connections_) + vector_heap_bytes(ordered_) + map_node_bytes(children_) +
            map_node_bytes(loop_edges_);
  m.object = heap_block_bytes(sizeof(KeyFrame) + 2 * sizeof(long)) - sizeof(Frame);
  return m;
}

KeyFrame::KeyFrame(std::uint64_t id, const Frame& frame) : id_(id), frame_(frame) {}

int KeyFrame::num_tracked_points(int min_obs) const {
  int n = 0;
  for (const auto& mp : frame_.map_points)
    if (mp && !mp->bad() && mp->num_observations() >= min_obs) ++n;
  return n;
}

void KeyFrame::update_connections() {
  std::map<std::uint64_t, std::pair<std::shared_ptr<KeyFrame>, int>> counter;
  for (const auto& mp : frame_.map_points) {
    if (!mp || mp->bad()) continue;
    for (const auto& [kid, o] : mp->observations()) {
      if (kid == id_) continue;
      auto kf = o.kf.lock();
      if (!kf || kf->bad()) continue;
      auto& c = counter[kid];
      c.first = kf;
      ++c.second;
    }
  }
  if (counter.empty()) return;
  constexpr int kThreshold = 15;
  int best_w = 0;
  std::shared_ptr<KeyFrame> best;
  connections_.clear();
  for (const auto& [kid, c] : counter) {
    if (c.second > best_w) {
      best_w = c.second;
      best = c.first;
    }
    if (c.second >= kThreshold) {
      connections_[kid] = {c.first, c.second};
      c.first->add_connection(shared_from_this(), c.second);
    }
  }
  if (connections_.empty()) {
    connections_[best->id()] = {best, best_w};
    best->add_connection(shared_from_this(), best_w);
  }
  update_order();
  if (first_connection_ && id_ != 0) {
    first_connection_ = false;
    std::shared_ptr<KeyFrame> strongest;
    for (const auto& [w, kid] : ordered_) {
      auto k = connections_.at(kid).first.lock();
      if (k && !k->bad()) {
        strongest = k;
        break;
      }
    }
    if (strongest) {
      parent_ = strongest;
      strongest->add_child(shared_from_this());
    }
  }
}

void KeyFrame::add_connection(const std::shared_ptr<KeyFrame>& kf, int weight) {
  connections_[kf->id()] = {kf, weight};
  update_order();
}

void KeyFrame::erase_connection(std::uint64_t kf_id) {
  if (connections_.erase(kf_id)) update_order();
}

void KeyFrame::update_order() {
  ordered_.clear();
  for (const auto& [kid, c] : connections_) ordered_.emplace_back(c.second, kid);
  std::sort(ordered_.begin(), ordered_.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
}

std::vector<std::shared_ptr<KeyFrame>> KeyFrame::best_covisibles(int n) const {
  std::vector<std::shared_ptr<KeyFrame>> out;
  for (const auto& [w, kid] : ordered_) {
    if (n >= 0 && static_cast<int>(out.size()) >= n) break;
    auto it = connections_.find(kid);
    if (it == connections_.end()) continue;
    auto k = it->second.first.lock();
    if (k && !k->bad()) out.push_back(k);
  }
  return out;
}

int KeyFrame::weight(std::uint64_t kf_id) const {
  auto it = connections_.find(kf_id);
  return it == connections_.end() ? 0 : it->second.second;
}

std::map<std::uint64_t, int> KeyFrame::connection_weights() const {
  std::map<std::uint64_t, int> out;
  for (const auto& [kid, c] : connections_) out[kid] = c.second;
  return out;
}

void KeyFrame::restore_graph(const std::shared_ptr<KeyFrame>& parent,
                             const std::vector<std::pair<std::shared_ptr<KeyFrame>, int>>& connections,
                             const std::vector<std::shared_ptr<KeyFrame>>& loop_edges) {
  first_connection_ = false;
  if (parent) change_parent(parent);
  connections_.clear();
  for (const auto& [kf, w] : connections) connections_[kf->id()] = {kf, w};
  update_order();
  for (const auto& kf : loop_edges) loop_edges_[kf->id()] = kf;
}

std::vector<std::shared_ptr<KeyFrame>> KeyFrame::children() const {
  std::vector<std::shared_ptr<KeyFrame>> out;
  for (const auto& [id, w] : children_)
    if (auto k = w.lock()) out.push_back(k);
  return out;
}

std::vector<std::shared_ptr<KeyFrame>> KeyFrame::loop_edges() const {
  std::vector<std::shared_ptr<KeyFrame>> out;
  for (const auto& [id, w] : loop_edges_)
    if (auto k = w.lock()) out.push_back(k);
  return out;
}

void KeyFrame::add_child(const std::shared_ptr<KeyFrame>& kf) { children_[kf->id()] = kf; }
void KeyFrame::erase_child(std::uint64_t kf_id) { children_.erase(kf_id); }
void KeyFrame::change_parent(const std::shared_ptr<KeyFrame>& kf) {
  parent_ = kf;
  kf->add_child(shared_from_this());
}

void KeyFrame::reroot_under(const std::shared_ptr<KeyFrame>& parent) {
  std::vector<std::shared_ptr<KeyFrame>> path = {shared_from_this()};
  while (auto p = path.back()->parent()) path.push_back(p);
  for (std::size_t i = path.size() - 1; i > 0; --i) {
    path[i]->erase_child(path[i - 1]->id());
    path[i]->change_parent(path[i - 1]);
    path[i]->root_ = false;
  }
  root_ = false;
  change_parent(parent);
}

bool KeyFrame::set_bad() {
  if (id_ == 0 || root_ || bad_ || fixed_ || !loop_edges_.empty()) return false;
  for (const auto& [kid, c] : connections_)
    if (auto k = c.first.lock()) k->erase_connection(id_);
  for (std::size_t i = 0; i < frame_.map_points.size(); ++i)
    if (auto mp = frame_.map_points[i]) mp->erase_observation(id_);
  connections_.clear();
  ordered_.clear();

  // Re-attach the children (ORB-SLAM2): repeatedly pick the child with the
  // strongest covisibility link to a keyframe already in the candidate
  // parent set, starting from this keyframe's parent.
  auto parent = parent_.lock();
  std::map<std::uint64_t, std::shared_ptr<KeyFrame>> candidates;
  if (parent) candidates[parent->id()] = parent;
  std::map<std::uint64_t, std::shared_ptr<KeyFrame>> kids;
  for (auto& k : children()) kids[k->id()] = k;
  while (!kids.empty()) {
    int best_w = -1;
    std::shared_ptr<KeyFrame> best_child, best_parent;
    for (const auto& [cid, child] : kids) {
      if (child->bad()) continue;
      for (const auto& cov : child->best_covisibles(-1)) {
        auto it = candidates.find(cov->id());
        if (it == candidates.end()) continue;
        const int w = child->weight(cov->id());
        if (w > best_w) {
          best_w = w;
          best_child = child;
          best_parent = it->second;
        }
      }
    }
    if (!best_child) break;
    best_child->change_parent(best_parent);
    candidates[best_child->id()] = best_child;
    kids.erase(best_child->id());
  }
  if (parent) {
    for (const auto& [cid, child] : kids) child->change_parent(parent);
    parent->erase_child(id_);
    removed_parent_ = parent;
    T_c_parent_ = frame_.T_c_w * parent->T_c_w().inverse();
  }
  children_.clear();
  place::BowVector().swap(bow_);
  place::FeatureVector().swap(features_by_node_);
  frame_.release_features();
  bad_ = true;
  return true;
}

geom::SE3d KeyFrame::T_c_w_via_tree() const {
  if (!bad_ || !removed_parent_) return frame_.T_c_w;
  return T_c_parent_ * removed_parent_->T_c_w_via_tree();
}

// Map -----------------------------------------------------------------------

std::shared_ptr<KeyFrame> Map::create_keyframe(const Frame& frame) {
  auto kf = std::make_shared<KeyFrame>(next_kf_id_++, frame);
  kf->set_session(session_);
  keyframes_[kf->id()] = kf;
  return kf;
}

std::shared_ptr<KeyFrame> Map::add_loaded_keyframe(std::uint64_t id, const Frame& frame) {
  auto kf = std::make_shared<KeyFrame>(id, frame);
  kf->release_pyramid();  // a loaded keyframe has no image: never aligned to
  if (!keyframes_.emplace(id, kf).second) throw std::logic_error("Map: keyframe id given twice");
  next_kf_id_ = std::max(next_kf_id_, id + 1);
  return kf;
}

std::shared_ptr<MapPoint> Map::add_loaded_point(std::uint64_t id, const Eigen::Vector3d& p_w,
                                                const std::shared_ptr<KeyFrame>& ref_kf) {
  auto mp = std::make_shared<MapPoint>(id, p_w, ref_kf);
  // A map file lists its points in id order: a hint at the end makes each insertion constant time.
  const auto hint = points_.empty() || points_.rbegin()->first < id ? points_.end() : points_.lower_bound(id);
  if (points_.emplace_hint(hint, id, mp)->second != mp) throw std::logic_error("Map: point id given twice");
  next_point_id_ = std::max(next_point_id_, id + 1);
  return mp;
}

std::shared_ptr<MapPoint> Map::create_point(const Eigen::Vector3d& p_w, const std::shared_ptr<KeyFrame>& ref_kf) {
  auto mp = std::make_shared<MapPoint>(next_point_id_++, p_w, ref_kf);
  points_[mp->id()] = mp;
  return mp;
}

void Map::erase_point(const std::shared_ptr<MapPoint>& mp) {
  mp->set_bad();
  points_.erase(mp->id());
}

void unlink_in_time(KeyFrame& kf) {
  KeyFrameMotion& m = kf.motion();
  const auto prev = m.prev.lock();
  const auto next = m.next.lock();
  if (next) {
    KeyframeInterval& n = next->motion().from_prev;
    if (n.imu && m.from_prev.imu) {
      auto joined = std::make_shared<ImuPreintegration>(*m.from_prev.imu);
      joined->append(*n.imu);
      n.imu = std::move(joined);
    } else {
      n.imu.reset();
    }
    if (n.wheels && m.from_prev.wheels) {
      auto joined = std::make_shared<WheelPreintegration>(*m.from_prev.wheels);
      joined->append(*n.wheels);
      n.wheels = std::move(joined);
    } else {
      n.wheels.reset();
    }
    next->motion().prev = prev;
  }
  if (prev) prev->motion().next = next;
  m.prev.reset();
  m.next.reset();
}

bool Map::erase_keyframe(const std::shared_ptr<KeyFrame>& kf) {
  const std::vector<std::shared_ptr<MapPoint>> seen = kf->map_points();  // set_bad frees them
  if (!kf->set_bad()) return false;
  unlink_in_time(*kf);
  keyframes_.erase(kf->id());
  remove_bad_among(seen);
  return true;
}

void Map::remove_bad_points() {
  for (auto it = points_.begin(); it != points_.end();)
    it = it->second->bad() ? points_.erase(it) : std::next(it);
}

void Map::remove_bad_among(const std::vector<std::shared_ptr<MapPoint>>& points) {
  for (const auto& mp : points)
    if (mp && mp->bad())
      if (const auto it = points_.find(mp->id()); it != points_.end() && it->second == mp) points_.erase(it);
}

MapMemory Map::memory() const {
  MapMemory m;
  m.keyframes = keyframes_.size();
  for (const auto& [id, kf] : keyframes_) {
    const KeyFrameMemory k = kf->memory();
    m.keyframe_bytes += k;
    if (kf->frame().features_spilled()) ++m.keyframes_spilled;
    if (kf->frame().pyramid) continue;
    ++m.keyframes_outside;
    m.outside_bytes += k;
  }
  m.points = points_.size();
  for (const auto& [id, mp] : points_) m.point_bytes += mp->memory_bytes();
  return m;
}

std::uint32_t Map::map_of(const KeyFrame& kf) const {
  std::uint32_t m = kf.provisional();
  for (auto it = merged_.find(m); it != merged_.end(); it = merged_.find(m)) m = it->second;
  return m;
}

void Map::clear() {
  keyframes_.clear();
  points_.clear();
}

}  // namespace pvb::slam
