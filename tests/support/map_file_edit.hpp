#pragma once
// Map files for tests (docs/map_file.md): a tiny map of three keyframes
// made through the writer, and the means to change any field of a file
// with its lengths and checksums made right, so that a test reaches the
// reader's checks behind the checksums (the impossible maps).
#include <cstdint>
#include <cstring>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "pvb/common/fnv.hpp"
#include "pvb/slam/core/map_file.hpp"

namespace pvb::test {

inline void put_le(std::string& b, std::size_t at, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) b[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}
inline void put_u32(std::string& b, std::size_t at, std::uint32_t v) { put_le(b, at, v, 4); }
inline void put_u64(std::string& b, std::size_t at, std::uint64_t v) { put_le(b, at, v, 8); }
inline void put_i32(std::string& b, std::size_t at, std::int32_t v) {
  put_le(b, at, static_cast<std::uint32_t>(v), 4);
}
inline void put_f32(std::string& b, std::size_t at, float v) {
  std::uint32_t u;
  std::memcpy(&u, &v, 4);
  put_le(b, at, u, 4);
}
inline void put_f64(std::string& b, std::size_t at, double v) {
  std::uint64_t u;
  std::memcpy(&u, &v, 8);
  put_le(b, at, u, 8);
}
inline std::uint64_t get_u64(const std::string& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t(static_cast<unsigned char>(b[at + i])) << (8 * i);
  return v;
}

/// The payloads of a well-formed map file's sections, in file order
/// (HEAD, KEYF, POIN, GRAP, BOWV, META; version 2 with INER before META).
inline std::vector<std::string> map_sections(const std::string& file) {
  std::vector<std::string> out;
  std::size_t at = 16;  // magic, version, section count
  const std::uint64_t count = get_u64(file, 8) >> 32;  // the u32 after the version
  for (std::uint64_t s = 0; s < count; ++s) {
    const std::uint64_t length = get_u64(file, at + 4);
    out.push_back(file.substr(at + 12, length));
    at += 12 + length + 8;
  }
  return out;
}

/// The map file of `payloads` (as map_sections gives them), each section
/// with its length and checksum: version 1 of 6 sections, version 2 of 7
/// (INER before META), version 3 of 8 (INER and WHEL before META).
inline std::string map_file_of(const std::vector<std::string>& payloads) {
  static const char* const kTags[] = {"HEAD", "KEYF", "POIN", "GRAP", "BOWV", "INER", "WHEL"};
  const std::uint32_t version = payloads.size() == 8 ? 3 : payloads.size() == 7 ? 2 : 1;
  std::string out("PVBMAP\r\n", 8);
  out.append(8, '\0');
  put_u32(out, 8, version);
  put_u32(out, 12, static_cast<std::uint32_t>(payloads.size()));
  for (std::size_t s = 0; s < payloads.size(); ++s) {
    std::string head(12, '\0');
    std::memcpy(head.data(), s + 1 == payloads.size() ? "META" : kTags[s], 4);
    put_u64(head, 4, payloads[s].size());
    std::string sum(8, '\0');
    put_u64(sum, 0, fnv1a64(payloads[s].data(), payloads[s].size()));
    out += head + payloads[s] + sum;
  }
  return out;
}

/// Settings of a 640x480 Kinect-like camera without distortion.
inline slam::MapSettings tiny_settings() {
  slam::MapSettings s;
  s.fx = s.fy = 525.0;
  s.cx = 319.5;
  s.cy = 239.5;
  s.bf = 40.0;
  s.width = 640;
  s.height = 480;
  s.th_depth_m = 3.0;
  s.depth_factor = 5000.0;
  s.scale_factor = 1.2;
  s.num_levels = 8;
  s.num_features = 1000;
  s.vocabulary = 0x1234;
  return s;
}

/// The tiny map's shape: keyframes 0, 1, 2 (0.1 m apart along x, each
/// with kTinyKeypoints keypoints), kTinyPoints points 2 m ahead, point i at
/// keypoint i of every keyframe, except that keyframe 2 does not observe
/// the last point.  Keyframes 1 and 2 hang under 0 in the spanning tree.
constexpr int kTinyKeyframes = 3, kTinyKeypoints = 8, kTinyPoints = 6;

/// Byte offsets in the tiny map's payloads (docs/map_file.md, "Layout").
constexpr std::size_t kTinyKeyframeBytes = 128 + kTinyKeypoints * 73;
inline std::size_t keyf_keyframe(int k) { return 8 + k * kTinyKeyframeBytes; }
inline std::size_t keyf_translation(int k) { return keyf_keyframe(k) + 28 + 72; }
inline std::size_t keyf_keypoint(int k, int i) { return keyf_keyframe(k) + 128 + i * 73; }
inline std::size_t poin_point(int p) { return 8 + p * 56; }  // id, x y z, ref, first, visible, found

/// The tiny map, through the writer, with `app_json` as its META; `edit`
/// changes the map (under its mutex) before it is written.
inline std::string tiny_map(const slam::MapSettings& settings = tiny_settings(),
                            const std::string& app_json = "{}",
                            const std::function<void(slam::Map&)>& edit = nullptr) {
  const auto cam = slam::camera_for(settings);
  slam::Map map;
  std::lock_guard<std::mutex> lock(map.mutex());
  std::vector<std::shared_ptr<slam::KeyFrame>> kfs;
  for (int k = 0; k < kTinyKeyframes; ++k) {
    std::vector<cv::Point2f> keys;
    std::vector<slam::Keypoint> keys_un;
    std::vector<float> depth;
    cv::Mat desc(kTinyKeypoints, 32, CV_8U);
    for (int i = 0; i < kTinyKeypoints; ++i) {
      const cv::Point2f pt(100.0f + 50.0f * i - 26.25f * k, 200.0f + 10.0f * i);
      keys.push_back(pt);
      keys_un.push_back(slam::Keypoint{pt, 30.0f * i, i % 3});
      depth.push_back(2.0f);
      for (int c = 0; c < 32; ++c) desc.at<unsigned char>(i, c) = static_cast<unsigned char>(7 * i + c + k);
    }
    slam::Frame f = slam::Frame::from_saved(static_cast<std::uint64_t>(10 * k), 1000000000LL * k, keys,
                                            keys_un, desc, depth, cam);
    f.T_c_w = geom::SE3d(Eigen::Translation3d(-0.1 * k, 0, 0));
    f.has_pose = true;
    kfs.push_back(map.create_keyframe(f));
  }
  for (int i = 0; i < kTinyPoints; ++i) {
    const auto mp = map.create_point(kfs[0]->frame().unproject_world(static_cast<std::size_t>(i)), kfs[0]);
    for (int k = 0; k < kTinyKeyframes; ++k) {
      if (k == 2 && i == kTinyPoints - 1) continue;
      mp->add_observation(kfs[k], static_cast<std::size_t>(i));
      kfs[k]->set_map_point(static_cast<std::size_t>(i), mp);
    }
  }
  for (const auto& kf : kfs) kf->update_connections();
  if (edit) edit(map);
  return slam::encode_map(map, settings, 1, app_json);
}

/// The tiny map's settings with an IMU and wheels: the camera 5 cm ahead
/// of the IMU, turned 90 degrees about z, and 0.4 m above the base.
inline slam::MapSettings tiny_inertial_settings() {
  slam::MapSettings s = tiny_settings();
  s.sensors = sensor::SensorSetup::kCameraImuWheels;
  s.T_b_c = geom::make_se3(Eigen::Matrix3d(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())),
                           Eigen::Vector3d(0.05, 0, 0.01));
  s.T_base_c = geom::make_se3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.1, 0, 0.4));
  return s;
}

