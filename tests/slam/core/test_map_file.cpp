// Map files on a real Kinect pair (TUM fr3 long_office_household): a map
// made on the pair is saved, loaded and saved again byte for byte; every
// kind of bad file is one IoError or ConfigError naming the file; and a
// run that loads the map to localise in it starts lost, relocalises on the
// first frame at the map's own pose, never adds a keyframe, and tracks the
// second frame where the mapping run put it.  A tiny map made
// impossible in one way at a time, its checksums made right, is refused for
// that reason (the same files seed the fuzz target).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>

#include "map_file_edit.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/slam/core/map_file.hpp"
#include "pvb/slam/core/system.hpp"
#include "shared_data.hpp"

namespace pvb::slam {
namespace {

/// A real two-frame Kinect sequence in ../shared/data.
std::string pair_dir() { return pvb::test::shared_path("data/tum/fr3_long_office_household_pair"); }
const std::string kTum3 = std::string(PVB_SOURCE_DIR) + "/configs/tum/TUM3.yaml";

/// A file of this test process (CTest runs the tests of this program as
/// processes side by side).
std::string tmp_path(const std::string& name) {
  const char* dir = std::getenv("TEST_TMPDIR");
  return std::string(dir ? dir : "/tmp") + "/map_file_" + std::to_string(::getpid()) + "_" + name;
}

std::vector<sensor::RgbdFrame> pair_frames(const Settings& s) {
  dataset::TumSequenceReader reader(pair_dir(), s.depth_map_factor);
  std::vector<sensor::RgbdFrame> out;
  while (auto f = reader.next()) out.push_back(*f);
  return out;
}

SystemOptions sync_options() {
  SystemOptions o;
  o.synchronous = true;
  return o;
}

/// Maps the pair, saves the map; returns the second frame's pose.
geom::SE3d map_pair(const std::string& path) {
  const Settings s = read_settings(kTum3);
  System system(s, sync_options());
  geom::SE3d T_w_c2 = geom::SE3d::Identity();
  for (const auto& f : pair_frames(s)) {
    const FrameResult r = system.track(f);
    EXPECT_EQ(r.state, TrackingState::kOk);
    if (r.T_w_c) T_w_c2 = *r.T_w_c;
  }
  system.shutdown();
  const MapSaveInfo info = system.save_map(path, R"({"station": "fr3"})");
  EXPECT_EQ(info.sessions, 1u);
  EXPECT_GE(info.keyframes, 1u);
  EXPECT_GT(info.points, 100u);
  return T_w_c2;
}

class MapFile : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    path_ = tmp_path("pair.pvbmap");
    T_w_c2_ = map_pair(path_);
    bytes_ = read_file(path_);
  }
  static std::string path_, bytes_;
  static geom::SE3d T_w_c2_;

  /// Loads `bytes` written to a file; returns what() of the error thrown ("" when none).
  static std::string load_error(const std::string& bytes, const std::string& name) {
    const std::string p = tmp_path(name);
    write_file(p, bytes);
    System system(read_settings(kTum3), sync_options());
    try {
      system.load_map(p, MapStart::kLocalise);
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(p), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      return what;
    }
    return "";
  }
};
std::string MapFile::path_, MapFile::bytes_;
geom::SE3d MapFile::T_w_c2_;

TEST_F(MapFile, SaveLoadSaveGivesTheSameBytes) {
  System system(read_settings(kTum3), sync_options());
  const MapLoadInfo info = system.load_map(path_, MapStart::kExtend);
  EXPECT_EQ(info.app_json, R"({"station": "fr3"})");
  EXPECT_EQ(info.bytes, bytes_.size());
  EXPECT_EQ(info.sessions, 1u);
  system.shutdown();
  const std::string again = tmp_path("again.pvbmap");
  const MapSaveInfo saved = system.save_map(again, info.app_json);
  EXPECT_EQ(saved.sessions, 1u);  // a session that added nothing is not counted
  EXPECT_TRUE(read_file(again) == bytes_);
}

TEST_F(MapFile, EncodeOfADecodedMapIsTheFileItCameFrom) {
  const MapFileHeader h = read_map_header(bytes_, path_);
  Map map;
  decode_map(bytes_, path_, h, camera_for(h.settings), &map);
  std::lock_guard<std::mutex> lock(map.mutex());
  EXPECT_EQ(encode_map(map, h.settings, h.sessions, h.app_json), bytes_);
}

