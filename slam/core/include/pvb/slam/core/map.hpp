#pragma once
// The sparse map: map points, keyframes, the covisibility graph and the
// spanning tree.  The Map owns both kinds (shared_ptr); keyframes hold their
// map points (shared_ptr) and map points refer back weakly (weak_ptr), so
// nothing leaks.  Containers are ordered by id so that every traversal is
// deterministic.  Per-run scratch state (which frame last saw a point, which
// keyframes are in the current local BA) lives in the algorithm objects.
//
// Thread safety: the tracker and the local mapper take Map::mutex() around
// every read or write of map data; the objects themselves have no locks.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <vector>

#include "pvb/slam/core/frame.hpp"
#include "pvb/slam/core/keyframe_motion.hpp"
#include "pvb/slam/core/reports.hpp"
#include "pvb/slam/inertial/wheel_calibration.hpp"
#include "pvb/slam/place/vocabulary.hpp"

namespace pvb::slam {

class KeyFrame;

/// A 3-D landmark.
class MapPoint {
 public:
  MapPoint(std::uint64_t id, const Eigen::Vector3d& p_w, const std::shared_ptr<KeyFrame>& ref_kf);

  std::uint64_t id() const { return id_; }
  const Eigen::Vector3d& p_w() const { return p_w_; }
  void set_p_w(const Eigen::Vector3d& p) { p_w_ = p; }
  bool bad() const { return bad_; }
  /// The point that replaced this one after fusion (null when none);
  /// follows the chain to the newest.
  std::shared_ptr<MapPoint> replaced() const;

  /// Observations: keyframe id -> (keyframe, keypoint index), ordered by id.
  /// The keypoint's pyramid level and whether it has depth are kept with
  /// it: a keyframe far behind the robot holds its keypoints in the feature
  /// file, and a loop's correction, which updates every point, would read
  /// them all back.
  struct Obs {
    std::weak_ptr<KeyFrame> kf;
    std::uint32_t idx = 0;
    std::int16_t octave = 0;  ///< the keypoint's pyramid level
    bool stereo = false;      ///< the keypoint has depth (counts twice in num_observations)
  };
  /// The observations as a sorted array: 32 bytes each, where a std::map
  /// node costs 80.  Read like a map (ascending ids, find, count).
  class Observations {
   public:
    using value_type = std::pair<std::uint64_t, Obs>;
    using const_iterator = std::vector<value_type>::const_iterator;
    const_iterator begin() const { return list_.begin(); }
    const_iterator end() const { return list_.end(); }
    std::size_t size() const { return list_.size(); }
    bool empty() const { return list_.empty(); }
    const_iterator find(std::uint64_t kf_id) const;
    std::size_t count(std::uint64_t kf_id) const { return find(kf_id) != end() ? 1 : 0; }
    /// Adds kf_id's observation; false (and no change) when it has one.
    bool insert(std::uint64_t kf_id, Obs o);
    /// Removes kf_id's observation; false when it has none.
    bool erase(std::uint64_t kf_id);
    void erase(const_iterator it) { list_.erase(it); }
    void clear() { std::vector<value_type>().swap(list_); }
    std::size_t heap_bytes() const;

   private:
    std::vector<value_type> list_;
  };
  const Observations& observations() const { return obs_; }
  int num_observations() const { return num_obs_; }
  void add_observation(const std::shared_ptr<KeyFrame>& kf, std::size_t idx);
  /// Removes the observation of keyframe kf_id; marks the point bad (and
  /// detaches it) when two or fewer observations remain (RGB-D counts 2 each).
  void erase_observation(std::uint64_t kf_id);
  /// Keypoint index in keyframe kf_id, or -1.
  long index_in(std::uint64_t kf_id) const;
  /// Marks bad and removes it from all observing keyframes (not from the Map:
  /// Map::erase_point does both).
  void set_bad();
  /// Replaces this point by `other` in every observing keyframe.
  void replace(const std::shared_ptr<MapPoint>& other, const std::shared_ptr<MapPoint>& self);

  /// The point's descriptor (32 bytes), null until the first
  /// compute_distinctive_descriptor() with an observation.
  const unsigned char* descriptor() const { return has_descriptor_ ? descriptor_.data() : nullptr; }
  /// Chooses the observation descriptor with the least median distance to
  /// the others (ORB-SLAM2 ComputeDistinctiveDescriptors), among the
  /// newest kMaxDescriptorViews observations by live keyframes: the work
  /// grows with their square, and a point at an aisle's vanishing end is
  /// seen by hundreds of keyframes.
  void compute_distinctive_descriptor();
  static constexpr std::size_t kMaxDescriptorViews = 32;
  /// Mean viewing direction and the scale-invariance distance range.
  void update_normal_and_depth();
  const Eigen::Vector3d& normal() const { return normal_; }
  double min_distance() const { return 0.8 * min_dist_m_; }
  double max_distance() const { return 1.2 * max_dist_m_; }

