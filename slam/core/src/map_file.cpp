#include "pvb/slam/core/map_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "map_file_bytes.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/fnv.hpp"
#include "pvb/common/text.hpp"

namespace pvb::slam {
namespace {

using namespace mapfile;


void put_settings(ByteWriter& w, const MapSettings& s, std::uint32_t sessions) {
  for (double v : {s.fx, s.fy, s.cx, s.cy, s.bf}) w.f64(v);
  w.u32(s.width);
  w.u32(s.height);
  for (double v : s.distortion) w.f64(v);
  w.f64(s.th_depth_m);
  w.f64(s.depth_factor);
  w.f64(s.scale_factor);
  w.u32(s.num_levels);
  w.u32(s.num_features);
  w.u64(s.vocabulary);
  w.u32(sessions);
}

void put_pose(ByteWriter& w, const geom::SE3d& T) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) w.f64(T.linear()(r, c));
  for (int r = 0; r < 3; ++r) w.f64(T.translation()(r));
}

/// Ids in ascending order (of the keyframes or points saved).
using SortedIds = std::vector<std::uint64_t>;
bool has(const SortedIds& ids, std::uint64_t id) { return std::binary_search(ids.begin(), ids.end(), id); }

void put_keyframe(ByteWriter& w, const KeyFrame& kf, const SortedIds& point_ids, std::int64_t offset_ns) {
  const Frame& f = kf.frame();
  w.u64(kf.id());
  w.u64(f.id);
  w.i64(f.t_ns + offset_ns);
  w.u32(kf.session());
  put_pose(w, kf.T_c_w());
  w.u32(static_cast<std::uint32_t>(f.size()));
  for (std::size_t i = 0; i < f.size(); ++i) {
    const cv::Point2f& k = f.keys[i];
    const Keypoint& u = f.keys_un[i];
    // Two reserved floats, written as 0 (ORB's size and response: never
    // read after extraction, so a frame does not keep them).
    for (float v : {k.x, k.y, u.pt.x, u.pt.y, u.angle, 0.0f, 0.0f}) w.f32(v);
    w.u8(static_cast<std::uint8_t>(u.octave));
    w.f32(f.depth_m[i]);
    const auto& mp = f.map_points[i];
    // A keyframe can hold a point at a second keypoint after fusion; the
    // point's own observation says which one counts.
    const bool observed = mp && !mp->bad() && has(point_ids, mp->id()) &&
                          mp->index_in(kf.id()) == static_cast<long>(i);
    w.u64(observed ? mp->id() : kNone);
    w.bytes(f.descriptors.ptr<unsigned char>(static_cast<int>(i)), 32);
  }
}

void put_graph(ByteWriter& w, const KeyFrame& kf, const SortedIds& kf_ids) {
  w.u64(kf.id());
  const auto parent = kf.parent();
  w.u64(parent && has(kf_ids, parent->id()) ? parent->id() : kNone);
  std::vector<std::pair<std::uint64_t, int>> edges;
  for (const auto& [id, weight] : kf.connection_weights())
    if (has(kf_ids, id)) edges.emplace_back(id, weight);
  w.u64(edges.size());
  for (const auto& [id, weight] : edges) {
    w.u64(id);
    w.i32(weight);
  }
  std::vector<std::uint64_t> loops;
  for (const auto& k : kf.loop_edges())
    if (has(kf_ids, k->id())) loops.push_back(k->id());
  w.u64(loops.size());
  for (std::uint64_t id : loops) w.u64(id);
}

/// The id of a keyframe in the file that observes `mp` at the keypoint its
/// observation names (the reader links points from the keyframes' side),
/// `preferred` when it is one; kNone when none is.
std::uint64_t saved_observer(const MapPoint& mp, const SortedIds& kf_ids, std::uint64_t preferred) {
  const auto observes = [&](std::uint64_t kf_id, const MapPoint::Obs& o) {
    const auto kf = o.kf.lock();
    return kf && has(kf_ids, kf_id) && kf->map_points()[o.idx].get() == &mp;
  };
  const auto& obs = mp.observations();
  if (const auto it = obs.find(preferred); it != obs.end() && observes(it->first, it->second))
    return preferred;
  for (const auto& [kf_id, o] : obs)
    if (observes(kf_id, o)) return kf_id;
  return kNone;
}