TEST_F(MapFile, AProvisionalMapNeverMergedIsLeftOutOfTheFile) {
  const MapFileHeader h = read_map_header(bytes_, path_);
  Map map;
  decode_map(bytes_, path_, h, camera_for(h.settings), &map);
  std::lock_guard<std::mutex> lock(map.mutex());
  // A provisional map (in a frame of its own) of two keyframes sharing points.
  const auto kf0 = map.keyframes().begin()->second;
  const std::uint32_t p = map.begin_provisional();
  Frame f = kf0->frame();
  std::fill(f.map_points.begin(), f.map_points.end(), nullptr);
  const auto root = map.create_keyframe(f), next = map.create_keyframe(f);
  for (const auto& kf : {root, next}) kf->set_provisional(p);
  root->make_root();
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!(f.depth_m[i] > 0)) continue;
    const auto mp = map.create_point(f.unproject_world(i), root);
    for (const auto& kf : {root, next}) {
      mp->add_observation(kf, i);
      kf->set_map_point(i, mp);
    }
  }
  for (const auto& kf : {root, next}) kf->update_connections();
  EXPECT_EQ(encode_map(map, h.settings, h.sessions, h.app_json), bytes_);
  // Once merged, it is in the file.
  next->reroot_under(kf0);
  map.merge_provisional(p, 0);
  EXPECT_GT(encode_map(map, h.settings, h.sessions, h.app_json).size(), bytes_.size());
}

TEST_F(MapFile, EveryTruncationIsOneErrorNamingTheFile) {
  for (std::size_t n : {std::size_t(0), std::size_t(5), std::size_t(8), std::size_t(12), std::size_t(20),
                        bytes_.size() / 3, bytes_.size() / 2, bytes_.size() - 9, bytes_.size() - 1}) {
    const std::string what = load_error(bytes_.substr(0, n), "cut.pvbmap");
    EXPECT_FALSE(what.empty()) << n << " bytes";
  }
}

TEST_F(MapFile, ADamagedByteInAnySectionFailsItsChecksum) {
  for (std::size_t at : {std::size_t(40), bytes_.size() / 4, bytes_.size() / 2, bytes_.size() - 20}) {
    std::string b = bytes_;
    b[at] = static_cast<char>(b[at] ^ 0x10);
    const std::string what = load_error(b, "damaged.pvbmap");
    EXPECT_NE(what.find("damaged"), std::string::npos) << what;
  }
}

TEST_F(MapFile, ForeignAndFutureFilesSaySo) {
  EXPECT_NE(load_error("PVBVOC1\nnot a map", "foreign.pvbmap").find("not a map file"), std::string::npos);
  std::string future = bytes_;
  future[8] = 3;  // version, little-endian u32 after the magic
  EXPECT_NE(load_error(future, "future.pvbmap").find("version 3 is newer than this build reads (2)"),
            std::string::npos);
  std::string unframed = bytes_;
  unframed[8] = 2;  // a version-2 file has an INER section
  EXPECT_NE(load_error(unframed, "v2.pvbmap").find("6 sections, expected 7 in a version-2 file"),
            std::string::npos);
}

TEST_F(MapFile, AMapOfOtherSettingsIsRefused) {
  Settings s = read_settings(kTum3);
  s.orb.num_features += 100;
  System system(s, sync_options());
  try {
    system.load_map(path_, MapStart::kLocalise);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("ORBextractor.nFeatures"), std::string::npos) << e.what();
  }
}

TEST_F(MapFile, LocaliseStartsLostRelocalisesAndNeverAddsKeyframes) {
  const Settings s = read_settings(kTum3);
  System system(s, sync_options());
  const MapLoadInfo info = system.load_map(path_, MapStart::kLocalise);
  EXPECT_EQ(system.state(), TrackingState::kLost);
  const auto frames = pair_frames(s);
  std::vector<FrameResult> results;
  for (const auto& f : frames) results.push_back(system.track(f));
  ASSERT_EQ(results.size(), 2u);
  ASSERT_TRUE(results[0].T_w_c) << results[0].tracking.failure;
  EXPECT_EQ(results[0].tracking.method, TrackingMethod::kRelocalization);
  // The map's frame is the mapping run's first camera.
  EXPECT_LT(results[0].T_w_c->translation().norm(), 0.01);
  ASSERT_TRUE(results[1].T_w_c);
  EXPECT_LT((results[1].T_w_c->translation() - T_w_c2_.translation()).norm(), 0.01);
  EXPECT_EQ(system.num_keyframes(), info.keyframes);
  EXPECT_EQ(system.relocalisations().size(), 1u);
  EXPECT_THROW(system.save_map(tmp_path("localised.pvbmap"), "{}"), ConfigError);
}

