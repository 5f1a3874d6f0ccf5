// Reading map files: every length, count, id and value is checked before
// it is used, so that a truncated, damaged or hostile file gives one error
// naming the file and what is wrong (the fuzz target tests/fuzz/
// fuzz_map_file.cpp runs this reader).
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <unordered_map>
#include <utility>
#include <vector>

#include "map_file_bytes.hpp"
#include "map_file_read.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/fnv.hpp"
#include "pvb/common/text.hpp"
#include "pvb/slam/core/map_file.hpp"

namespace pvb::slam {
namespace {

using namespace mapfile;

/// Where each section's payload lies in the file: (offset, length).
using Sections = std::vector<std::pair<std::uint64_t, std::uint64_t>>;

/// Reads up to `n` bytes at `offset` of the file (fewer at its end).
using ReadAt = std::function<std::string(std::uint64_t offset, std::uint64_t n)>;

std::uint64_t le64(const std::string& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t(static_cast<unsigned char>(b[at + i])) << (8 * i);
  return v;
}

/// The file header: magic, version, section count; returns the version.
std::uint32_t check_file_header(const std::string& head, const std::string& file) {
  if (head.size() < kMagicBytes || head.compare(0, kMagicBytes, kMagic, kMagicBytes) != 0)
    throw IoError(file, "not a map file (it does not start with PVBMAP)");
  ByteReader r(head.data() + kMagicBytes, head.size() - kMagicBytes, file, "file header", kMagicBytes,
               kMagicBytes);
  const std::uint32_t version = r.u32();
  if (version > kMapFileVersion)
    throw IoError(file, "map file version " + std::to_string(version) + " is newer than this build reads (" +
                            std::to_string(kMapFileVersion) + ")");
  if (version == 0) throw IoError(file, "map file version 0 does not exist");
  const std::uint32_t count = r.u32();
  const std::size_t expected = section_tags(version).size();
  if (count != expected)
    r.fail(std::to_string(count) + " sections, expected " + std::to_string(expected) + " in a version-" +
           std::to_string(version) + " file");
  return version;
}

/// A file's version and where each section's payload lies.
struct Framing {
  std::uint32_t version = 0;
  Sections sections;
};

/// The sections of a file of `size` bytes, from the file header and each
/// section's tag and length alone (16 bytes, then 12 a section): their
/// lengths must add up to the file's size.
Framing frame_sections(const ReadAt& read_at, std::uint64_t size, const std::string& file) {
  Framing framing;
  framing.version = check_file_header(read_at(0, kMagicBytes + 8), file);
  const std::vector<const char*> tags = section_tags(framing.version);
  Sections& out = framing.sections;
  out.resize(tags.size());
  std::uint64_t at = kMagicBytes + 8;  // where the section begins
  for (std::size_t s = 0; s < tags.size(); ++s) {
    const std::string label = std::string(tags[s]) + " section";
    const auto fail = [&](std::uint64_t offset, const std::string& what) {
      throw IoError(file, ByteReader::where(label, offset, at + offset) + what);
    };
    if (size - at < kSectionHeadBytes)
      fail(0, at == size ? "missing (the file ends before it)"
                         : "its tag and length are cut short (the file is truncated)");
    const std::string head = read_at(at, kSectionHeadBytes);
    if (head.compare(0, 4, tags[s]) != 0)
      fail(0, "tag \"" + printable(head.substr(0, 4)) + "\", expected " + tags[s]);
    const std::uint64_t length = le64(head, 4);
    const std::uint64_t left = size - at - kSectionHeadBytes;
    if (length > left || left - length < kSectionTailBytes)
      fail(4, "a payload of " + std::to_string(length) + " bytes and its checksum do not fit in the " +
                  std::to_string(left) + " bytes left (the file is truncated)");
    out[s] = {at + kSectionHeadBytes, length};
    at += kSectionHeadBytes + length + kSectionTailBytes;
  }
  if (at != size)
    throw IoError(file, std::to_string(size - at) + " bytes after the last section (from file byte " +
                            std::to_string(at) + ")");
  return framing;
}

/// The framing of `src`, with every section's checksum checked (read a
/// piece at a time when the bytes are in the file).
Framing split_sections(const MapFileBytes& src) {
  const std::string& file = src.name();
  const ReadAt read_at = [&](std::uint64_t offset, std::uint64_t n) {
    std::string b(static_cast<std::size_t>(std::min(n, src.size() - std::min(offset, src.size()))), '\0');
    src.read(offset, b.data(), b.size());
    return b;
  };
  const Framing framing = frame_sections(read_at, src.size(), file);
  const std::vector<const char*> tags = section_tags(framing.version);
  std::string piece;
  for (std::size_t s = 0; s < tags.size(); ++s) {
    const auto [payload, length] = framing.sections[s];
    std::uint64_t h = kFnv1a64Offset;
    if (src.data()) {
      h = fnv1a64(src.data() + payload, length);
    } else {
      for (std::uint64_t done = 0; done < length;) {
        piece.resize(static_cast<std::size_t>(std::min(length - done, src.piece_bytes())));
        src.read(payload + done, piece.data(), piece.size());
        h = fnv1a64(piece.data(), piece.size(), h);
        done += piece.size();
      }
    }
    if (le64(read_at(payload + length, 8), 0) != h)
      throw IoError(file, ByteReader::where(std::string(tags[s]) + " section", kSectionHeadBytes + length,
                                            payload + length) +
                              "checksum does not match its " + std::to_string(length) +
                              "-byte payload (the file is damaged)");
  }
  return framing;
}

/// A reader of section `i` of a file of `version`.
ByteReader reader_for(const MapFileBytes& src, const Sections& s, std::size_t i, std::uint32_t version) {
  return ByteReader(src, s[i].first, s[i].second, std::string(section_tags(version)[i]) + " section",
                    kSectionHeadBytes);
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
  const Eigen::Vector3d centre = -R.transpose() * t;
  if (!within_map_bounds(centre))
    r.fail("a camera centre at (" + format_g(centre.x()) + ", " + format_g(centre.y()) + ", " +
           format_g(centre.z()) + ") m lies beyond " + format_g(kMaxMapCoordinateM) +
           " m of the map's origin");
  return geom::make_se3(R, t);
}

/// Refuses a keypoint that a camera of the map's settings cannot have made:
/// values not finite, a position beyond the image widened by its own size
/// on every side (as detected and undistorted), an angle outside
/// 0-360 degrees, a depth beyond kMaxMapCoordinateM, an octave beyond the
/// pyramid.  `v`: x, y, undistorted x, y, angle, two reserved.
void check_keypoint(ByteReader& r, std::uint32_t i, const float (&v)[7], float depth, std::uint8_t octave,
                    const CameraModel& cam) {
  const auto bad = [&](const std::string& what) { r.fail("keypoint " + std::to_string(i) + " " + what); };
  for (int k = 0; k < 7; ++k)
    if (!std::isfinite(v[k])) bad("has a value that is not finite");
  if (!std::isfinite(depth)) bad("has a depth that is not finite");
  const double w = cam.width, h = cam.height;
  for (int k : {0, 2})
    if (!(v[k] >= -w && v[k] <= 2 * w && v[k + 1] >= -h && v[k + 1] <= 2 * h))
      bad(std::string(k == 0 ? "as detected" : "undistorted") + " at (" + format_g(v[k]) + ", " +
          format_g(v[k + 1]) + ") lies beyond the " + std::to_string(cam.width) + "x" +
          std::to_string(cam.height) + " image widened by its size on every side");
  if (!(v[4] >= 0 && v[4] <= 360)) bad("has angle " + format_g(v[4]) + ", outside 0-360 degrees");
  if (depth > kMaxMapCoordinateM)
    bad("has depth " + format_g(depth) + " m, beyond " + format_g(kMaxMapCoordinateM) + " m");
  if (octave >= cam.num_levels) bad("has octave " + std::to_string(octave));
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
    check_keypoint(r, i, v, depth[i], octave, *cam);
    keys[i] = cv::Point2f(v[0], v[1]);
    keys_un[i] = Keypoint{cv::Point2f(v[2], v[3]), v[4], octave};
  }
  return Frame::from_saved(frame_id, t_ns, std::move(keys), std::move(keys_un), desc, std::move(depth), cam);
}

using PointIdsByKf = std::map<std::uint64_t, std::vector<std::uint64_t>>;

PointIdsByKf read_keyframes(ByteReader r, const std::shared_ptr<const CameraModel>& cam, std::uint32_t sessions,
                            Map* map, const std::shared_ptr<FeatureSpill>& spill) {
  PointIdsByKf ids;
  const std::uint64_t n = r.count(kKeyframeHeadBytes, "keyframes");
  for (std::uint64_t k = 0; k < n; ++k) {
    const std::uint64_t id = r.u64();
    if (id >= kMaxId) r.fail("keyframe id " + std::to_string(id) + " is not below 2^48");
    if (map->keyframes().count(id)) r.fail("keyframe id " + std::to_string(id) + " given twice");
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
    if (spill) kf->spill_features(spill);  // written through the file: nothing of it stays in the process
  }
  if (!r.at_end()) r.fail("longer than its keyframes");
  return ids;
}

struct SavedPoint {
  Eigen::Vector3d p_w;
  std::uint64_t ref = kNone, first = 0;
  std::int32_t visible = 0, found = 0;
};

/// Refuses a point that cannot be: an id at or above 2^48, a position not
/// finite or beyond kMaxMapCoordinateM, a reference or first keyframe not
/// in the map, counts below 0, above kMaxVisible or found more often than
/// predicted visible.
void check_point(ByteReader& r, std::uint64_t id, const SavedPoint& p, const Map& map) {
  const auto fail = [&](const std::string& why) { r.fail("point " + std::to_string(id) + why); };
  if (id >= kMaxId) fail(": its id is not below 2^48");
  if (!p.p_w.allFinite()) fail(" has a position that is not finite");
  if (!within_map_bounds(p.p_w))
    fail(" at (" + format_g(p.p_w.x()) + ", " + format_g(p.p_w.y()) + ", " + format_g(p.p_w.z()) +
         ") m lies beyond " + format_g(kMaxMapCoordinateM) + " m of the map's origin");
  if (p.ref != kNone && !map.keyframes().count(p.ref))
    fail(": its reference keyframe " + std::to_string(p.ref) + " is not in the map");
  if (!map.keyframes().count(p.first))
    fail(": its first keyframe " + std::to_string(p.first) + " is not in the map");
  if (p.visible < 0 || p.found < 0) fail(" has negative counts");
  if (p.visible > kMaxVisible)
    fail(" was predicted visible " + std::to_string(p.visible) + " times, more than 2^30");
  if (p.found > p.visible)
    fail(" was found " + std::to_string(p.found) + " times but predicted visible only " +
         std::to_string(p.visible));
}

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
    // Saved in id order: a hint at the end makes each insertion constant time.
    const bool after_last = out.empty() || out.rbegin()->first < id;
    if (!after_last && out.count(id)) r.fail("point " + std::to_string(id) + " given twice");
    check_point(r, id, p, map);
    out.emplace_hint(after_last ? out.end() : out.lower_bound(id), id, p);
  }
  if (!r.at_end()) r.fail("longer than its points");
  return out;
}

