// Reading map files: every length, count, id and value is checked before
// it is used, so that a truncated, damaged or hostile file gives one error
// naming the file and what is wrong (the fuzz target tests/fuzz/
// fuzz_map_file.cpp runs this reader).
#include <array>
#include <cmath>
#include <map>
#include <unordered_map>
#include <stdexcept>
#include <utility>
#include <vector>

#include "map_file_bytes.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/fnv.hpp"
#include "pvb/slam/core/map_file.hpp"

namespace pvb::slam {
namespace {

using namespace mapfile;


/// Where each section's payload lies in the file: (offset, length).
using Sections = std::vector<std::pair<std::size_t, std::size_t>>;

Sections split_sections(const std::string& b, const std::string& file) {
  if (b.size() < kMagicBytes || b.compare(0, kMagicBytes, kMagic, kMagicBytes) != 0)
    throw IoError(file, "not a map file (it does not start with PVBMAP)");
  ByteReader r(b.data() + kMagicBytes, b.size() - kMagicBytes, file, "file header", kMagicBytes);
  const std::uint32_t version = r.u32();
  if (version > kMapFileVersion)
    throw IoError(file, "map file version " + std::to_string(version) + " is newer than this build reads (" +
                            std::to_string(kMapFileVersion) + ")");
  if (version == 0) throw IoError(file, "map file version 0 does not exist");
  const std::uint32_t count = r.u32();
  if (count != kSections.size())
    r.fail(std::to_string(count) + " sections, expected " + std::to_string(kSections.size()));
  Sections out(kSections.size());
  for (std::size_t s = 0; s < kSections.size(); ++s) {
    const std::string tag(r.bytes(4), 4);
    if (tag != kSections[s]) r.fail("section " + std::to_string(s) + " is not " + kSections[s]);
    const std::uint64_t length = r.u64();
    if (length > r.remaining()) r.fail(std::string(kSections[s]) + " is cut short (the file is truncated)");
    out[s].first = b.size() - r.remaining();
    out[s].second = length;
    const char* payload = r.bytes(length);
    if (r.u64() != fnv1a64(payload, length))
      r.fail(std::string(kSections[s]) + " checksum does not match (the file is damaged)");
  }
  if (!r.at_end()) r.fail(std::to_string(r.remaining()) + " bytes after the last section");
  return out;
}

ByteReader reader_for(const std::string& b, const Sections& s, std::size_t i, const std::string& file) {
  return ByteReader(b.data() + s[i].first, s[i].second, file, kSections[i], s[i].first);
}

void check_settings(ByteReader& r, const MapSettings& s) {
  for (double v : {s.fx, s.fy, s.bf})
    if (!(std::isfinite(v) && v > 0)) r.fail("fx, fy and bf must be finite and positive");
  if (s.width < 8 || s.height < 8 || s.width > 8192 || s.height > 8192) r.fail("image size out of range");
  if (!(std::isfinite(s.cx) && std::isfinite(s.cy) && s.cx >= 0 && s.cy >= 0 && s.cx < s.width && s.cy < s.height))
    r.fail("principal point outside the image");
  for (double d : s.distortion)
    if (!(std::isfinite(d) && std::abs(d) <= 100)) r.fail("distortion out of range");
  if (!(std::isfinite(s.th_depth_m) && s.th_depth_m > 0)) r.fail("depth threshold must be positive");
  if (!(std::isfinite(s.depth_factor) && s.depth_factor > 0)) r.fail("depth factor must be positive");
  if (!(std::isfinite(s.scale_factor) && s.scale_factor > 1 && s.scale_factor <= 4)) r.fail("bad scale factor");
  if (s.num_levels < 1 || s.num_levels > 32 || s.num_features > kMaxKeypoints) r.fail("bad ORB settings");
}

MapFileHeader parse_head(ByteReader r) {
  MapFileHeader h;
  h.version = kMapFileVersion;
  MapSettings& s = h.settings;
  for (double* v : {&s.fx, &s.fy, &s.cx, &s.cy, &s.bf}) *v = r.f64();
  s.width = r.u32();
  s.height = r.u32();
  for (double& d : s.distortion) d = r.f64();
  s.th_depth_m = r.f64();
  s.depth_factor = r.f64();
  s.scale_factor = r.f64();
  s.num_levels = r.u32();
  s.num_features = r.u32();
  s.vocabulary = r.u64();
  h.sessions = r.u32();
  if (!r.at_end()) r.fail("longer than its fields");
  check_settings(r, s);
  if (h.sessions < 1) r.fail("a map holds at least one session");
  return h;
}

geom::SE3d read_pose(ByteReader& r) {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = r.f64();
  for (int i = 0; i < 3; ++i) t(i) = r.f64();
  if (!R.allFinite() || !t.allFinite()) r.fail("a pose is not finite");
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0)
    r.fail("a pose's rotation is not a rotation");
  return geom::make_se3(R, t);
}

/// The keypoints of one keyframe, after its id, time, session and pose;
/// their point ids in *point_ids.
Frame read_frame(ByteReader& r, std::uint64_t frame_id, std::int64_t t_ns,
                 const std::shared_ptr<const CameraModel>& cam, std::vector<std::uint64_t>* point_ids) {
  const std::uint32_t n = r.u32();
  if (n > kMaxKeypoints || n * kKeypointBytes > r.remaining()) r.fail(std::to_string(n) + " keypoints do not fit");
  std::vector<cv::Point2f> keys(n);
  std::vector<Keypoint> keys_un(n);
  std::vector<float> depth(n);
  cv::Mat desc(static_cast<int>(n), 32, CV_8U);
  point_ids->assign(n, kNone);
  for (std::uint32_t i = 0; i < n; ++i) {
    float v[7];  // x, y, undistorted x, y, angle, two reserved
    for (float& x : v) x = r.f32();
    const std::uint8_t octave = r.u8();
    depth[i] = r.f32();
    (*point_ids)[i] = r.u64();
    std::memcpy(desc.ptr<unsigned char>(static_cast<int>(i)), r.bytes(32), 32);
    for (float x : v)
      if (!std::isfinite(x)) r.fail("keypoint " + std::to_string(i) + " has a value that is not finite");
    if (!std::isfinite(depth[i])) r.fail("keypoint " + std::to_string(i) + " has a depth that is not finite");
    if (octave >= cam->num_levels) r.fail("keypoint " + std::to_string(i) + " has octave " + std::to_string(octave));
    keys[i] = cv::Point2f(v[0], v[1]);
    keys_un[i] = Keypoint{cv::Point2f(v[2], v[3]), v[4], octave};
  }
  return Frame::from_saved(frame_id, t_ns, std::move(keys), std::move(keys_un), desc, std::move(depth), cam);
}

using PointIdsByKf = std::map<std::uint64_t, std::vector<std::uint64_t>>;

PointIdsByKf read_keyframes(ByteReader r, const std::shared_ptr<const CameraModel>& cam, std::uint32_t sessions,
                            Map* map) {
  PointIdsByKf ids;
  const std::uint64_t n = r.count(kKeyframeHeadBytes, "keyframes");
  for (std::uint64_t k = 0; k < n; ++k) {
    const std::uint64_t id = r.u64();
    if (id == kNone || map->keyframes().count(id)) r.fail("keyframe id " + std::to_string(id) + " given twice");
    const std::uint64_t frame_id = r.u64();
    const std::int64_t t_ns = r.i64();
    const std::uint32_t session = r.u32();
    if (session >= sessions)
      r.fail("keyframe " + std::to_string(id) + " of session " + std::to_string(session) + " in a map of " +
             std::to_string(sessions));
    const geom::SE3d T_c_w = read_pose(r);
    std::vector<std::uint64_t> point_ids;
    Frame f = read_frame(r, frame_id, t_ns, cam, &point_ids);
    f.T_c_w = T_c_w;
    f.has_pose = true;
    auto kf = map->add_loaded_keyframe(id, f);
    kf->set_session(session);
    ids[id] = std::move(point_ids);
  }
  if (!r.at_end()) r.fail("longer than its keyframes");
  return ids;
}

struct SavedPoint {
  Eigen::Vector3d p_w;
  std::uint64_t ref = kNone, first = 0;
  std::int32_t visible = 0, found = 0;
};

std::map<std::uint64_t, SavedPoint> read_points(ByteReader r, const Map& map) {
  std::map<std::uint64_t, SavedPoint> out;
  const std::uint64_t n = r.count(8 + 24 + 8 + 8 + 8, "points");
  for (std::uint64_t k = 0; k < n; ++k) {
    const std::uint64_t id = r.u64();
    SavedPoint p;
    for (int i = 0; i < 3; ++i) p.p_w(i) = r.f64();
    p.ref = r.u64();
    p.first = r.u64();
    p.visible = r.i32();
    p.found = r.i32();
    const auto fail = [&](const std::string& why) { r.fail("point " + std::to_string(id) + why); };
    // Saved in id order: a hint at the end makes each insertion constant time.
    const bool after_last = out.empty() || out.rbegin()->first < id;
    if (id == kNone || (!after_last && out.count(id))) fail(" given twice");
    if (!p.p_w.allFinite()) fail(" has a position that is not finite");
    if (p.ref != kNone && !map.keyframes().count(p.ref))
      fail(": its reference keyframe " + std::to_string(p.ref) + " is not in the map");
    if (p.visible < 0 || p.found < 0) fail(" has negative counts");
    out.emplace_hint(after_last ? out.end() : out.lower_bound(id), id, p);
  }
  if (!r.at_end()) r.fail("longer than its points");
  return out;
}

/// Creates the points and their observations from the keyframes' side.
void link_points(ByteReader r, const PointIdsByKf& ids, const std::map<std::uint64_t, SavedPoint>& saved, Map* map) {
  std::unordered_map<std::uint64_t, std::uint64_t> first_observer;
  first_observer.reserve(saved.size());
  for (const auto& [kf_id, pids] : ids)
    for (std::uint64_t pid : pids)
      if (pid != kNone) first_observer.emplace(pid, kf_id);
  for (const auto& [id, p] : saved) {
    const auto obs = first_observer.find(id);
    if (obs == first_observer.end()) r.fail("point " + std::to_string(id) + " is observed by no keyframe");
    const std::uint64_t ref = p.ref != kNone ? p.ref : obs->second;
    map->add_loaded_point(id, p.p_w, map->keyframes().at(ref))->restore(p.first, p.visible, p.found);
  }
  for (const auto& [kf_id, pids] : ids) {
    const auto& kf = map->keyframes().at(kf_id);
    for (std::size_t i = 0; i < pids.size(); ++i) {
      if (pids[i] == kNone) continue;
      const auto it = map->points().find(pids[i]);
      const auto fail = [&](const char* what) {  // the message is built only for a bad file
        r.fail("keyframe " + std::to_string(kf_id) + ", keypoint " + std::to_string(i) + ": point " +
               std::to_string(pids[i]) + what);
      };
      if (it == map->points().end()) fail(" is not in the map");
      if (it->second->observations().count(kf_id)) fail(" seen twice");  // linked at an earlier keypoint
      kf->set_map_point(i, it->second);
      it->second->add_observation(kf, i);
    }
  }
  for (const auto& [id, mp] : map->points()) {
    mp->compute_distinctive_descriptor();
    mp->update_normal_and_depth();
  }
}

void read_graph(ByteReader r, Map* map) {
  const auto& kfs = map->keyframes();
  const std::uint64_t n = r.count(8 + 8 + 8 + 8, "graph entries");
  if (n != kfs.size()) r.fail(std::to_string(n) + " graph entries for " + std::to_string(kfs.size()) + " keyframes");
  const auto keyframe = [&](std::uint64_t id, std::uint64_t self, const char* what) {
    const auto it = kfs.find(id);
    if (it == kfs.end() || id == self)
      r.fail("keyframe " + std::to_string(self) + ": " + what + " " + std::to_string(id) + " is not another keyframe");
    return it->second;
  };
  for (auto it = kfs.begin(); it != kfs.end(); ++it) {
    const std::uint64_t id = r.u64();
    if (id != it->first) r.fail("graph entry for keyframe " + std::to_string(id) + " out of order");
    const std::uint64_t parent_id = r.u64();
    const auto parent = parent_id == kNone ? nullptr : keyframe(parent_id, id, "parent");
    std::vector<std::pair<std::shared_ptr<KeyFrame>, int>> edges(r.count(12, "edges"));
    for (auto& [kf, w] : edges) {
      kf = keyframe(r.u64(), id, "neighbour");
      w = r.i32();
      if (w <= 0) r.fail("keyframe " + std::to_string(id) + ": an edge of weight " + std::to_string(w));
    }
    std::vector<std::shared_ptr<KeyFrame>> loops(r.count(8, "loop edges"));
    for (auto& kf : loops) kf = keyframe(r.u64(), id, "loop edge");
    it->second->restore_graph(parent, edges, loops);
  }
  if (!r.at_end()) r.fail("longer than its graph");
}

/// The bags of words and direct indices, in keyframe order.
void read_bows(ByteReader r, Map* map) {
  for (const auto& [id, kf] : map->keyframes()) {
    const std::string what = "keyframe " + std::to_string(id);
    place::BowVector bow;
    const std::uint64_t words = r.count(12, "words");
    for (std::uint64_t k = 0; k < words; ++k) {
      const std::uint32_t word = r.u32();
      const double weight = r.f64();
      if (!(std::isfinite(weight) && weight >= 0) || (!bow.empty() && bow.back().first >= word))
        r.fail(what + ": word " + std::to_string(word) + " out of order, repeated or weighted " +
               std::to_string(weight));
      bow.emplace_back(word, weight);
    }
    place::FeatureVector features;
    const std::uint64_t nodes = r.count(12, "nodes");
    for (std::uint64_t k = 0; k < nodes; ++k) {
      const std::uint32_t node = r.u32();
      std::vector<std::uint32_t> indices(r.count(4, "keypoint indices"));
      for (std::uint32_t& i : indices) {
        i = r.u32();
        if (i >= kf->frame().size()) r.fail(what + ": keypoint " + std::to_string(i) + " of node " + std::to_string(node));
      }
      if (!features.empty() && features.back().first >= node)
        r.fail(what + ": node " + std::to_string(node) + " out of order or repeated");
      features.emplace_back(node, std::move(indices));
    }
    kf->set_bow(std::move(bow), std::move(features));
  }
  if (!r.at_end()) r.fail("longer than its bags of words");
}

}  // namespace

MapFileHeader read_map_header(const std::string& bytes, const std::string& file) {
  const Sections s = split_sections(bytes, file);
  MapFileHeader h = parse_head(reader_for(bytes, s, 0, file));
  h.app_json.assign(bytes, s[5].first, s[5].second);
  h.sections = s;
  return h;
}

void decode_map(const std::string& bytes, const std::string& file, const MapFileHeader& h,
                const std::shared_ptr<const CameraModel>& cam, Map* map) {
  const Sections& s = h.sections;
  if (s.size() != kSections.size()) throw std::logic_error("decode_map: a header not from read_map_header");
  const PointIdsByKf ids = read_keyframes(reader_for(bytes, s, 1, file), cam, h.sessions, map);
  if (map->keyframes().empty()) throw IoError(file, "the map has no keyframes");
  const auto saved = read_points(reader_for(bytes, s, 2, file), *map);
  link_points(reader_for(bytes, s, 2, file), ids, saved, map);
  read_graph(reader_for(bytes, s, 3, file), map);
  read_bows(reader_for(bytes, s, 4, file), map);
}

}  // namespace pvb::slam