void put_point(ByteWriter& w, const MapPoint& mp, const SortedIds& kf_ids) {
  w.u64(mp.id());
  for (int r = 0; r < 3; ++r) w.f64(mp.p_w()(r));
  // The reference keyframe when it is saved and observes the point (else
  // none: the reader takes the first observer).
  const auto ref = mp.reference_keyframe();
  const bool ref_saved = ref && !ref->bad() && saved_observer(mp, kf_ids, ref->id()) == ref->id();
  w.u64(ref_saved ? ref->id() : kNone);
  // The keyframe that made the point; when it was culled, an observer
  // that is saved stands for it (the id only orders the culling of recent
  // points within the session that made them).
  w.u64(has(kf_ids, mp.first_kf_id()) ? mp.first_kf_id()
                                      : saved_observer(mp, kf_ids, ref ? ref->id() : kNone));
  w.i32(mp.visible());
  w.i32(mp.found());
}

/// The keyframe's bag of words and direct index (as the place database and
/// relocalisation use them): recomputing them is most of a load's time.
void put_bow(ByteWriter& w, const KeyFrame& kf, const BagOf& bag_of) {
  const place::BowVector bow = bag_of ? bag_of(kf) : kf.bow();
  w.u64(bow.size());
  for (const auto& [word, weight] : bow) {
    w.u32(word);
    w.f64(weight);
  }
  w.u64(kf.features_by_node().size());
  for (const auto& [node, indices] : kf.features_by_node()) {
    w.u32(node);
    w.u64(indices.size());
    for (std::uint32_t i : indices) w.u32(i);
  }
}

void put_vector(ByteWriter& w, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) w.f64(v(i));
}

void put_bias(ByteWriter& w, const ImuBias& b) {
  put_vector(w, b.gyro_radps);
  put_vector(w, b.accel_mps2);
}

/// The keyframe before `kf` in time when the file can name it: saved, of
/// `kf`'s session, older (id and time) and naming `kf` as its next; else
/// kNone (the chain breaks there).
std::uint64_t saved_prev(const KeyFrame& kf, const SortedIds& kf_ids) {
  const auto prev = kf.motion().prev.lock();
  const bool named = prev && !prev->bad() && has(kf_ids, prev->id()) && prev->id() < kf.id() &&
                     prev->t_ns() < kf.t_ns() && prev->session() == kf.session() &&
                     prev->motion().next.lock().get() == &kf;
  return named ? prev->id() : kNone;
}

/// INER: the setup, gravity, the extrinsics, then per keyframe its
/// predecessor in time and its state (a state the reader would refuse is
/// written as none).
void put_inertial(ByteWriter& w, const Map& map, const MapSettings& s,
                  const std::vector<std::shared_ptr<KeyFrame>>& kfs, const SortedIds& kf_ids) {
  const MapGravity& g = map.gravity();
  w.u32(sensor_code(s.sensors));
  put_vector(w, g.g_w);
  put_pose(w, s.T_b_c);
  if (uses_wheels(s.sensors)) put_pose(w, s.T_base_c);
  put_bias(w, bias_in_range(g.bias) ? g.bias : ImuBias{});
  w.u64(g.ready_keyframe_id);
  w.i64(g.ready_t_ns);
  w.f64(std::isfinite(g.init_rms) && g.init_rms >= 0 ? g.init_rms : 0.0);
  w.u64(kfs.size());
  for (const auto& kf : kfs) {
    const KeyFrameMotion& m = kf->motion();
    const bool state = m.has_state && speed_in_range(m.v_w_mps) && bias_in_range(m.bias);
    w.u64(kf->id());
    w.u64(saved_prev(*kf, kf_ids));
    w.u8(state ? 1 : 0);
    put_vector(w, state ? m.v_w_mps : Eigen::Vector3d::Zero());
    put_bias(w, state ? m.bias : ImuBias{});
  }
}