/// Creates the points and their observations from the keyframes' side;
/// a point's reference keyframe must be one of them.
void link_points(ByteReader r, const PointIdsByKf& ids, const std::map<std::uint64_t, SavedPoint>& saved, Map* map,
                 FeatureSpill* spill) {
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
  for (const auto& entry : ids) {  // not a structured binding: C++17 lambdas cannot capture one
    const std::uint64_t kf_id = entry.first;
    const std::vector<std::uint64_t>& pids = entry.second;
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
  for (const auto& [id, p] : saved)
    if (p.ref != kNone && !map->points().at(id)->observations().count(p.ref))
      r.fail("point " + std::to_string(id) + ": its reference keyframe " + std::to_string(p.ref) +
             " does not observe it");
  std::size_t n = 0;
  for (const auto& [id, mp] : map->points()) {
    mp->compute_distinctive_descriptor();  // reads its observers' descriptors
    mp->update_normal_and_depth();
    if (spill && ++n % kLoadSpillDropPoints == 0) spill->drop_from_process();
  }
}

/// Refuses a spanning tree with other than one root, or with a cycle.
/// `ids`: the keyframes in ascending order; `parents`: each one's parent
/// (kNone: a root), every one a keyframe of `ids` other than itself.
void check_tree(ByteReader& r, const std::vector<std::uint64_t>& ids,
                const std::vector<std::uint64_t>& parents) {
  std::vector<std::uint64_t> roots;
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (parents[i] == kNone) roots.push_back(ids[i]);
  if (roots.size() != 1)
    r.fail("the spanning tree has " + std::to_string(roots.size()) + " roots" +
           (roots.size() > 1
                ? " (keyframes " + std::to_string(roots[0]) + " and " + std::to_string(roots[1]) + ")"
                : std::string()) +
           ", expected one");
  const auto index_of = [&](std::uint64_t id) {
    return static_cast<std::size_t>(std::lower_bound(ids.begin(), ids.end(), id) - ids.begin());
  };
  enum : std::uint8_t { kUnseen, kOnPath, kReachesRoot };
  std::vector<std::uint8_t> state(ids.size(), kUnseen);
  std::vector<std::size_t> path;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    path.clear();
    std::size_t j = i;
    while (state[j] == kUnseen) {  // up the tree until the root or a keyframe known to reach it
      state[j] = kOnPath;
      path.push_back(j);
      if (parents[j] == kNone) break;
      j = index_of(parents[j]);
    }
    if (state[j] == kOnPath && parents[j] != kNone)
      r.fail("the spanning tree has a cycle through keyframe " + std::to_string(ids[j]));
    for (std::size_t k : path) state[k] = kReachesRoot;
  }
}