  std::shared_ptr<KeyFrame> reference_keyframe() const { return ref_kf_.lock(); }
  std::uint64_t first_kf_id() const { return first_kf_id_; }

  /// Tracking statistics: frames where the point was predicted visible and
  /// where it was matched (ORB-SLAM2 mnVisible, mnFound).
  void increase_visible(int n = 1) { visible_ += n; }
  void increase_found(int n = 1) { found_ += n; }
  double found_ratio() const { return visible_ > 0 ? static_cast<double>(found_) / visible_ : 0.0; }
  int visible() const { return visible_; }
  int found() const { return found_; }
  /// A point read from a map file: its first keyframe and statistics.
  void restore(std::uint64_t first_kf_id, int visible, int found) {
    first_kf_id_ = first_kf_id;
    visible_ = visible;
    found_ = found;
  }

  /// Bytes the point holds: the object (with make_shared's control block),
  /// its observation nodes and its descriptor.
  std::size_t memory_bytes() const;

 private:
  std::uint64_t id_;
  Eigen::Vector3d p_w_;
  Observations obs_;
  int num_obs_ = 0;
  std::array<unsigned char, 32> descriptor_{};
  bool has_descriptor_ = false;
  Eigen::Vector3d normal_ = Eigen::Vector3d::Zero();
  double min_dist_m_ = 0, max_dist_m_ = 0;
  std::weak_ptr<KeyFrame> ref_kf_;
  std::uint64_t first_kf_id_ = 0;
  int visible_ = 1, found_ = 1;
  bool bad_ = false;
  std::shared_ptr<MapPoint> replaced_;
};

/// A keyframe: a frozen frame plus its place in the covisibility graph and
/// the spanning tree.
class KeyFrame : public std::enable_shared_from_this<KeyFrame> {
 public:
  KeyFrame(std::uint64_t id, const Frame& frame);

  std::uint64_t id() const { return id_; }
  std::uint64_t frame_id() const { return frame_.id; }
  std::int64_t t_ns() const { return frame_.t_ns; }
  const Frame& frame() const { return frame_; }
  /// Write access for patch alignment of its keypoints only
  /// (align_keyframe_observations), under the map lock.
  Frame& frame_for_alignment() { return frame_; }
  /// Drops the grey pyramid (the keyframe has left the local map): its
  /// patches are no longer alignment references.
  void release_pyramid() { frame_.release_pyramid(); }
  /// Its features into `spill` (Frame::spill_features), under the map's mutex.
  void spill_features(const std::shared_ptr<FeatureSpill>& spill) { frame_.spill_features(spill); }
  const geom::SE3d& T_c_w() const { return frame_.T_c_w; }
  void set_T_c_w(const geom::SE3d& T) { frame_.T_c_w = T; }
  /// A correction (loop, merge) moves the keyframe to T: its velocity
  /// in the world turns with it.
  void correct_T_c_w(const geom::SE3d& T) {
    motion_.v_w_mps = T.linear().transpose() * frame_.T_c_w.linear() * motion_.v_w_mps;
    frame_.T_c_w = T;
  }
  Eigen::Vector3d camera_center_w() const { return frame_.camera_center_w(); }
  bool bad() const { return bad_; }
  /// The mapping session the keyframe was made in (0: the map's first).
  std::uint32_t session() const { return session_; }
  void set_session(std::uint32_t s) { session_ = s; }
  /// Held where it is: local BA does not move it and culling keeps it
  /// (the keyframes of a loaded map that a session extends).
  bool fixed() const { return fixed_; }
  void set_fixed(bool f) { fixed_ = f; }
  /// The provisional map the keyframe was made in (0: the map's own frame);
  /// Map::map_of says which map it belongs to now.
  std::uint32_t provisional() const { return provisional_; }
  void set_provisional(std::uint32_t m) { provisional_ = m; }
  /// The first keyframe of a provisional map: a root of the spanning tree
  /// like keyframe 0 (never re-parented by update_connections(), never
  /// culled, the gauge of local BA) until reroot_under() joins it.
  bool root() const { return root_; }
  void make_root() {
    root_ = true;
    first_connection_ = false;
  }
  /// Hangs this keyframe under `parent` (a merge of two maps): the tree
  /// path from here up to this keyframe's root is reversed first, so the
  /// old root becomes a descendant of this keyframe.
  void reroot_under(const std::shared_ptr<KeyFrame>& parent);

