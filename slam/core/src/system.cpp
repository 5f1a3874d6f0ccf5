#include "pvb/slam/core/system.hpp"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include <set>
#include <sstream>

#include "pvb/common/clock.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/text.hpp"
#include "pvb/slam/core/frame.hpp"
#include "pvb/slam/core/local_mapping.hpp"
#include "pvb/slam/core/loop_closing.hpp"
#include "pvb/slam/core/map.hpp"
#include "pvb/slam/core/map_file.hpp"
#include "pvb/slam/core/place_recognition.hpp"
#include "pvb/slam/core/tracking.hpp"
#include "pvb/slam/dense/dense_mapper.hpp"
#include "pvb/slam/features/orb_extractor.hpp"

namespace pvb::slam {
namespace {

/// A map's save drops the spilled features it has read from the process
/// each time it has written this much (the keyframe section is about 1.3 ×
/// the features it reads).
constexpr std::size_t kSaveSpillDropBytes = std::size_t(32) << 20;

/// The spill read ahead for one pass over every keyframe, and let go of
/// (written out, dropped from the process and the cache) when it ends.
class SpillReadAhead {
 public:
  explicit SpillReadAhead(FeatureSpill* spill) : spill_(spill) {
    if (spill_) spill_->read_ahead();
  }
  ~SpillReadAhead() {
    if (!spill_) return;
    spill_->end_read_ahead();
    spill_->release_resident();
  }
  SpillReadAhead(const SpillReadAhead&) = delete;
  SpillReadAhead& operator=(const SpillReadAhead&) = delete;