using KeyFrameList = std::vector<std::shared_ptr<KeyFrame>>;

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
  // Each list in ascending id order, so that none names a keyframe twice.
  const auto repeated = [&](std::uint64_t self, const char* what, std::uint64_t id) {
    r.fail("keyframe " + std::to_string(self) + ": " + what + " " + std::to_string(id) +
           " repeated or out of order");
  };
  std::vector<std::uint64_t> ids, parents;
  std::vector<std::vector<std::pair<std::shared_ptr<KeyFrame>, int>>> edges(kfs.size());
  std::vector<KeyFrameList> loops(kfs.size());
  std::size_t k = 0;
  for (auto it = kfs.begin(); it != kfs.end(); ++it, ++k) {
    const std::uint64_t id = r.u64();
    if (id != it->first) r.fail("graph entry for keyframe " + std::to_string(id) + " out of order");
    const std::uint64_t parent_id = r.u64();
    if (parent_id != kNone) keyframe(parent_id, id, "parent");
    ids.push_back(id);
    parents.push_back(parent_id);
    edges[k].resize(r.count(12, "edges"));
    for (std::size_t e = 0; e < edges[k].size(); ++e) {
      const std::uint64_t other = r.u64();
      if (e > 0 && other <= edges[k][e - 1].first->id()) repeated(id, "neighbour", other);
      edges[k][e].first = keyframe(other, id, "neighbour");
      const int w = edges[k][e].second = r.i32();
      if (w <= 0) r.fail("keyframe " + std::to_string(id) + ": an edge of weight " + std::to_string(w));
    }
    loops[k].resize(r.count(8, "loop edges"));
    for (std::size_t e = 0; e < loops[k].size(); ++e) {
      const std::uint64_t other = r.u64();
      if (e > 0 && other <= loops[k][e - 1]->id()) repeated(id, "loop edge", other);
      loops[k][e] = keyframe(other, id, "loop edge");
    }
  }
  if (!r.at_end()) r.fail("longer than its graph");
  check_tree(r, ids, parents);
  k = 0;
  for (auto it = kfs.begin(); it != kfs.end(); ++it, ++k)
    it->second->restore_graph(parents[k] == kNone ? nullptr : kfs.at(parents[k]), edges[k], loops[k]);
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
      if (!(std::isfinite(weight) && weight >= 0))
        r.fail(what + ": word " + std::to_string(word) + " has weight " + std::to_string(weight) +
               ", expected a finite weight >= 0");
      if (!bow.empty() && bow.back().first >= word)
        r.fail(what + ": word " + std::to_string(word) + " after word " + std::to_string(bow.back().first) +
               ", expected words in ascending order, each once");
      bow.emplace_back(word, weight);
    }
    place::FeatureVector features;
    const std::uint64_t nodes = r.count(12, "nodes");
    for (std::uint64_t k = 0; k < nodes; ++k) {
      const std::uint32_t node = r.u32();
      std::vector<std::uint32_t> indices(r.count(4, "keypoint indices"));
      for (std::uint32_t& i : indices) {
        i = r.u32();
        if (i >= kf->frame().size())
          r.fail(what + ": direct-index node " + std::to_string(node) + " names keypoint " + std::to_string(i) +
                 ", but the keyframe has " + std::to_string(kf->frame().size()) + " keypoints");
      }
      if (!features.empty() && features.back().first >= node)
        r.fail(what + ": direct-index node " + std::to_string(node) + " after node " +
               std::to_string(features.back().first) + ", expected nodes in ascending order, each once");
      features.emplace_back(node, std::move(indices));
    }
    kf->set_bow(std::move(bow), std::move(features));
  }
  if (!r.at_end()) r.fail("longer than its bags of words");
}

}  // namespace

