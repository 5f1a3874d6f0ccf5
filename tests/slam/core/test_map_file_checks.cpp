// Map files made impossible one way at a time (a tiny map, its checksums
// made right) are refused for that reason; the fuzz target's seed corpus
// holds each, and its whole maps are read; the writer never writes what
// the reader refuses; and the inertial state of version 2: round trips,
// version-1 files, and extrinsics compared between map and run.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>

#include "map_file_edit.hpp"
#include "map_file_pair.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/slam/core/map_file.hpp"
#include "pvb/slam/core/system.hpp"

namespace pvb::slam {
namespace {

using test::kTum3;
using test::pair_frames;
using test::sync_options;

// --- Impossible maps ------------------------------------------------------------

/// Reads `bytes` as a map: what() of the error thrown ("" when none).
std::string decode_error(const std::string& bytes, const std::string& file = "m.pvbmap") {
  try {
    const MapFileHeader h = read_map_header(bytes, file);
    Map map;
    decode_map(bytes, file, h, camera_for(h.settings), &map);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

struct ImpossibleMap {
  std::string name;    ///< the corpus file is impossible_NAME.pvbmap
  std::string bytes;   ///< checksums right
  std::string reason;  ///< in the error
};

/// A BOWV payload for `keyframes` keyframes without words, the first with
/// one direct-index node and its keypoint indices.
std::string bow_payload(int keyframes, const std::pair<std::uint32_t, std::vector<std::uint32_t>>& node) {
  std::string b;
  const auto u64 = [&](std::uint64_t v) { b.append(8, '\0'), test::put_u64(b, b.size() - 8, v); };
  const auto u32 = [&](std::uint32_t v) { b.append(4, '\0'), test::put_u32(b, b.size() - 4, v); };
  for (int k = 0; k < keyframes; ++k) {
    u64(0);  // words
    u64(k == 0 ? 1 : 0);
    if (k != 0) continue;
    u32(node.first);
    u64(node.second.size());
    for (std::uint32_t i : node.second) u32(i);
  }
  return b;
}

/// The tiny map made impossible one way at a time.
std::vector<ImpossibleMap> impossible_maps() {
  using namespace test;
  const std::string tiny = tiny_map();
  const auto edit = [&](int section, const std::function<void(std::string&)>& change) {
    std::vector<std::string> p = map_sections(tiny);
    change(p[static_cast<std::size_t>(section)]);
    return map_file_of(p);
  };
  const auto graph = [&](const std::vector<GraphEntry>& g) {
    return edit(3, [&](std::string& b) { b = graph_payload(g); });
  };
  const std::uint64_t none = ~std::uint64_t(0);
  const std::vector<std::pair<std::uint64_t, std::int32_t>> e0 = {{1, 6}, {2, 5}}, e1 = {{0, 6}},
                                                            e2 = {{0, 5}};
  return {
      {"first_keyframe_missing", edit(2, [](std::string& b) { put_u64(b, poin_point(0) + 40, 99); }),
       "point 0: its first keyframe 99 is not in the map"},
      {"reference_does_not_observe", edit(2, [](std::string& b) { put_u64(b, poin_point(5) + 32, 2); }),
       "point 5: its reference keyframe 2 does not observe it"},
      {"tree_cycle", graph({{none, e0, {}}, {2, e1, {}}, {1, e2, {}}}),
       "the spanning tree has a cycle through keyframe"},
      {"tree_two_roots", graph({{none, e0, {}}, {0, e1, {}}, {none, e2, {}}}),
       "the spanning tree has 2 roots (keyframes 0 and 2), expected one"},
      {"duplicate_edge", graph({{none, {{1, 6}, {1, 6}, {2, 5}}, {}}, {0, e1, {}}, {0, e2, {}}}),
       "keyframe 0: neighbour 1 repeated or out of order"},
      {"duplicate_loop_edge", graph({{none, e0, {2, 2}}, {0, e1, {}}, {0, e2, {0}}}),
       "keyframe 0: loop edge 2 repeated or out of order"},
      {"sessions_4294967295", edit(0, [](std::string& b) { put_u32(b, b.size() - 4, 4294967295u); }),
       "HEAD section at byte 140 (file byte 156): 4294967295 sessions in a map of 3 keyframes"},
      {"keypoint_x_1e6", edit(1, [](std::string& b) { put_f32(b, keyf_keypoint(0, 0), 1e6f); }),
       "keypoint 0 as detected at (1e+06, 200) lies beyond the 640x480 image widened by its size on every "
       "side"},
      {"keypoint_angle", edit(1, [](std::string& b) { put_f32(b, keyf_keypoint(1, 2) + 16, -1e30f); }),
       "keypoint 2 has angle -1e+30, outside 0-360 degrees"},
      {"keypoint_depth_1e30", edit(1, [](std::string& b) { put_f32(b, keyf_keypoint(0, 3) + 29, 1e30f); }),
       "keypoint 3 has depth 1e+30 m, beyond 1e+06 m"},
      {"translation_1e300", edit(1, [](std::string& b) { put_f64(b, keyf_translation(2), 1e300); }),
       "a camera centre at (-1e+300, -0, -0) m lies beyond 1e+06 m of the map's origin"},
      {"keyframe_id_2e48",
       edit(1, [](std::string& b) { put_u64(b, keyf_keyframe(2), std::uint64_t(1) << 48); }),
       "keyframe id 281474976710656 is not below 2^48"},
      {"point_1e308", edit(2, [](std::string& b) { put_f64(b, poin_point(1) + 8, 1e308); }),
       "point 1 at (1e+308, "},
      {"found_above_visible",
       edit(2,
            [](std::string& b) {
              put_i32(b, poin_point(0) + 48, 2);
              put_i32(b, poin_point(0) + 52, 3);
            }),
       "point 0 was found 3 times but predicted visible only 2"},
      {"visible_2e31", edit(2, [](std::string& b) { put_i32(b, poin_point(0) + 48, 2147483647); }),
       "point 0 was predicted visible 2147483647 times, more than 2^30"},
      {"bow_keypoint_995", edit(4, [](std::string& b) { b = bow_payload(3, {11, {995}}); }),
       "keyframe 0: direct-index node 11 names keypoint 995, but the keyframe has " +
           std::to_string(test::kTinyKeypoints) + " keypoints"},
  };
}

/// The tiny inertial map made impossible one way at a time (in its INER).
std::vector<ImpossibleMap> impossible_inertial_maps() {
  using namespace test;
  const std::string tiny = tiny_inertial_map();
  const auto edit = [&](const std::function<void(std::string&)>& change) {
    std::vector<std::string> p = map_sections(tiny);
    change(p[5]);
    return map_file_of(p);
  };
  const auto prev = [](int k) { return iner_keyframe(k) + 8; };
  const auto state = [](int k) { return iner_keyframe(k) + 16; };
  const auto velocity = [](int k) { return iner_keyframe(k) + 17; };
  const auto bias = [](int k) { return iner_keyframe(k) + 41; };
  return {
      {"inertial_setup_9", edit([](std::string& b) { put_u32(b, 0, 9); }),
       "sensor setup 9 is not known (0 to 3)"},
      {"inertial_setup_camera", edit([](std::string& b) { put_u32(b, 0, 0); }),
       "sensor setup camera has no inertial state"},
      {"inertial_gravity_12", edit([](std::string& b) { put_f64(b, kInerGravity + 16, -12); }),
       "INER section at byte 40 (file byte 2976): gravity (0.1, -0.2, -12) m/s^2 of magnitude 12.0021, expected 9 "
       "to 10.6 m/s^2"},  // as docs/map_file.md shows it
      {"inertial_t_b_c_not_a_rotation", edit([](std::string& b) { put_f64(b, kInerTbc, 2.0); }),
       "IMU.T_b_c1 is not a rigid transform within 10 m"},
      {"inertial_t_base_c_20m", edit([](std::string& b) { put_f64(b, kInerTbaseC + 72, 20.0); }),
       "Robot.T_base_c1 is not a rigid transform within 10 m"},
      {"inertial_map_bias_nan",
       edit([](std::string& b) { put_f64(b, kInerBias, std::numeric_limits<double>::quiet_NaN()); }),
       "the map's gyro bias ("},
      {"inertial_rms_negative", edit([](std::string& b) { put_f64(b, kInerRms, -1.0); }),
       "initialisation RMS -1, expected a finite value >= 0"},
      {"inertial_count_2", edit([](std::string& b) { put_u64(b, kInerCount, 2); }),
       "2 keyframe states for 3 keyframes"},
      {"inertial_predecessor_missing", edit([&](std::string& b) { put_u64(b, prev(1), 7); }),
       "keyframe 1: its predecessor in time 7 is not in the map"},
      {"inertial_predecessor_newer", edit([&](std::string& b) { put_u64(b, prev(1), 2); }),
       "keyframe 1: its predecessor in time 2 is not older (at 2000000000 ns, it at 1000000000 ns)"},
      {"inertial_predecessor_shared", edit([&](std::string& b) { put_u64(b, prev(2), 0); }),
       "INER section at byte 579 (file byte 3515): keyframe 2: its predecessor in time 0 is already keyframe "
       "1's"},  // as docs/map_file.md shows it
      {"inertial_has_state_2", edit([&](std::string& b) { b[state(1)] = 2; }),
       "keyframe 1: has_state 2, expected 0 or 1"},
      {"inertial_stateless_velocity", edit([&](std::string& b) { put_f64(b, velocity(0), 0.5); }),
       "keyframe 0 has no inertial state but a velocity or bias other than 0"},
      {"inertial_speed_1000", edit([&](std::string& b) { put_f64(b, velocity(2), 1000.0); }),
       "keyframe 2: velocity (1000, 0.05, -0.01) m/s, not finite or faster than 100 m/s"},
      {"inertial_speed_inf",
       edit([&](std::string& b) { put_f64(b, velocity(1) + 8, std::numeric_limits<double>::infinity()); }),
       "keyframe 1: velocity (0.1, inf, -0.01) m/s, not finite or faster than 100 m/s"},
      {"inertial_gyro_bias_2", edit([&](std::string& b) { put_f64(b, bias(1), 2.0); }),
       "keyframe 1's gyro bias (2, -0.002, 0.003) rad/s and accelerometer bias (0.02, 0.01, -0.03) m/s^2: "
       "not finite or beyond 1 rad/s and 5 m/s^2"},
  };
}

/// The tiny map with a wheel fit, its WHEL section made impossible one way
/// at a time.
std::vector<ImpossibleMap> impossible_wheel_maps() {
  using namespace test;
  const std::string tiny = tiny_wheel_map();
  const auto edit = [&](const std::function<void(std::string&)>& change) {
    std::vector<std::string> p = map_sections(tiny);
    change(p[6]);
    return map_file_of(p);
  };
  constexpr std::size_t kFactors = 16, kFlags = 40, kCounts = 42, kRolled = 50, kSums = 66;
  return {
      {"wheels_track_20m", edit([](std::string& b) { put_f64(b, 8, 20.0); }),
       "described track 20 m, expected more than 0 and at most 10 m"},
      {"wheels_factor_3", edit([](std::string& b) { put_f64(b, kFactors + 8, 3.0); }),
       "wheel factor 3, expected 0.5 to 2"},
      {"wheels_flag_2", edit([](std::string& b) { b[kFlags + 1] = 2; }), "track_known 2, expected 0 or 1"},
      {"wheels_no_interval", edit([](std::string& b) { put_u32(b, kCounts, 0); }),
       "no interval fitted (a map without a fit has no WHEL section)"},
      {"wheels_rolled_negative", edit([](std::string& b) { put_f64(b, kRolled, -1.0); }),
       "rolled (m) -1, expected a finite value >= 0"},
      {"wheels_sum_inf",
       edit([](std::string& b) { put_f64(b, kSums + 8, std::numeric_limits<double>::infinity()); }),
       "a calibration sum that is not finite"},
      {"wheels_square_negative", edit([](std::string& b) { put_f64(b, kSums + 5 * 8, -1.0); }),
       "a sum of squares below 0"},
      {"wheels_longer", edit([](std::string& b) { b.append(8, '\0'); }), "longer than its calibration"},
  };
}

const std::string kCorpus = std::string(PVB_SOURCE_DIR) + "/tests/fuzz/corpus/map_file";

TEST(MapFileChecks, TheTinyMapIsWhatItsOffsetsSay) {
  const std::string tiny = test::tiny_map();
  EXPECT_EQ(decode_error(tiny), "");
  const auto p = test::map_sections(tiny);
  EXPECT_EQ(p[1].size(), 8 + 3 * test::kTinyKeyframeBytes);
  EXPECT_EQ(p[2].size(), 8 + 6 * 56u);
  EXPECT_EQ(test::map_file_of(p), tiny);
  const std::vector<std::pair<std::uint64_t, std::int32_t>> e0 = {{1, 6}, {2, 5}}, e1 = {{0, 6}},
                                                            e2 = {{0, 5}};
  const std::uint64_t none = ~std::uint64_t(0);
  EXPECT_EQ(p[3], test::graph_payload({{none, e0, {}}, {0, e1, {}}, {0, e2, {}}}));
}

// Each is refused for its reason, and the fuzz target's seed corpus holds
// each (PVB_WRITE_MAP_CORPUS=DIR writes them to DIR).
TEST(MapFileChecks, EveryImpossibleMapIsRefusedForItsReason) {
  const char* out = std::getenv("PVB_WRITE_MAP_CORPUS");
  if (out) write_file(std::string(out) + "/tiny.pvbmap", test::tiny_map());
  if (out) write_file(std::string(out) + "/tiny_inertial.pvbmap", test::tiny_inertial_map());
  std::vector<ImpossibleMap> maps = impossible_maps();
  if (out) write_file(std::string(out) + "/tiny_wheel.pvbmap", test::tiny_wheel_map());
  for (ImpossibleMap& m : impossible_inertial_maps()) maps.push_back(std::move(m));
  for (ImpossibleMap& m : impossible_wheel_maps()) maps.push_back(std::move(m));
  for (const ImpossibleMap& m : maps) {
    const std::string what = decode_error(m.bytes, "m.pvbmap");
    EXPECT_NE(what.find(m.reason), std::string::npos) << m.name << ": " << what;
    const std::string seed = "impossible_" + m.name + ".pvbmap";
    if (out) write_file(std::string(out) + "/" + seed, m.bytes);
    std::ifstream in(kCorpus + "/" + seed, std::ios::binary);
    if (!in.good()) {
      ADD_FAILURE() << seed << " is not in " << kCorpus;
      continue;
    }
    const std::string committed((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(decode_error(committed, seed).find(m.reason), std::string::npos) << seed;
  }
}

/// The corpus's map of the pair, of 600-feature keyframes (half the size
/// of the default 1000), and its first 1000 bytes.
void write_pair_seeds(const std::string& dir) {
  Settings s = read_settings(kTum3);
  s.orb.num_features = 600;
  System system(s, sync_options());
  for (const auto& f : pair_frames(s)) system.track(f);
  system.shutdown();
  system.save_map(dir + "/fr3_pair_600.pvbmap", R"({"station": "fr3"})");
  write_file(dir + "/truncated.pvbmap", read_file(dir + "/fr3_pair_600.pvbmap").substr(0, 1000));
}

// The seeds that are whole maps are maps the reader reads.
TEST(MapFileChecks, TheWholeMapsOfTheCorpusAreRead) {
  if (const char* out = std::getenv("PVB_WRITE_MAP_CORPUS")) write_pair_seeds(out);
  for (const char* seed : {"tiny.pvbmap", "tiny_inertial.pvbmap", "tiny_wheel.pvbmap", "fr3_pair_600.pvbmap"}) {
    std::ifstream in(kCorpus + "/" + seed, std::ios::binary);
    ASSERT_TRUE(in.good()) << seed;
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(decode_error(bytes, seed), "") << seed;
  }
}

// A point whose first keyframe was culled, or whose reference keyframe does
// not observe it, is saved with keyframes of the file in their place; a
// point no keyframe names is not saved.
TEST(MapFileChecks, TheWriterNeverWritesWhatTheReaderRefuses) {
  const std::string tiny = test::tiny_map();
  const MapFileHeader h = read_map_header(tiny, "tiny.pvbmap");
  Map map;
  decode_map(tiny, "tiny.pvbmap", h, camera_for(h.settings), &map);
  std::lock_guard<std::mutex> lock(map.mutex());
  map.points().at(0)->restore(77, 4, 3);  // made by keyframe 77, since culled
  const auto kf2 = map.keyframes().at(2);
  const auto far =
      map.create_point(Eigen::Vector3d(0, 0, 2), kf2);  // referred to keyframe 2, seen by 0 and 1
  for (std::uint64_t k : {0, 1}) {
    far->add_observation(map.keyframes().at(k), 7);
    map.keyframes().at(k)->set_map_point(7, far);
  }
  const auto unseen = map.create_point(Eigen::Vector3d(0, 0, 3), kf2);  // observed by none
  const std::string bytes = encode_map(map, h.settings, 1, "{}");
  const MapFileHeader h2 = read_map_header(bytes, "again.pvbmap");
  Map again;
  ASSERT_EQ(decode_error(bytes, "again.pvbmap"), "");
  decode_map(bytes, "again.pvbmap", h2, camera_for(h2.settings), &again);
  EXPECT_EQ(again.points().at(0)->first_kf_id(), 0u);                       // its reference keyframe
  EXPECT_EQ(again.points().at(far->id())->reference_keyframe()->id(), 0u);  // its first observer
  EXPECT_EQ(again.points().count(unseen->id()), 0u);
  EXPECT_THROW(encode_map(map, h.settings, 0, "{}"), std::logic_error);
  EXPECT_THROW(encode_map(map, h.settings, 4, "{}"), std::logic_error);  // more sessions than keyframes
}

// --- Inertial state (version 2) ------------------------------------------------

/// The file's version (the u32 after the magic).
std::uint32_t version_of(const std::string& bytes) {
  return static_cast<std::uint32_t>(test::get_u64(bytes, 8));
}

std::string corpus_file(const std::string& name) {
  std::ifstream in(kCorpus + "/" + name, std::ios::binary);
  EXPECT_TRUE(in.good()) << name;
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A map without a trusted inertial state, or saved by a run without an
// accelerometer, is the version-1 file it always was: the tiny map as
// committed to the corpus before version 2 existed.
TEST(MapFileInertial, AMapWithoutInertialStateIsVersion1ByteForByte) {
  const std::string tiny = test::tiny_map();
  EXPECT_EQ(version_of(tiny), 1u);
  EXPECT_TRUE(tiny == corpus_file("tiny.pvbmap"));
  // Sensors with an IMU but gravity not yet trusted: nothing to save.
  EXPECT_TRUE(test::tiny_map(test::tiny_inertial_settings()) == tiny);
  // Gravity trusted, but the run saving the map has no accelerometer.
  EXPECT_TRUE(test::tiny_map(test::tiny_settings(), "{}", test::give_tiny_inertial_state) == tiny);
}

// Version-1 files (the corpus's, made before version 2) are read, as
// camera-only maps without inertial state, and written again unchanged.
TEST(MapFileInertial, AVersion1FileIsReadAndWrittenAgainByteForByte) {
  for (const char* seed : {"tiny.pvbmap", "fr3_pair_600.pvbmap"}) {
    const std::string bytes = corpus_file(seed);
    const MapFileHeader h = read_map_header(bytes, seed);
    EXPECT_EQ(h.version, 1u) << seed;
    EXPECT_EQ(h.settings.sensors, sensor::SensorSetup::kCamera) << seed;
    Map map;
    decode_map(bytes, seed, h, camera_for(h.settings), &map);
    std::lock_guard<std::mutex> lock(map.mutex());
    EXPECT_FALSE(map.gravity().ready) << seed;
    for (const auto& [id, kf] : map.keyframes()) {
      EXPECT_FALSE(kf->motion().has_state) << seed << " keyframe " << id;
      EXPECT_FALSE(kf->motion().prev.lock()) << seed << " keyframe " << id;
    }
    EXPECT_TRUE(encode_map(map, h.settings, h.sessions, h.app_json) == bytes) << seed;
  }
}

TEST(MapFileInertial, TheTinyInertialMapIsWhatItsOffsetsSay) {
  const std::string tiny = test::tiny_inertial_map();
  EXPECT_EQ(version_of(tiny), 2u);
  const auto p = test::map_sections(tiny);
  ASSERT_EQ(p.size(), 7u);
  EXPECT_EQ(p[5].size(), test::iner_keyframe(3));
  EXPECT_EQ(test::get_u64(p[5], test::kInerReadyId), 1u);
  EXPECT_EQ(test::get_u64(p[5], test::kInerCount), 3u);
  EXPECT_EQ(test::get_u64(p[5], test::iner_keyframe(0) + 8), ~std::uint64_t(0));  // the chain's start
  EXPECT_EQ(test::get_u64(p[5], test::iner_keyframe(2) + 8), 1u);
  EXPECT_EQ(test::map_file_of(p), tiny);
  // The visual sections and META are the camera-only map's.
  const auto visual = test::map_sections(test::tiny_map());
  for (std::size_t s = 0; s < 5; ++s) EXPECT_TRUE(p[s] == visual[s]) << s;
  EXPECT_EQ(p[6], visual[5]);
  EXPECT_EQ(decode_error(tiny), "");
  // An error in INER names it and the byte.
  std::vector<std::string> bad = p;
  test::put_u32(bad[5], 0, 9);
  std::size_t iner = 16;  // where INER's tag lies in the file
  for (std::size_t s = 0; s < 5; ++s) iner += 12 + p[s].size() + 8;
  const std::string what = decode_error(test::map_file_of(bad));
  EXPECT_NE(what.find("INER section at byte 16 (file byte " + std::to_string(iner + 16) +
                      "): sensor setup 9 is not known (0 to 3)"),
            std::string::npos)
      << what;
}

// Save -> load -> save of a map with inertial state: the same bytes, and
// the loaded map holds the state (gravity ready, velocities, biases, the
// chain in time without its readings).
TEST(MapFileInertial, AMapWithInertialStateRoundTripsAsVersion2) {
  const std::string bytes = test::tiny_inertial_map();
  const MapFileHeader h = read_map_header(bytes, "tiny_inertial.pvbmap");
  const MapSettings want = test::tiny_inertial_settings();
  EXPECT_EQ(h.version, 2u);
  EXPECT_EQ(h.settings.sensors, sensor::SensorSetup::kCameraImuWheels);
  EXPECT_TRUE(h.settings.T_b_c.isApprox(want.T_b_c, 0));
  EXPECT_TRUE(h.settings.T_base_c.isApprox(want.T_base_c, 0));
  EXPECT_EQ(h.settings.difference(want), "");
  Map map;
  decode_map(bytes, "tiny_inertial.pvbmap", h, camera_for(h.settings), &map);
  std::lock_guard<std::mutex> lock(map.mutex());
  const MapGravity& g = map.gravity();
  EXPECT_TRUE(g.ready);
  EXPECT_EQ(g.g_w, Eigen::Vector3d(0.1, -0.2, -9.8));
  EXPECT_EQ(g.bias.gyro_radps, Eigen::Vector3d(0.001, -0.002, 0.003));
  EXPECT_EQ(g.bias.accel_mps2, Eigen::Vector3d(0.02, 0.01, -0.03));
  EXPECT_EQ(g.ready_keyframe_id, 1u);
  EXPECT_EQ(g.ready_t_ns, 1000000000);
  EXPECT_EQ(g.init_rms, 0.75);
  const auto& kfs = map.keyframes();
  ASSERT_EQ(kfs.size(), 3u);
  EXPECT_FALSE(kfs.at(0)->motion().has_state);
  EXPECT_FALSE(kfs.at(0)->motion().prev.lock());
  for (std::uint64_t id : {1, 2}) {
    const KeyFrameMotion& m = kfs.at(id)->motion();
    EXPECT_TRUE(m.has_state) << id;
    EXPECT_EQ(m.v_w_mps, Eigen::Vector3d(0.1 * static_cast<double>(id), 0.05, -0.01)) << id;
    EXPECT_EQ(m.bias.accel_mps2, g.bias.accel_mps2) << id;
    EXPECT_EQ(m.prev.lock(), kfs.at(id - 1)) << id;
    EXPECT_EQ(kfs.at(id - 1)->motion().next.lock(), kfs.at(id)) << id;
    EXPECT_FALSE(m.from_prev.imu) << id;  // the readings are not saved
    EXPECT_FALSE(m.from_prev.wheels) << id;
  }
  EXPECT_FALSE(kfs.at(2)->motion().next.lock());
  EXPECT_TRUE(encode_map(map, h.settings, h.sessions, h.app_json) == bytes);
}

// A map whose wheels were calibrated saves the fit as version 3 (WHEL
// after INER) and reads it back whole; save -> load -> save gives the same
// bytes; without a fit, or without the wheels, it is version 2 or 1 as
// before; a value the reader refuses names WHEL and its byte.
TEST(MapFileInertial, AMapWithAWheelFitRoundTripsAsVersion3) {
  const std::string bytes = test::tiny_wheel_map();
  EXPECT_EQ(version_of(bytes), 3u);
  const auto p = test::map_sections(bytes);
  ASSERT_EQ(p.size(), 8u);
  EXPECT_EQ(p[6].size(), 2 * 8 + 3 * 8 + 2 + 2 * 4 + 2 * 8 + 10 * 8u);
  const auto v2 = test::map_sections(test::tiny_inertial_map());
  for (std::size_t s = 0; s < 6; ++s) EXPECT_TRUE(p[s] == v2[s]) << s;
  EXPECT_EQ(p[7], v2[6]);
  const MapFileHeader h = read_map_header(bytes, "wheels.pvbmap");
  Map map;
  decode_map(bytes, "wheels.pvbmap", h, camera_for(h.settings), &map);
  Map want;
  test::give_tiny_wheel_fit(want);
  const WheelFit& got = map.wheels();
  EXPECT_EQ(got.calibration, want.wheels().calibration);
  EXPECT_TRUE(got.sums == want.wheels().sums);
  EXPECT_EQ(got.radii_known, true);
  EXPECT_EQ(got.track_known, false);
  EXPECT_EQ(got.intervals, 48);
  EXPECT_EQ(got.refused, 2);
  EXPECT_EQ(got.rolled_m, 12.0);
  EXPECT_EQ(got.turned_rad, 3.5);
  EXPECT_EQ(got.described_radius_m, 0.1);
  EXPECT_EQ(got.described_track_m, 0.42);
  EXPECT_TRUE(encode_map(map, h.settings, h.sessions, h.app_json) == bytes);

  // No interval fitted: version 2; a run without wheels: no WHEL either.
  const auto unfitted = [](Map& m) {
    test::give_tiny_wheel_fit(m);
    m.wheels().intervals = 0;
  };
  EXPECT_TRUE(test::tiny_map(test::tiny_inertial_settings(), "{}", unfitted) == test::tiny_inertial_map());
  MapSettings imu_only = test::tiny_inertial_settings();
  imu_only.sensors = sensor::SensorSetup::kCameraImu;
  EXPECT_EQ(version_of(test::tiny_map(imu_only, "{}", test::give_tiny_wheel_fit)), 2u);
  // A factor the reader refuses is not written.
  const auto huge = [](Map& m) {
    test::give_tiny_wheel_fit(m);
    m.wheels().calibration.track_scale = 3;
  };
  EXPECT_TRUE(test::tiny_map(test::tiny_inertial_settings(), "{}", huge) == test::tiny_inertial_map());

  std::vector<std::string> bad = p;
  test::put_f64(bad[6], 16, 3.0);  // the left wheel's factor
  std::size_t whel = 16;           // where WHEL's tag lies in the file
  for (std::size_t s = 0; s < 6; ++s) whel += 12 + p[s].size() + 8;
  const std::string what = decode_error(test::map_file_of(bad));
  EXPECT_NE(what.find("WHEL section at byte 36 (file byte " + std::to_string(whel + 36) +
                      "): wheel factor 3, expected 0.5 to 2"),
            std::string::npos)
      << what;
  bad = p;
  test::put_f64(bad[6], 0, 0.0);  // the described radius
  EXPECT_NE(decode_error(test::map_file_of(bad)).find("described wheel radius 0 m, expected more than 0"),
            std::string::npos);
  bad = p;
  test::put_f64(bad[6], 2 * 8 + 3 * 8 + 2 + 2 * 4 + 2 * 8 + 5 * 8, std::nan(""));  // sum mm
  EXPECT_NE(decode_error(test::map_file_of(bad)).find("a calibration sum that is not finite"), std::string::npos);
}

// What the reader would refuse is not written: a keyframe state beyond
// range is saved as none, a link in time that the reader would refuse as
// the chain's start, and a gravity beyond range leaves the section out.
TEST(MapFileInertial, TheWriterLeavesOutWhatTheReaderWouldRefuse) {
  const auto bad_state = [](Map& m) {
    test::give_tiny_inertial_state(m);
    m.keyframes().at(2)->motion().v_w_mps.x() = 1e3;  // faster than 100 m/s
    m.keyframes().at(1)->motion().next.reset();       // 1 no longer names 2 as its next
  };
  const std::string bytes = test::tiny_map(test::tiny_inertial_settings(), "{}", bad_state);
  ASSERT_EQ(decode_error(bytes), "");
  const MapFileHeader h = read_map_header(bytes, "m.pvbmap");
  Map map;
  decode_map(bytes, "m.pvbmap", h, camera_for(h.settings), &map);
  EXPECT_FALSE(map.keyframes().at(2)->motion().has_state);
  EXPECT_EQ(map.keyframes().at(2)->motion().v_w_mps, Eigen::Vector3d::Zero());
  EXPECT_FALSE(map.keyframes().at(2)->motion().prev.lock());
  EXPECT_EQ(map.keyframes().at(1)->motion().prev.lock(), map.keyframes().at(0));
  const auto heavy = [](Map& m) {
    test::give_tiny_inertial_state(m);
    m.gravity().g_w = Eigen::Vector3d(0, 0, -12);
  };
  EXPECT_TRUE(test::tiny_map(test::tiny_inertial_settings(), "{}", heavy) == test::tiny_map());
}

// The setup is not compared (either side without a sensor leaves the
// other's state unused); extrinsics are where both use them, to 1 mm and
// 0.1 degrees, in one line.
TEST(MapFileInertial, ExtrinsicsAreComparedWhereMapAndRunBothUseThem) {
  const MapSettings map = test::tiny_inertial_settings();
  MapSettings run = map;
  const auto moved = [](const geom::SE3d& T, double shift_m, double turn_deg) {
    return T *
           geom::make_se3(Eigen::Matrix3d(Eigen::AngleAxisd(turn_deg * M_PI / 180, Eigen::Vector3d::UnitY())),
                          Eigen::Vector3d(shift_m, 0, 0));
  };
  run.T_b_c = moved(map.T_b_c, 0.0009, 0.09);
  run.T_base_c = moved(map.T_base_c, 0.0009, 0.09);
  EXPECT_EQ(map.difference(run), "");
  run.T_b_c = moved(map.T_b_c, 0.002, 0);
  EXPECT_EQ(
      map.difference(run),
      "IMU.T_b_c1: the map's and this run's differ by 2.00 mm and 0.000 deg (at most 1 mm and 0.1 deg when "
      "both use the IMU)");
  run.T_b_c = moved(map.T_b_c, 0, 0.2);
  EXPECT_NE(map.difference(run).find("IMU.T_b_c1: the map's and this run's differ by 0.00 mm and 0.200 deg"),
            std::string::npos)
      << map.difference(run);
  run.T_b_c = map.T_b_c;
  run.T_base_c = moved(map.T_base_c, 0.01, 0);
  EXPECT_NE(map.difference(run).find("Robot.T_base_c1: the map's and this run's differ by 10.00 mm"),
            std::string::npos)
      << map.difference(run);
  run.sensors = sensor::SensorSetup::kCameraImu;  // the run has no wheels: the base is not compared
  EXPECT_EQ(map.difference(run), "");
  run.T_b_c = moved(map.T_b_c, 0.05, 5);
  run.sensors = sensor::SensorSetup::kCamera;  // a camera-only run uses the visual map alone
  EXPECT_EQ(map.difference(run), "");
  EXPECT_EQ(run.difference(map), "");       // and a camera-only map serves a run with an IMU
  run.sensors = sensor::SensorSetup::kCameraAccel;  // an accelerometer's frame is compared
  EXPECT_NE(map.difference(run).find("IMU.T_b_c1"), std::string::npos);
  run.num_features += 1;  // the visual settings first
  EXPECT_NE(map.difference(run).find("ORBextractor.nFeatures"), std::string::npos);
}

}  // namespace
}  // namespace pvb::slam