/// The pair's map with inertial state (test::give_tiny_inertial_state), as
/// a run with an IMU whose camera sits at T_b_c saves it.
std::string inertial_pair_map(const std::string& bytes, const std::string& file, const geom::SE3d& T_b_c,
                              sensor::SensorSetup setup = sensor::SensorSetup::kCameraImu) {
  const MapFileHeader h = read_map_header(bytes, file);
  Map map;
  decode_map(bytes, file, h, camera_for(h.settings), &map);
  std::lock_guard<std::mutex> lock(map.mutex());
  test::give_tiny_inertial_state(map);
  MapSettings s = h.settings;
  s.sensors = setup;
  s.T_b_c = T_b_c;
  return encode_map(map, s, h.sessions, h.app_json);
}

Settings imu_settings(const geom::SE3d& T_b_c) {
  Settings s = read_settings(kTum3);
  s.motion.setup = sensor::SensorSetup::kCameraImu;
  s.motion.imu.present = true;
  s.motion.imu.T_b_c = T_b_c;
  return s;
}

// A run with an IMU that loads a map with inertial state has its gravity
// and keyframe states at once, and saves the map again byte for byte; one
// whose IMU sits elsewhere is refused in one line; a camera-only run
// localises in the map and keeps no inertial state.
TEST_F(MapFile, ARunWithAnImuHasTheMapsGravityAtOnce) {
  const geom::SE3d T_b_c = test::tiny_inertial_settings().T_b_c;
  const std::string p = tmp_path("inertial_pair.pvbmap");
  const std::string bytes = inertial_pair_map(bytes_, path_, T_b_c);
  write_file(p, bytes);
  {
    System system(imu_settings(T_b_c), sync_options());
    system.load_map(p, MapStart::kExtend);
    const MapGravity g = system.gravity();
    EXPECT_TRUE(g.ready);
    EXPECT_EQ(g.g_w, Eigen::Vector3d(0.1, -0.2, -9.8));
    EXPECT_EQ(system.keyframe_states().size(), system.num_keyframes() - 1);  // all but the first
    system.shutdown();
    const std::string again = tmp_path("inertial_again.pvbmap");
    system.save_map(again, R"({"station": "fr3"})");
    EXPECT_TRUE(read_file(again) == bytes);
  }
  System moved(imu_settings(T_b_c * geom::SE3d(Eigen::Translation3d(0.002, 0, 0))), sync_options());
  try {
    moved.load_map(p, MapStart::kLocalise);
    ADD_FAILURE() << "loaded";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("IMU.T_b_c1: the map's and this run's differ by 2.00 mm and 0.000 deg"),
              std::string::npos)
        << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  const Settings s = read_settings(kTum3);
  System camera(s, sync_options());
  camera.load_map(p, MapStart::kLocalise);
  EXPECT_FALSE(camera.gravity().ready);
  const FrameResult r = camera.track(pair_frames(s).front());
  ASSERT_TRUE(r.T_w_c) << r.tracking.failure;
  EXPECT_LT(r.T_w_c->translation().norm(), 0.01);
}

// A map made with an accelerometer alone holds a tilt, not the IMU's full
// state: a run with an IMU that extends it initialises the IMU again from
// its new keyframes (gravity not trusted yet, the tilt kept as the guess);
// one that localises in it uses the tilt at once.
TEST_F(MapFile, AnImuRunExtendingATiltOnlyMapInitialisesItsImu) {
  const geom::SE3d T_b_c = test::tiny_inertial_settings().T_b_c;
  const std::string p = tmp_path("tilt_pair.pvbmap");
  write_file(p, inertial_pair_map(bytes_, path_, T_b_c, sensor::SensorSetup::kCameraAccel));
  System extend(imu_settings(T_b_c), sync_options());
  extend.load_map(p, MapStart::kExtend);
  EXPECT_FALSE(extend.gravity().ready);
  EXPECT_EQ(extend.gravity().g_w, Eigen::Vector3d(0.1, -0.2, -9.8));
  System localise(imu_settings(T_b_c), sync_options());
  localise.load_map(p, MapStart::kLocalise);
  EXPECT_TRUE(localise.gravity().ready);
}