std::string read_map_file(const std::string& path) {
  require_regular_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, std::string("cannot open for reading: ") + std::strerror(errno));
  in.seekg(0, std::ios::end);
  const std::streamoff end = in.tellg();
  if (end < 0) throw IoError(path, "cannot tell its size");
  const auto size = static_cast<std::uint64_t>(end);
  if (size > kMaxMapFileBytes)
    throw IoError(path, std::to_string(size) + " bytes, larger than a map file may be (" +
                            std::to_string(kMaxMapFileBytes) + " bytes, 4 GiB)");
  const ReadAt from_file = [&](std::uint64_t offset, std::uint64_t n) {
    std::string b(static_cast<std::size_t>(std::min(n, size - std::min(offset, size))), '\0');
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(b.data(), static_cast<std::streamsize>(b.size()));
    if (in.gcount() != static_cast<std::streamsize>(b.size())) throw IoError(path, "cannot read it");
    return b;
  };
  frame_sections(from_file, size, path);  // before reading the payloads
  return from_file(0, size);
}

MapFileHeader read_map_header(const MapFileBytes& src) {
  const Framing framing = split_sections(src);
  const Sections& s = framing.sections;
  MapFileHeader h = parse_head(reader_for(src, s, 0, framing.version));
  h.version = framing.version;
  if (h.version >= 2) {
    ByteReader iner = reader_for(src, s, kInerSection, h.version);
    MapGravity unused;
    read_inertial_head(iner, &h.settings, &unused);
  }
  h.app_json.resize(static_cast<std::size_t>(s.back().second));
  src.read(s.back().first, h.app_json.data(), s.back().second);
  h.sections = s;
  return h;
}