 private:
  FeatureSpill* spill_;
};

}  // namespace

System::System(const Settings& settings, const SystemOptions& options)
    : settings_(settings),
      options_(options),
      extractor_(std::make_unique<OrbExtractor>(settings.orb)),
      map_(std::make_unique<Map>()) {
  StereoIntrinsics K;
  K.fx = settings.K.fx;
  K.fy = settings.K.fy;
  K.cx = settings.K.cx;
  K.cy = settings.K.cy;
  K.bf = settings.bf;
  cam_ = std::make_shared<const CameraModel>(CameraModel::make(
      K, settings.K.width, settings.K.height, {settings.k1, settings.k2, settings.p1, settings.p2, settings.k3},
      settings.th_depth_m(), settings.orb.scale_factor, settings.orb.num_levels));
  TrackingOptions topt;
  topt.use_pe_match = settings.pe_match.enabled;
  topt.pe_match.population = settings.pe_match.population;
  topt.pe_match.num_fitness_samples = settings.pe_match.num_fitness_samples;
  topt.pe_match.stall_iterations = settings.pe_match.stall_iterations;
  topt.pe_match.inlier_threshold_px = settings.pe_match.threshold_px;
  topt.pe_match.refine = settings.pe_match.refine;
  topt.pe_match.distance = settings.pe_match.sampson ? EpipolarDistance::kSampson : EpipolarDistance::kPointLine;
  topt.pe_match.seed = options.seed;
  topt.pe_skip_low_parallax = settings.pe_match.skip_low_parallax;
  topt.max_frames = static_cast<int>(settings.fps);
  topt.kf_min_tracked_close = settings.keyframe.min_tracked_close;
  topt.kf_min_untracked_close = settings.keyframe.min_untracked_close;
  topt.kf_ref_overlap = settings.keyframe.ref_overlap;
  topt.align_patches = settings.align_patches;
  topt.patch_align.scale_factor = settings.orb.scale_factor;
  topt.reloc_ambiguity_check = settings.loop.ambiguity_check;
  topt.reloc_ambiguity_distance_m = settings.loop.ambiguity_distance_m;
  topt.reloc_lookalikes = settings.reloc_lookalikes;
  topt.max_observing_keyframes = settings.max_observing_keyframes;
  topt.two_view_start = settings.two_view_start;
  topt.new_map_after_lost = settings.new_map_after_lost;
  topt.merge_reloc_every = settings.merge_reloc_every;
  topt.reloc_odometry_floor_m = settings.reloc_odometry_floor_m;
  topt.reloc_odometry_rate = settings.reloc_odometry_rate;
  topt.carried_restart_after = settings.carried_restart_after;
  if (settings.vocabulary_path != "none") {
    auto vocabulary = place::Vocabulary::load_shared(settings.vocabulary_path);
    vocabulary_fingerprint_ = vocabulary->fingerprint();
    place_ = std::make_unique<PlaceRecognizer>(std::move(vocabulary));
  }
  tracking_ = std::make_unique<Tracking>(*map_, cam_, topt, place_.get());
  settings.motion.check(settings.source);  // once: tracking and local mapping share them
  tracking_->use_motion_sensors(settings.motion);
  LocalMappingOptions mopt;
  mopt.align_patches = settings.align_patches;
  mopt.patch_align = topt.patch_align;
  mopt.motion = settings.motion;
  mapping_ = std::make_unique<LocalMapping>(*map_, cam_, mopt);
  if (settings.spill_features) {
    feature_spill_ = std::make_shared<FeatureSpill>();
    mapping_->set_feature_spill(feature_spill_);
  }
  if (settings.loop.enabled) loop_ = std::make_unique<LoopClosing>(*map_, settings.loop, place_.get());
  // After local mapping: the keyframe's bag of words, loop detection
  // against the older keyframes, then the keyframe joins the database.
  mapping_->set_after_keyframe([this](const std::shared_ptr<KeyFrame>& kf) {
    // Descriptors never change; the bag is read by others only once the
    // keyframe is in the database (whose mutex publishes it).
    if (place_) place_->compute_bow(*kf);
    const bool closed = loop_ && loop_->process(kf);
    if (place_ && !kf->bad()) place_->add(*kf);
    const std::vector<std::uint64_t> culled = mapping_->take_culled();
    if (place_)
      for (std::uint64_t id : culled) place_->erase(id);  // their bags are of no use any more
    // Local BA (and a loop's correction) moved keyframes: the dense map follows.
    if (dense_ && settings_.dense.reassemble) post_dense_poses(closed, false);
  });
  if (!options.synchronous) mapping_->start();
  if (settings.dense.enabled) {
    dense::DenseMapperOptions dopt;
    dopt.K = settings.K;
    dopt.back_projection.stride_px = settings.dense.stride_px;
    dopt.back_projection.min_depth_m = settings.dense.min_depth_m;
    dopt.back_projection.max_depth_m = settings.dense.max_depth_m;
    dopt.leaf_m = settings.dense.resolution_m;
    dopt.memory_budget_bytes = static_cast<std::size_t>(settings.dense.memory_budget_mb * 1024 * 1024);
    dense_ = std::make_unique<dense::DenseMapper>(dopt);
    if (!options.synchronous) dense_->start();
  }
}

System::~System() {
  if (feature_spill_) feature_spill_->discard();  // the map's keyframes go with the file
  shutdown();
}

void System::shutdown() {
  if (mapping_) mapping_->stop();
  if (dense_) dense_->stop();
  // What ended a worker thread reaches the caller here at the latest.
  if (mapping_) mapping_->rethrow_error();
  if (dense_) dense_->rethrow_error();
}

LocalMappingStats System::mapping_stats() const { return mapping_->stats(); }

TrackingState System::state() const { return tracking_->state(); }

LoopClosingStats System::loop_stats() const { return loop_ ? loop_->stats() : LoopClosingStats{}; }

LoopDetectTotals System::loop_detect_totals() const { return loop_ ? loop_->detect_totals() : LoopDetectTotals{}; }

const std::vector<RelocEvent>& System::relocalisations() const { return tracking_->relocalisations(); }

FrameResult System::track(const sensor::RgbdFrame& in) {
  FrameResult out;
  out.t_ns = in.t_ns;
  const auto t0 = std::chrono::steady_clock::now();
  cv::Mat grey;
  if (in.rgb.channels() == 3) cv::cvtColor(in.rgb, grey, cv::COLOR_RGB2GRAY);  // RgbdFrame is R,G,B
  else grey = in.rgb;
  OrbFeatures features = extractor_->extract(grey);
  out.num_features = static_cast<int>(features.keypoints.size());
  out.orb_ms = ms_since(t0);
  if (!session_first_t_ns_) start_session_clock(in.t_ns);
  Frame frame(next_frame_id_++, in.t_ns, std::move(features), in.depth_m, cam_);
  out.features_with_depth = frame.num_with_depth();
  if (!in.depth_m.empty())
    out.depth_valid = static_cast<double>(cv::countNonZero(in.depth_m > 0)) / static_cast<double>(in.depth_m.total());
  if (settings_.align_patches) frame.pyramid = std::make_shared<const ImagePyramid>(copy_pyramid(extractor_->pyramid()));
  tracking_->add_motion(in.t_ns, in.imu, in.wheel_ticks);
  std::shared_ptr<KeyFrame> kf = tracking_->track(std::move(frame), mapping_->idle(), mapping_->queue_size());
  if (auto hint = tracking_->take_merge_hint(); hint && loop_)
    loop_->suggest_merge(hint->from, hint->T_into_from, hint->anchor);
  out.tracking_ms = ms_since(t0);
  out.state = tracking_->state();
  out.tracking = tracking_->stats();
  if (out.state == TrackingState::kOk || out.state == TrackingState::kDeadReckoning) {
    const auto ref = tracking_->reference_keyframe();
    std::lock_guard<std::mutex> lock(map_->mutex());
    out.provisional = ref && map_->map_of(*ref) != 0;
    if (!out.provisional) out.T_w_c = tracking_->last_frame().T_c_w.inverse();
    if (!out.provisional && map_->gravity().ready) out.g_w = map_->gravity().g_w;
    if (ref) records_.push_back({in.t_ns, ref, tracking_->last_frame().T_c_w * ref->T_c_w().inverse()});
  }
  if (kf && dense_) {
    // Only keyframes keep their images.  The worker gets its own copy (a
    // source may reuse its buffers); inline processing reads them in place.
    dense::DenseKeyFrame dkf;
    dkf.id = kf->id();
    dkf.t_ns = in.t_ns;
    dkf.rgb = dense_->running() ? in.rgb.clone() : in.rgb;
    dkf.depth_m = dense_->running() ? in.depth_m.clone() : in.depth_m;
    {
      std::lock_guard<std::mutex> lock(map_->mutex());
      dkf.T_w_c = kf->T_c_w().inverse();
    }
    {
      std::lock_guard<std::mutex> lock(dense_keyframes_mutex_);
      dense_keyframes_[kf->id()] = kf;
    }
    dense_->insert(std::move(dkf));
  }
  if (kf) {
    const auto t1 = std::chrono::steady_clock::now();
    if (auto first = tracking_->take_start_keyframe()) mapping_->insert(first);  // a two-view start's first view
    mapping_->insert(kf);
    out.mapping_ms = ms_since(t1);
  }
  return out;
}

MapSettings System::map_settings() const {
  MapSettings m;
  m.fx = settings_.K.fx;
  m.fy = settings_.K.fy;
  m.cx = settings_.K.cx;
  m.cy = settings_.K.cy;
  m.bf = settings_.bf;
  m.width = static_cast<std::uint32_t>(settings_.K.width);
  m.height = static_cast<std::uint32_t>(settings_.K.height);
  m.distortion = {settings_.k1, settings_.k2, settings_.p1, settings_.p2, settings_.k3};
  m.th_depth_m = settings_.th_depth_m();
  m.depth_factor = settings_.depth_map_factor;
  m.scale_factor = settings_.orb.scale_factor;
  m.num_levels = static_cast<std::uint32_t>(settings_.orb.num_levels);
  m.num_features = static_cast<std::uint32_t>(settings_.orb.num_features);
  m.vocabulary = vocabulary_fingerprint_;
  m.sensors = settings_.motion.setup;  // extrinsics only where the setup uses them (docs/map_file.md)
  if (uses_accel(m.sensors)) m.T_b_c = settings_.motion.imu.T_b_c;
  if (uses_wheels(m.sensors)) m.T_base_c = settings_.motion.robot.T_base_c;
  return m;
}

void System::take_wheel_fit(MapLoadInfo* info) {
  const WheelFit& fit = map_->wheels();
  if (fit.intervals == 0) return;
  const RobotSettings& robot = settings_.motion.robot;
  if (!uses_wheels(settings_.motion.setup))
    info->wheel_fit_note = "not used: this run reads no wheels";
  else if (fit.described_radius_m != robot.drive.wheel_radius_m || fit.described_track_m != robot.drive.track_m)
    info->wheel_fit_note = "not used: fitted to wheels of radius " + format_g(fit.described_radius_m) +
                           " m and track " + format_g(fit.described_track_m) + " m as described, this run's are " +
                           format_g(robot.drive.wheel_radius_m) + " m and " + format_g(robot.drive.track_m) + " m";
  else if (!robot.wheel_calibration.enabled)
    info->wheel_fit_note = "not used: Robot.CalibrateWheels is 0";
  else
    info->wheel_fit_taken = true;
  if (!info->wheel_fit_taken) map_->wheels() = WheelFit{};
}

MapLoadInfo System::load_map(const std::string& path, MapStart start) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!place_) throw ConfigError(settings_.source, "Vocabulary.path", "a vocabulary to relocalise in a saved map");
  if (next_frame_id_ > 0 || map_start_) throw std::logic_error("System::load_map: after the first frame");
  const MapFileBytes bytes = MapFileBytes::open(path);  // read a piece at a time, never whole
  const MapFileHeader head = read_map_header(bytes);
  const std::string diff = head.settings.difference(map_settings());
  if (!diff.empty()) throw ConfigError(path, "settings", "a map made with this run's settings", diff);
  MapLoadInfo info;
  {
    std::lock_guard<std::mutex> lock(map_->mutex());
    // With a version-2 file, gravity ready and the chain; features into the spill.
    decode_map(bytes, head, cam_, map_.get(), feature_spill_);
    if (!uses_accel(settings_.motion.setup))
      map_->gravity() = MapGravity{};  // a camera-only run keeps no inertial state
    else if (start == MapStart::kExtend && uses_imu(settings_.motion.setup) && !uses_imu(head.settings.sensors))
      map_->gravity().ready = false;  // a tilt alone (camera+accel): the new keyframes initialise the IMU
    take_wheel_fit(&info);
    place_->reserve(map_->num_keyframes());
    for (const auto& [id, kf] : map_->keyframes()) {
      kf->set_fixed(start == MapStart::kExtend);
      if (kf->bow().empty()) place_->compute_bow(*kf);  // saved with the map (the same vocabulary)
      place_->add(*kf);
    }
    if (feature_spill_) feature_spill_->drop_from_process();  // the pages linking and the bags read
    map_->set_session(head.sessions);
    for (const auto& [id, kf] : map_->keyframes())
      loaded_last_t_ns_ = std::max(loaded_last_t_ns_.value_or(kf->t_ns()), kf->t_ns());
    info.keyframes = map_->num_keyframes();
    info.points = map_->num_points();
  }
  tracking_->start_in_map(start == MapStart::kLocalise);
  map_start_ = start;
  loaded_sessions_ = head.sessions;
  info.sessions = head.sessions;
  info.bytes = bytes.size();
  info.app_json = head.app_json;
  info.load_ms = ms_since(t0);
  return info;
}