/// The pair's map with a look-alike place added: its first keyframe again
/// at its own place observing its own points (so that their covisibility
/// group outscores a lone keyframe, as a well-mapped place does) and a copy
/// `shift_m` along x with its points moved along (a repeated texture two
/// tiles away).  With `hidden`, that copy keeps only one of the words (it
/// ranks below the full copies), and a third copy at the far place with all
/// the words but no points, covisible with it, is what the bag of words
/// finds there.  Returns the bytes and the id of the copy with the points.
std::pair<std::string, std::uint64_t> lookalike_map(const std::string& bytes, const std::string& file,
                                                    double shift_m, bool hidden) {
  const MapFileHeader h = read_map_header(bytes, file);
  Map map;
  decode_map(bytes, file, h, camera_for(h.settings), &map);
  std::lock_guard<std::mutex> lock(map.mutex());
  const auto kf0 = map.keyframes().begin()->second;
  const auto twin = map.create_keyframe(kf0->frame());
  const Eigen::Vector3d d_w(shift_m, 0, 0);
  Frame moved = kf0->frame();
  moved.T_c_w = kf0->T_c_w() * geom::SE3d(Eigen::Translation3d(-d_w));
  std::fill(moved.map_points.begin(), moved.map_points.end(), nullptr);
  const auto far = map.create_keyframe(moved);
  twin->set_bow(kf0->bow(), kf0->features_by_node());
  if (hidden)
    far->set_bow({kf0->bow().front()}, kf0->features_by_node());
  else
    far->set_bow(kf0->bow(), kf0->features_by_node());
  for (const auto& kf : {twin, far}) kf->set_session(kf0->session());
  for (std::size_t i = 0; i < kf0->map_points().size(); ++i) {
    const auto& mp = kf0->map_points()[i];
    if (!mp || mp->bad()) continue;
    mp->add_observation(twin, i);
    const auto copy = map.create_point(mp->p_w() + d_w, far);
    copy->add_observation(far, i);
    far->set_map_point(i, copy);
  }
  for (const auto& kf : {kf0, twin, far}) kf->update_connections();
  far->change_parent(kf0);
  if (hidden) {
    const auto blind = map.create_keyframe(moved);
    blind->set_session(kf0->session());
    blind->set_bow(kf0->bow(), kf0->features_by_node());
    blind->add_connection(far, 100);
    far->add_connection(blind, 100);
    blind->change_parent(kf0);
  }
  return {encode_map(map, h.settings, h.sessions, h.app_json), far->id()};
}

TEST_F(MapFile, ALookAlikePlaceOutsideTheCandidateGroupsKeepsTheFrameLost) {
  const std::string p = tmp_path("lookalike.pvbmap");
  write_file(p, lookalike_map(bytes_, path_, 6.0, false).first);
  const auto first_frame = [&](int lookalikes) {
    Settings s = read_settings(kTum3);
    s.reloc_lookalikes = lookalikes;
    System system(s, sync_options());
    system.load_map(p, MapStart::kLocalise);
    return system.track(pair_frames(s).front());
  };
  // Checked against the best-scoring keyframes one by one, the place 6 m
  // away matches too: ambiguous, no pose.
  const FrameResult checked = first_frame(10);
  EXPECT_FALSE(checked.T_w_c);
  EXPECT_NE(checked.tracking.failure.find("look-alike keyframe"), std::string::npos) << checked.tracking.failure;
  // The grouped candidates alone are all at the first place: relocalised.
  const FrameResult grouped = first_frame(0);
  ASSERT_TRUE(grouped.T_w_c) << grouped.tracking.failure;
  EXPECT_LT(grouped.T_w_c->translation().norm(), 0.01);
}