MapFileHeader read_map_header(const std::string& bytes, const std::string& file) {
  return read_map_header(MapFileBytes::in_memory(bytes, file));
}

void decode_map(const MapFileBytes& src, const MapFileHeader& h, const std::shared_ptr<const CameraModel>& cam,
                Map* map, const std::shared_ptr<FeatureSpill>& spill) {
  const std::string& file = src.name();
  const Sections& s = h.sections;
  if (h.version < 1 || h.version > kMapFileVersion || s.size() != section_tags(h.version).size())
    throw std::logic_error("decode_map: a header not from read_map_header");
  const auto reader = [&](std::size_t i) { return reader_for(src, s, i, h.version); };
  const PointIdsByKf ids = read_keyframes(reader(1), cam, h.sessions, map, spill);
  if (map->keyframes().empty()) throw IoError(file, "the map has no keyframes");
  if (h.sessions > map->keyframes().size())  // every session counted made a keyframe that is kept
    throw IoError(
        file,
        ByteReader::where("HEAD section", kSectionHeadBytes + s[0].second - 4, s[0].first + s[0].second - 4) +
            std::to_string(h.sessions) + " sessions in a map of " + std::to_string(map->keyframes().size()) +
            " keyframes (each session holds one at least)");
  const auto saved = read_points(reader(2), *map);
  link_points(reader(2), ids, saved, map, spill.get());
  read_graph(reader(3), map);
  read_bows(reader(4), map);
  if (h.version >= 2) read_inertial(reader(kInerSection), map);
  if (h.version >= 3) map->wheels() = read_wheels(reader(kWhelSection));
}

void decode_map(const std::string& bytes, const std::string& file, const MapFileHeader& h,
                const std::shared_ptr<const CameraModel>& cam, Map* map) {
  decode_map(MapFileBytes::in_memory(bytes, file), h, cam, map);
}

}  // namespace pvb::slam