MapSaveInfo System::save_map(const std::string& path, const std::string& app_json) {
  if (map_start_ == MapStart::kLocalise)
    throw ConfigError(path, "map", "a map made or extended by this run (it only localised in a saved one)");
  const auto t0 = std::chrono::steady_clock::now();
  MapSaveInfo info;
  std::string bytes;
  {
    std::lock_guard<std::mutex> lock(map_->mutex());
    // The sessions loaded, and this one when it made a keyframe.
    if (map_->num_keyframes() == 0) throw ConfigError(path, "map", "a map with keyframes (this run made none)");
    std::uint64_t sessions = loaded_sessions_;  // counted on in 64 bits: no wrap to 0
    for (const auto& [id, kf] : map_->keyframes()) {
      if (map_->map_of(*kf) != 0) {  // a provisional map never merged: not saved
        ++info.unmerged_keyframes;
        continue;
      }
      ++info.keyframes;
      if (kf->session() == map_->session()) sessions = std::uint64_t(map_->session()) + 1;
    }
    if (sessions > info.keyframes)  // the reader refuses more sessions than keyframes
      throw IoError(path, std::to_string(sessions) + " sessions in a map of " +
                              std::to_string(info.keyframes) +
                              " keyframes (each session holds one at least)");
    info.sessions = static_cast<std::uint32_t>(sessions);
    const BagOf bag_of = [this](const KeyFrame& kf) { return place_ ? place_->bag_of(kf) : kf.bow(); };
    info.points = map_->num_points();
    if (resolve_output_target(path).kind == OutputTarget::Kind::kStream) {
      // A stream cannot take the sections' lengths afterwards: the file is
      // made in memory first.
      bytes = encode_map(*map_, map_settings(), info.sessions, app_json, bag_of, session_offset_ns_);
      info.bytes = bytes.size();
    } else {
      // Streamed into a temporary file beside `path`, a piece at a time.
      // The keyframes' features come back from the spill: read ahead in
      // large reads, and out of the process again every kSaveSpillDropBytes.
      const SpillReadAhead read_ahead(feature_spill_.get());
      std::size_t since_drop = 0;
      write_file_via_temp(path, [&](OutputFile& f) {
        MapByteSink sink;
        sink.append = [&](const char* d, std::size_t n) {
          f.append(d, n);
          if (feature_spill_ && (since_drop += n) >= kSaveSpillDropBytes) {
            feature_spill_->drop_from_process();
            since_drop = 0;
          }
        };
        sink.patch = [&](std::uint64_t at, const char* d, std::size_t n) { f.patch(static_cast<long long>(at), d, n); };
        info.bytes = encode_map(*map_, map_settings(), info.sessions, app_json, bag_of, session_offset_ns_, sink);
      });
    }
  }
  if (!bytes.empty()) write_file(path, bytes);
  info.save_ms = ms_since(t0);
  return info;
}