  /// Map points per keypoint (null where none).
  const std::vector<std::shared_ptr<MapPoint>>& map_points() const { return frame_.map_points; }
  void set_map_point(std::size_t idx, std::shared_ptr<MapPoint> mp) { frame_.map_points[idx] = std::move(mp); }
  /// Good points with at least min_obs observations.
  int num_tracked_points(int min_obs) const;

  // Covisibility graph ------------------------------------------------------
  /// Recomputes the edges from shared map points (weight >= 15, or the best
  /// one), updates the other ends, and on first call attaches this keyframe
  /// to the spanning tree under its strongest neighbour.
  void update_connections();
  void add_connection(const std::shared_ptr<KeyFrame>& kf, int weight);
  void erase_connection(std::uint64_t kf_id);
  /// Neighbours sorted by weight (descending, then id ascending); at most n (n < 0: all).
  std::vector<std::shared_ptr<KeyFrame>> best_covisibles(int n) const;
  int weight(std::uint64_t kf_id) const;
  /// Covisibility weights by neighbour id (for map files).
  std::map<std::uint64_t, int> connection_weights() const;
  /// A keyframe read from a map file: its parent in the spanning tree (may
  /// be null) and its edges, as they were saved; the other ends are updated
  /// by their own restore.  update_connections() will not re-parent it.
  void restore_graph(const std::shared_ptr<KeyFrame>& parent,
                     const std::vector<std::pair<std::shared_ptr<KeyFrame>, int>>& connections,
                     const std::vector<std::shared_ptr<KeyFrame>>& loop_edges);

  // Bag of words (place recognition) -----------------------------------------
  /// Set once, by the thread that processes the keyframe, before the
  /// keyframe enters the place database (which publishes it).
  void set_bow(place::BowVector bow, place::FeatureVector features) {
    bow_ = std::move(bow);
    features_by_node_ = std::move(features);
  }
  /// Its bag of words until it enters the place database, which keeps the
  /// weights from then on (PlaceRecognizer::bag_of); empty after that.
  const place::BowVector& bow() const { return bow_; }
  /// Frees the bag (PlaceRecognizer::add, once the database holds it).
  void drop_bow() { place::BowVector().swap(bow_); }
  /// The direct index: keypoint indices by vocabulary node.
  const place::FeatureVector& features_by_node() const { return features_by_node_; }

  // Loop edges (loop closing) ---------------------------------------------------
  /// Records a closed loop between this keyframe and kf; a keyframe with a
  /// loop edge is never removed (it anchors the essential graph).
  void add_loop_edge(const std::shared_ptr<KeyFrame>& kf) { loop_edges_[kf->id()] = kf; }
  std::vector<std::shared_ptr<KeyFrame>> loop_edges() const;
  bool has_loop_edges() const { return !loop_edges_.empty(); }

  // Spanning tree -----------------------------------------------------------
  std::shared_ptr<KeyFrame> parent() const { return parent_.lock(); }
  std::vector<std::shared_ptr<KeyFrame>> children() const;
  void add_child(const std::shared_ptr<KeyFrame>& kf);
  void erase_child(std::uint64_t kf_id);
  void change_parent(const std::shared_ptr<KeyFrame>& kf);

  /// Removes the keyframe from the graph: its map points forget it, its
  /// children are re-attached in the spanning tree (ORB-SLAM2 SetBadFlag),
  /// and what it held for matching is freed (keypoints, descriptors, its
  /// map points, the grid, the bag of words): a removed keyframe keeps its
  /// pose relative to its parent, for the trajectory, and no more.
  /// The first keyframe (id 0) and keyframes with loop edges are never
  /// removed; returns false then.
  bool set_bad();
  /// World-to-camera pose, for a removed keyframe composed through the
  /// spanning tree from its pose relative to its parent at removal time.
  geom::SE3d T_c_w_via_tree() const;

  /// What this keyframe holds, by structure.
  KeyFrameMemory memory() const;

  // Motion sensors (under the map's mutex) -------------------------------------
  KeyFrameMotion& motion() { return motion_; }
  const KeyFrameMotion& motion() const { return motion_; }

 private:
  void update_order();