/// Makes the tiny map's inertial state: gravity trusted at keyframe 1,
/// keyframes chained 0 -> 1 -> 2 in time, 1 and 2 with a velocity and bias.
inline void give_tiny_inertial_state(slam::Map& map) {
  slam::MapGravity& g = map.gravity();
  g.ready = true;
  g.g_w = Eigen::Vector3d(0.1, -0.2, -9.8);
  g.bias.gyro_radps = Eigen::Vector3d(0.001, -0.002, 0.003);
  g.bias.accel_mps2 = Eigen::Vector3d(0.02, 0.01, -0.03);
  g.ready_keyframe_id = 1;
  g.ready_t_ns = 1000000000;
  g.init_rms = 0.75;
  std::shared_ptr<slam::KeyFrame> prev;
  for (const auto& [id, kf] : map.keyframes()) {
    if (prev) {
      kf->motion().prev = prev;
      prev->motion().next = kf;
    }
    if (id > 0) {
      kf->motion().has_state = true;
      kf->motion().v_w_mps = Eigen::Vector3d(0.1 * static_cast<double>(id), 0.05, -0.01);
      kf->motion().bias = g.bias;
    }
    prev = kf;
  }
}

/// The tiny map with its inertial state (a version-2 file).
inline std::string tiny_inertial_map() {
  return tiny_map(tiny_inertial_settings(), "{}", give_tiny_inertial_state);
}