std::vector<geom::StampedPose> System::keyframe_trajectory() {
  std::lock_guard<std::mutex> lock(map_->mutex());
  std::vector<geom::StampedPose> out;
  for (const auto& [id, kf] : map_->keyframes()) {
    if (kf->bad() || map_->map_of(*kf) != 0) continue;
    const std::int64_t offset = kf->session() == map_->session() ? session_offset_ns_ : 0;
    out.push_back({kf->t_ns() + offset, kf->T_c_w().inverse()});
  }
  std::sort(out.begin(), out.end(),
            [](const geom::StampedPose& a, const geom::StampedPose& b) { return a.t_ns < b.t_ns; });
  return out;
}

void System::start_session_clock(std::int64_t t_ns) {
  session_first_t_ns_ = t_ns;
  if (!loaded_last_t_ns_ || t_ns > *loaded_last_t_ns_) return;
  // Whole seconds, so that the stamps keep their digits: the first frame
  // lands at least a second after the map's last keyframe.
  constexpr std::int64_t kSecondNs = 1'000'000'000;
  const long double gap_ns = static_cast<long double>(*loaded_last_t_ns_) - static_cast<long double>(t_ns);
  if (gap_ns > 1e18L)
    throw ConfigError("the frames", "time stamps",
                      "a recording whose clock is within 1e9 s of the saved map's (its stamps are put after the "
                      "map's)");
  const std::int64_t gap = *loaded_last_t_ns_ - t_ns;
  session_offset_ns_ = (gap / kSecondNs + 2) * kSecondNs;
}