  std::uint64_t id_;
  Frame frame_;
  std::map<std::uint64_t, std::pair<std::weak_ptr<KeyFrame>, int>> connections_;
  std::vector<std::pair<int, std::uint64_t>> ordered_;  ///< (weight, id) sorted
  bool first_connection_ = true;
  std::weak_ptr<KeyFrame> parent_;
  std::map<std::uint64_t, std::weak_ptr<KeyFrame>> children_;
  std::map<std::uint64_t, std::weak_ptr<KeyFrame>> loop_edges_;
  place::BowVector bow_;
  place::FeatureVector features_by_node_;
  bool bad_ = false;
  std::uint32_t session_ = 0;
  bool fixed_ = false;
  std::uint32_t provisional_ = 0;
  bool root_ = false;
  std::shared_ptr<KeyFrame> removed_parent_;          ///< parent at removal (kept alive for trajectories)
  geom::SE3d T_c_parent_ = geom::SE3d::Identity();  ///< pose relative to it at removal
  KeyFrameMotion motion_;
};

/// All keyframes and map points of a run.
class Map {
 public:
  std::mutex& mutex() { return mutex_; }

  std::shared_ptr<KeyFrame> create_keyframe(const Frame& frame);
  std::shared_ptr<MapPoint> create_point(const Eigen::Vector3d& p_w, const std::shared_ptr<KeyFrame>& ref_kf);
  /// Marks a point bad and removes it from the map.
  void erase_point(const std::shared_ptr<MapPoint>& mp);
  /// Marks a keyframe bad and removes it from the map (not the first one).
  bool erase_keyframe(const std::shared_ptr<KeyFrame>& kf);
  /// Drops points that were marked bad elsewhere (e.g. by erase_observation).
  /// Walks the whole map.
  void remove_bad_points();
  /// Drops those of `points` that are bad: the points one step touched,
  /// without walking the map.
  void remove_bad_among(const std::vector<std::shared_ptr<MapPoint>>& points);

  const std::map<std::uint64_t, std::shared_ptr<KeyFrame>>& keyframes() const { return keyframes_; }
  const std::map<std::uint64_t, std::shared_ptr<MapPoint>>& points() const { return points_; }
  std::size_t num_keyframes() const { return keyframes_.size(); }
  std::size_t num_points() const { return points_.size(); }
  /// What the keyframes and points in the map hold (callers hold mutex()).
  MapMemory memory() const;
  void clear();

  // Loading a saved map (map_file.hpp) ---------------------------------------
  /// Adds a keyframe or point with its saved id; ids created later follow
  /// the largest.  An id already in the map is a logic error.
  std::shared_ptr<KeyFrame> add_loaded_keyframe(std::uint64_t id, const Frame& frame);
  std::shared_ptr<MapPoint> add_loaded_point(std::uint64_t id, const Eigen::Vector3d& p_w,
                                             const std::shared_ptr<KeyFrame>& ref_kf);
  /// The session that new keyframes belong to (set_session on creation).
  std::uint32_t session() const { return session_; }
  void set_session(std::uint32_t s) { session_ = s; }
  std::uint64_t next_keyframe_id() const { return next_kf_id_; }
  std::uint64_t next_point_id() const { return next_point_id_; }

  // Provisional maps ------------------------------------------------------------
  /// A new provisional map: begun while lost in a loaded map (extend mode),
  /// in a frame of its own until it is merged.  Returns its id (> 0).
  std::uint32_t begin_provisional() { return next_provisional_++; }
  /// Provisional map `from` now lies in the frame of map `into` (its
  /// keyframes and points were moved there).
  void merge_provisional(std::uint32_t from, std::uint32_t into) { merged_[from] = into; }
  /// The map a keyframe belongs to now: 0 for the map's own frame.
  std::uint32_t map_of(const KeyFrame& kf) const;

  // Motion sensors -----------------------------------------------------------------
  /// Gravity in the map's frame and whether the inertial state is trusted.
  MapGravity& gravity() { return gravity_; }
  const MapGravity& gravity() const { return gravity_; }
  /// The wheels' calibration so far (local mapping's WheelCalibrator;
  /// tracking reads new encoder intervals with it).
  WheelFit& wheels() { return wheels_; }
  const WheelFit& wheels() const { return wheels_; }

 private:
  std::mutex mutex_;
  std::map<std::uint64_t, std::shared_ptr<KeyFrame>> keyframes_;
  std::map<std::uint64_t, std::shared_ptr<MapPoint>> points_;
  std::uint64_t next_kf_id_ = 0;
  std::uint64_t next_point_id_ = 0;
  std::uint32_t session_ = 0;
  std::uint32_t next_provisional_ = 1;
  std::map<std::uint32_t, std::uint32_t> merged_;  ///< provisional map -> the map it was merged into
  MapGravity gravity_;
  WheelFit wheels_;
};

/// Takes kf out of the chain in time: its next keyframe's interval then
/// begins at kf's predecessor (the readings appended), or is dropped when
/// a part is missing.
void unlink_in_time(KeyFrame& kf);

}  // namespace pvb::slam