/// Whether the map's wheel calibration goes into the file (version 3):
/// with the inertial state, for a setup with wheels, once an interval was
/// fitted, and only what the reader takes.
bool saves_wheels(const Map& map, const MapSettings& s) {
  const WheelFit& f = map.wheels();
  const WheelFitSums& m = f.sums;
  const auto described = [](double v) { return v > 0 && v <= kMaxWheelDescriptionM; };
  return uses_wheels(s.sensors) && f.intervals > 0 && f.refused >= 0 && described(f.described_track_m) &&
         described(f.described_radius_m) && wheel_scale_in_range(f.calibration.left_scale) &&
         wheel_scale_in_range(f.calibration.right_scale) && wheel_scale_in_range(f.calibration.track_scale) &&
         std::isfinite(f.rolled_m) && f.rolled_m >= 0 && std::isfinite(f.turned_rad) && f.turned_rad >= 0 &&
         m.turn_normal.allFinite() && m.turn_rhs.allFinite() &&
         Eigen::Matrix<double, 5, 1>(m.mm, m.mn, m.nn, m.am, m.an).allFinite();
}

/// WHEL: the description the fit was taken with, the fit, what it rests
/// on, and the calibrator's sums (to go on fitting in a later session).
void put_wheels(ByteWriter& w, const WheelFit& f) {
  w.f64(f.described_radius_m);
  w.f64(f.described_track_m);
  for (double v : {f.calibration.left_scale, f.calibration.right_scale, f.calibration.track_scale}) w.f64(v);
  w.u8(f.radii_known ? 1 : 0);
  w.u8(f.track_known ? 1 : 0);
  w.u32(static_cast<std::uint32_t>(f.intervals));
  w.u32(static_cast<std::uint32_t>(f.refused));
  w.f64(f.rolled_m);
  w.f64(f.turned_rad);
  const WheelFitSums& m = f.sums;
  for (double v : {m.turn_normal(0, 0), m.turn_normal(0, 1), m.turn_normal(1, 1), m.turn_rhs(0), m.turn_rhs(1),
                   m.mm, m.mn, m.nn, m.am, m.an})
    w.f64(v);
}

/// Whether the map's inertial state goes into the file (version 2).
bool saves_inertial(const Map& map, const MapSettings& s) {
  if (!map.gravity().ready || !uses_accel(s.sensors) || !gravity_in_range(map.gravity().g_w)) return false;
  if (!rigid_in_range(s.T_b_c) || (uses_wheels(s.sensors) && !rigid_in_range(s.T_base_c)))
    throw std::logic_error("encode_map: an extrinsic transform that is not rigid or lies beyond 10 m");
  return true;
}

/// Sections written to a sink as their payloads grow: the tag, a length
/// patched in once the payload is done, the payload a piece at a time, its
/// checksum.
class SectionStream {
 public:
  static constexpr std::size_t kPieceBytes = std::size_t(1) << 20;
  explicit SectionStream(const MapByteSink& sink) : sink_(sink) {}
  /// Bytes outside any section (the file header).
  void raw(const std::string& bytes) {
    sink_.append(bytes.data(), bytes.size());
    at_ += bytes.size();
  }
  void begin(const char* tag) {
    ByteWriter head;
    head.bytes(tag, 4);
    head.u64(0);  // the length, patched by end()
    length_at_ = at_ + 4;
    raw(head.data());
    length_ = 0;
    fnv_ = kFnv1a64Offset;
  }
  ByteWriter& w() { return w_; }
  void flush_if_full() {
    if (w_.data().size() >= kPieceBytes) flush();
  }
  void end() {
    flush();
    ByteWriter n;
    n.u64(length_);
    sink_.patch(length_at_, n.data().data(), 8);
    ByteWriter sum;
    sum.u64(fnv_);
    raw(sum.data());
  }
  std::uint64_t bytes() const { return at_; }