MapSnapshot System::map_snapshot() {
  std::lock_guard<std::mutex> lock(map_->mutex());
  return snapshot_map(*map_, cam_->K, settings_.orb.scale_factor);
}

std::vector<geom::StampedPose> System::refined_trajectory() {
  std::lock_guard<std::mutex> lock(map_->mutex());
  std::vector<geom::StampedPose> out;
  out.reserve(records_.size());
  for (const FrameRecord& r : records_)
    if (map_->map_of(*r.ref) == 0) out.push_back({r.t_ns, (r.T_c_r * r.ref->T_c_w_via_tree()).inverse()});
  return out;
}

void System::post_dense_poses(bool loop_correction, bool exact) {
  dense::PoseUpdate update;
  update.loop_correction = loop_correction;
  update.exact = exact;
  {
    std::lock_guard<std::mutex> kf_lock(dense_keyframes_mutex_);
    std::lock_guard<std::mutex> lock(map_->mutex());
    for (const auto& [id, kf] : dense_keyframes_) update.T_w_c_by_id[id] = kf->T_c_w_via_tree().inverse();
  }
  dense_->update_poses(std::move(update));
}

dense::PointCloud System::point_cloud() {
  if (!dense_) return {};
  post_dense_poses(false, true);
  return dense_->corrected_cloud();
}