/// The tiny inertial map's state and a wheel fit: 12 m rolled, one turn.
inline void give_tiny_wheel_fit(slam::Map& map) {
  give_tiny_inertial_state(map);
  slam::WheelFit& f = map.wheels();
  f.calibration = {0.998, 1.002, 1.05};
  f.radii_known = true;
  f.intervals = 48;
  f.refused = 2;
  f.rolled_m = 12.0;
  f.turned_rad = 3.5;
  f.sums.turn_normal << 0.5, 0.125, 0.125, 24.0;
  f.sums.turn_rhs << 0.7, 0.01;
  f.sums.mm = 3.0, f.sums.mn = 0.02, f.sums.nn = 0.25, f.sums.am = 2.99, f.sums.an = 0.021;
  f.described_track_m = 0.42;
  f.described_radius_m = 0.1;
}

inline std::string tiny_wheel_map() { return tiny_map(tiny_inertial_settings(), "{}", give_tiny_wheel_fit); }

/// Byte offsets in the tiny inertial map's INER payload: setup, gravity,
/// T_b_c (rotation, translation), T_base_c, the map's bias, the keyframe
/// and time gravity was trusted at, the RMS, the count; then per keyframe
/// 89 bytes: id, predecessor, has_state, velocity, bias.
constexpr std::size_t kInerGravity = 4, kInerTbc = 28, kInerTbaseC = 124, kInerBias = 220, kInerReadyId = 268,
                      kInerRms = 284, kInerCount = 292;
inline std::size_t iner_keyframe(int k) { return 300 + static_cast<std::size_t>(k) * 89; }

/// A GRAP payload: per keyframe (ids 0, 1, ...) its parent (kNone: the
/// root), its covisibility edges and its loop edges, as given.
struct GraphEntry {
  std::uint64_t parent;
  std::vector<std::pair<std::uint64_t, std::int32_t>> edges;
  std::vector<std::uint64_t> loops;
};
inline std::string graph_payload(const std::vector<GraphEntry>& entries) {
  std::string b(8, '\0');
  put_u64(b, 0, entries.size());
  const auto u64 = [&](std::uint64_t v) {
    std::string x(8, '\0');
    put_u64(x, 0, v);
    b += x;
  };
  for (std::size_t k = 0; k < entries.size(); ++k) {
    u64(k);
    u64(entries[k].parent);
    u64(entries[k].edges.size());
    for (const auto& [id, w] : entries[k].edges) {
      u64(id);
      std::string x(4, '\0');
      put_i32(x, 0, w);
      b += x;
    }
    u64(entries[k].loops.size());
    for (std::uint64_t id : entries[k].loops) u64(id);
  }
  return b;
}

}  // namespace pvb::test