 private:
  void flush() {
    const std::string& d = w_.data();
    fnv_ = fnv1a64(d.data(), d.size(), fnv_);
    length_ += d.size();
    raw(d);
    w_.clear();
  }
  const MapByteSink& sink_;
  ByteWriter w_;
  std::uint64_t at_ = 0, length_at_ = 0, length_ = 0, fnv_ = kFnv1a64Offset;
};

/// "NAME: the map's and this run's differ by X mm and Y deg (...)" when
/// they differ by more than kMaxExtrinsicShiftM or kMaxExtrinsicTurnDeg;
/// empty when they agree.
std::string extrinsic_difference(const char* name, const char* sensor, const geom::SE3d& in_map,
                                 const geom::SE3d& in_run) {
  const double shift_m = (in_map.translation() - in_run.translation()).norm();
  const Eigen::Matrix3d dR = in_map.linear().transpose() * in_run.linear();
  const double turn_deg = Eigen::AngleAxisd(dR).angle() * 180.0 / M_PI;
  if (shift_m <= kMaxExtrinsicShiftM && turn_deg <= kMaxExtrinsicTurnDeg) return {};
  return std::string(name) + ": the map's and this run's differ by " + format_fixed(shift_m * 1e3, 2) +
         " mm and " + format_fixed(turn_deg, 3) + " deg (at most " + format_g(kMaxExtrinsicShiftM * 1e3) +
         " mm and " + format_g(kMaxExtrinsicTurnDeg) + " deg when both use the " + sensor + ")";
}

}  // namespace

std::uint64_t encode_map(const Map& map, const MapSettings& settings, std::uint32_t sessions,
                         const std::string& app_json, const BagOf& bag_of, std::int64_t session_offset_ns,
                         const MapByteSink& sink) {
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  SortedIds kf_ids;  // the maps iterate in id order
  for (const auto& [id, kf] : map.keyframes())
    if (!kf->bad() && map.map_of(*kf) == 0) {
      kfs.push_back(kf);
      kf_ids.push_back(id);
    }
  // Each session counted holds a keyframe (the reader checks it).
  if (sessions < 1 || sessions > kfs.size())
    throw std::logic_error("encode_map: " + std::to_string(sessions) + " sessions for " +
                           std::to_string(kfs.size()) + " keyframes");
  // A point no keyframe of the file names (seen only by keyframes left out)
  // is left out too: the reader links points from the keyframes' side.  So
  // is a point beyond kMaxMapCoordinateM (triangulated from nearly parallel
  // rays), which the reader would refuse.
  SortedIds point_ids;
  for (const auto& [id, mp] : map.points())
    if (!mp->bad() && within_map_bounds(mp->p_w()) && saved_observer(*mp, kf_ids, kNone) != kNone)
      point_ids.push_back(id);
  const bool inertial = saves_inertial(map, settings);
  const bool wheels = inertial && saves_wheels(map, settings);
  const std::uint32_t version =
      wheels ? kMapFileVersion : inertial ? kMapFileVersionInertial : kMapFileVersionVisual;
  const std::vector<const char*> tags = section_tags(version);

  SectionStream out(sink);
  ByteWriter file_head;
  file_head.bytes(kMagic, kMagicBytes);
  file_head.u32(version);
  file_head.u32(static_cast<std::uint32_t>(tags.size()));
  out.raw(file_head.data());
  ByteWriter& w = out.w();
  out.begin("HEAD");
  put_settings(w, settings, sessions);
  out.end();
  out.begin("KEYF");
  w.u64(kfs.size());
  for (const auto& kf : kfs) {
    put_keyframe(w, *kf, point_ids, kf->session() == map.session() ? session_offset_ns : 0);
    out.flush_if_full();
  }
  out.end();
  out.begin("POIN");
  w.u64(point_ids.size());
  for (std::uint64_t id : point_ids) put_point(w, *map.points().at(id), kf_ids), out.flush_if_full();
  out.end();
  out.begin("GRAP");
  w.u64(kfs.size());
  for (const auto& kf : kfs) put_graph(w, *kf, kf_ids), out.flush_if_full();
  out.end();
  out.begin("BOWV");
  for (const auto& kf : kfs) put_bow(w, *kf, bag_of), out.flush_if_full();
  out.end();
  if (inertial) {
    out.begin("INER");
    put_inertial(w, map, settings, kfs, kf_ids);
    out.end();
  }
  if (wheels) {
    out.begin("WHEL");
    put_wheels(w, map.wheels());
    out.end();
  }
  out.begin("META");
  w.bytes(app_json.data(), app_json.size());
  out.end();
  return out.bytes();
}