std::size_t System::write_point_cloud(const std::string& path) {
  if (!dense_) return 0;
  post_dense_poses(false, true);
  return dense_->write_corrected_ply(path);
}

std::size_t System::write_live_point_cloud(const std::string& path) const {
  return dense_ ? dense_->write_live_ply(path) : 0;
}

bool System::write_dense_first_loop(const std::string& before_path, const std::string& after_path) const {
  return dense_ && dense_->write_first_loop_ply(before_path, after_path);
}

dense::PointCloud System::live_point_cloud() const { return dense_ ? dense_->live_cloud() : dense::PointCloud{}; }

std::optional<dense::LoopSnapshot> System::dense_first_loop() const {
  return dense_ ? dense_->first_loop() : std::nullopt;
}

dense::DenseMapperStats System::dense_stats() const { return dense_ ? dense_->stats() : dense::DenseMapperStats{}; }

SystemMemory System::memory() {
  SystemMemory m;
  {
    std::lock_guard<std::mutex> lock(map_->mutex());
    m.map = map_->memory();
    // Every keyframe was the reference keyframe of the frame that made it.
    std::set<const KeyFrame*> culled;
    for (const FrameRecord& r : records_)
      if (r.ref->bad() && culled.insert(r.ref.get()).second) m.culled_bytes += r.ref->memory();
    m.culled_keyframes = culled.size();
  }
  if (place_) {
    m.place_database_bytes = place_->database_bytes();
    const place::Database::Counts c = place_->database_counts();
    m.place_database_words = c.words;
    m.place_database_postings = c.postings;
  }
  if (dense_) m.dense = dense_->memory();
  if (feature_spill_) {
    m.feature_spill = feature_spill_->stats();
    m.feature_spill_resident_bytes = feature_spill_->resident_bytes();
  }
  return m;
}