// A best-scoring keyframe at the other place that cannot match itself is
// tried through its covisibles: the one that matches there keeps the frame
// lost.
TEST_F(MapFile, ALookAlikePlaceIsTriedThroughTheCovisiblesOfItsKeyframe) {
  const std::string p = tmp_path("hidden_lookalike.pvbmap");
  const auto [bytes, far_id] = lookalike_map(bytes_, path_, 6.0, true);
  write_file(p, bytes);
  Settings s = read_settings(kTum3);
  s.reloc_lookalikes = 3;  // the first keyframe, its twin and the copy without points
  System system(s, sync_options());
  system.load_map(p, MapStart::kLocalise);
  const FrameResult r = system.track(pair_frames(s).front());
  EXPECT_FALSE(r.T_w_c);
  EXPECT_NE(r.tracking.failure.find("look-alike keyframe " + std::to_string(far_id) + " matched at a place 6.0"),
            std::string::npos)
      << r.tracking.failure;
}

// --- Framing and size ---------------------------------------------------------

TEST_F(MapFile, AFramingOrChecksumErrorNamesItsSectionAndAByteInIt) {
  const std::string tiny = test::tiny_map();
  std::size_t at = 16;
  for (const char* tag : {"HEAD", "KEYF", "POIN", "GRAP", "BOWV", "META"}) {
    const std::uint64_t length = test::get_u64(tiny, at + 4);
    std::string damaged = tiny;
    if (length > 0)
      damaged[at + 12 + length / 2] ^= 0x20;
    else
      damaged[at + 12] ^= 0x20;  // an empty payload: its checksum
    const std::string sum =
        std::to_string(12 + length) + " (file byte " + std::to_string(at + 12 + length) + ")";
    EXPECT_NE(load_error(damaged, "damaged.pvbmap")
                  .find(std::string(tag) + " section at byte " + sum + ": checksum does not match"),
              std::string::npos)
        << tag << ": " << load_error(damaged, "damaged.pvbmap");
    const std::string cut = load_error(tiny.substr(0, at + 12 + length / 2), "cut.pvbmap");
    EXPECT_NE(cut.find(std::string(tag) + " section at byte 4 (file byte " + std::to_string(at + 4) +
                       "): a payload of " + std::to_string(length) + " bytes"),
              std::string::npos)
        << cut;
    at += 12 + length + 8;
  }
  const std::size_t head_end = 16 + 12 + test::get_u64(tiny, 20) + 8;  // the file cut after HEAD
  EXPECT_NE(load_error(tiny.substr(0, head_end), "cut.pvbmap")
                .find("KEYF section at byte 0 (file byte " + std::to_string(head_end) + "): missing"),
            std::string::npos);
}

/// `bytes` written to a file then stretched to `size` bytes (a sparse file:
/// nothing is written past the map); the error loading it ("" when none)
/// and how long that took.
std::pair<std::string, double> load_stretched(const std::string& bytes, std::uint64_t size) {
  const std::string p = tmp_path("stretched.pvbmap");
  write_file(p, bytes);
  const int fd = ::open(p.c_str(), O_WRONLY);
  EXPECT_GE(fd, 0);
  EXPECT_EQ(::ftruncate(fd, static_cast<off_t>(size)), 0);
  ::close(fd);
  System system(read_settings(kTum3), sync_options());
  const auto t0 = std::chrono::steady_clock::now();
  std::string what;
  try {
    system.load_map(p, MapStart::kLocalise);
  } catch (const Error& e) {
    what = e.what();
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::remove(p.c_str());
  return {what, s};
}

TEST_F(MapFile, AFileLargerThanTheLimitIsRefusedBeforeItsBytesAreRead) {
  const auto [what, seconds] = load_stretched(bytes_, std::uint64_t(20) << 30);
  EXPECT_NE(what.find("21474836480 bytes, larger than a map file may be (4294967296 bytes, 4 GiB)"),
            std::string::npos)
      << what;
  EXPECT_LT(seconds, 1.0);
}

TEST_F(MapFile, AFileWhoseSectionsDoNotAddUpIsRefusedBeforeItsBytesAreRead) {
  const std::uint64_t size = std::uint64_t(3) << 30;  // within the limit, above 2^31
  const auto [what, seconds] = load_stretched(bytes_, size);
  EXPECT_NE(what.find(std::to_string(size - bytes_.size()) +
                      " bytes after the last section (from file byte " + std::to_string(bytes_.size()) + ")"),
            std::string::npos)
      << what;
  EXPECT_LT(seconds, 1.0);
}

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
  for (ImpossibleMap& m : impossible_inertial_maps()) maps.push_back(std::move(m));
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
  for (const char* seed : {"tiny.pvbmap", "tiny_inertial.pvbmap", "fr3_pair_600.pvbmap"}) {
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