std::string encode_map(const Map& map, const MapSettings& settings, std::uint32_t sessions,
                       const std::string& app_json, const BagOf& bag_of, std::int64_t session_offset_ns) {
  std::string bytes;
  MapByteSink sink;
  sink.append = [&](const char* d, std::size_t n) { bytes.append(d, n); };
  sink.patch = [&](std::uint64_t at, const char* d, std::size_t n) { std::memcpy(&bytes[at], d, n); };
  encode_map(map, settings, sessions, app_json, bag_of, session_offset_ns, sink);
  return bytes;
}

std::string MapSettings::difference(const MapSettings& run) const {
  std::ostringstream o;
  o.precision(17);
  const auto differs = [&](const char* name, double in_map, double in_run) {
    if (in_map == in_run) return false;
    o << name << ": " << in_map << " in the map, " << in_run << " in this run";
    return true;
  };
  const char* dist_names[] = {"k1", "k2", "p1", "p2", "k3"};
  if (differs("fx", fx, run.fx) || differs("fy", fy, run.fy) || differs("cx", cx, run.cx) ||
      differs("cy", cy, run.cy) || differs("bf", bf, run.bf) || differs("width", width, run.width) ||
      differs("height", height, run.height))
    return o.str();
  for (int i = 0; i < 5; ++i)
    if (differs(dist_names[i], distortion[i], run.distortion[i])) return o.str();
  // DepthMapFactor is recorded but not compared: it says how a source's raw
  // depth becomes metres (5000 for TUM PNGs, 1000 for a Kinect's
  // millimetres), and the map holds metres.
  if (differs("ThDepth (m)", th_depth_m, run.th_depth_m) ||
      differs("ORBextractor.scaleFactor", scale_factor, run.scale_factor) ||
      differs("ORBextractor.nLevels", num_levels, run.num_levels) ||
      differs("ORBextractor.nFeatures", num_features, run.num_features))
    return o.str();
  if (vocabulary != run.vocabulary) {
    o << "vocabulary: fingerprint " << std::hex << vocabulary << " in the map, " << run.vocabulary
      << " in this run (another vocabulary)";
    return o.str();
  }
  // The setup is not compared: either side without the sensor leaves the
  // other's state unused.  Extrinsics are, where both use them.
  if (uses_accel(sensors) && uses_accel(run.sensors))
    if (std::string d = extrinsic_difference("IMU.T_b_c1", "IMU", T_b_c, run.T_b_c); !d.empty()) return d;
  if (uses_wheels(sensors) && uses_wheels(run.sensors))
    if (std::string d = extrinsic_difference("Robot.T_base_c1", "wheels", T_base_c, run.T_base_c); !d.empty())
      return d;
  return {};
}

std::shared_ptr<const CameraModel> camera_for(const MapSettings& s) {
  StereoIntrinsics K;
  K.fx = s.fx;
  K.fy = s.fy;
  K.cx = s.cx;
  K.cy = s.cy;
  K.bf = s.bf;
  const std::vector<double> dist(s.distortion.begin(), s.distortion.end());
  return std::make_shared<const CameraModel>(CameraModel::make(K, static_cast<int>(s.width),
                                                               static_cast<int>(s.height), dist, s.th_depth_m,
                                                               s.scale_factor, static_cast<int>(s.num_levels)));
}

}  // namespace pvb::slam