namespace {
std::string frame_memory_json(const FrameMemory& f) {
  std::ostringstream js;
  js << "\"pyramid\": " << f.pyramid << ", \"keypoints\": " << f.keypoints << ", \"descriptors\": " << f.descriptors
     << ", \"per_keypoint\": " << f.per_keypoint << ", \"grid\": " << f.grid << ", \"frame_object\": " << f.object
     << ", \"spilled\": " << f.spilled;
  return js.str();
}
std::string keyframe_memory_json(const KeyFrameMemory& k) {
  std::ostringstream js;
  js << "{" << frame_memory_json(k.frame) << ", \"bow\": " << k.bow << ", \"graph\": " << k.graph
     << ", \"object\": " << k.object << ", \"total\": " << k.total() << "}";
  return js.str();
}
}  // namespace

std::string to_json(const SystemMemory& m) {
  std::ostringstream js;
  js << "{\"keyframes\": " << m.map.keyframes << ", \"keyframe_bytes\": " << keyframe_memory_json(m.map.keyframe_bytes)
     << ", \"keyframes_outside_local_map\": " << m.map.keyframes_outside
     << ", \"outside_keyframe_bytes\": " << keyframe_memory_json(m.map.outside_bytes)
     << ", \"points\": " << m.map.points << ", \"point_bytes\": " << m.map.point_bytes
     << ", \"culled_keyframes\": " << m.culled_keyframes
     << ", \"culled_keyframe_bytes\": " << keyframe_memory_json(m.culled_bytes)
     << ", \"place_database_bytes\": " << m.place_database_bytes
     << ", \"place_database_words\": " << m.place_database_words
     << ", \"place_database_postings\": " << m.place_database_postings
     << ", \"dense_keyframes\": " << m.dense.keyframes << ", \"dense_keyframe_bytes\": " << m.dense.keyframe_bytes
     << ", \"dense_map_bytes\": " << m.dense.map_bytes
     << ", \"dense_keyframes_spilled\": " << m.dense.keyframes_spilled
     << ", \"dense_spilled_keyframe_bytes\": " << m.dense.spilled_keyframe_bytes
     << ", \"dense_spilled_map_bytes\": " << m.dense.spilled_map_bytes
     << ", \"keyframes_spilled\": " << m.map.keyframes_spilled
     << ", \"feature_spill_bytes\": " << m.feature_spill.live_bytes()
     << ", \"feature_spill_file_bytes\": " << m.feature_spill.file_bytes
     << ", \"feature_spill_resident_bytes\": " << m.feature_spill_resident_bytes
     << ", \"feature_spill_releases\": " << m.feature_spill.releases << "}";
  return js.str();
}

std::size_t System::num_keyframes() {
  std::lock_guard<std::mutex> lock(map_->mutex());
  return map_->num_keyframes();
}

std::size_t System::num_map_points() {
  std::lock_guard<std::mutex> lock(map_->mutex());
  return map_->num_points();
}

std::vector<Eigen::Vector3d> System::map_point_positions() {
  std::lock_guard<std::mutex> lock(map_->mutex());
  std::vector<Eigen::Vector3d> out;
  out.reserve(map_->num_points());
  for (const auto& [id, mp] : map_->points())
    if (!mp->bad()) out.push_back(mp->p_w());
  return out;
}

std::vector<System::LandmarkUse> System::landmark_uses() {
  std::lock_guard<std::mutex> lock(map_->mutex());
  std::vector<LandmarkUse> out;
  out.reserve(map_->num_points());
  for (const auto& [id, mp] : map_->points())
    if (!mp->bad()) out.push_back({id, mp->p_w(), mp->found()});
  return out;
}

MapGravity System::gravity() {
  std::lock_guard<std::mutex> lock(map_->mutex());
  return map_->gravity();
}

WheelFit System::wheels() {
  std::lock_guard<std::mutex> lock(map_->mutex());
  return map_->wheels();
}

std::vector<System::KeyFrameState> System::keyframe_states() {
  std::lock_guard<std::mutex> lock(map_->mutex());
  std::vector<KeyFrameState> out;
  for (const auto& [id, kf] : map_->keyframes())
    if (kf->motion().has_state) out.push_back({id, kf->t_ns(), kf->motion().v_w_mps, kf->motion().bias});
  return out;
}

}  // namespace pvb::slam
