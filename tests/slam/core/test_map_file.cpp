// Map files on a real Kinect pair (TUM fr3 long_office_household): a map
// made on the pair is saved, loaded and saved again byte for byte; every
// kind of bad file is one IoError or ConfigError naming the file; and a
// run that loads the map to localise in it starts lost, relocalises on the
// first frame at the map's own pose, never adds a keyframe, and tracks the
// second frame where the mapping run put it.  The maps made impossible one
// way at a time, the fuzz corpus and the inertial state's checks are in
// test_map_file_checks.cpp.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>

#include "map_file_edit.hpp"
#include "map_file_pair.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/slam/core/map_file.hpp"
#include "pvb/slam/core/system.hpp"
#include "shared_data.hpp"

namespace pvb::slam {
namespace {

using test::kTum3;
using test::pair_frames;
using test::sync_options;

/// A file of this test process (CTest runs the tests of this program as
/// processes side by side).
std::string tmp_path(const std::string& name) {
  const char* dir = std::getenv("TEST_TMPDIR");
  return std::string(dir ? dir : "/tmp") + "/map_file_" + std::to_string(::getpid()) + "_" + name;
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

TEST_F(MapFile, AMapDecodedIntoASpillHoldsItsFeaturesThereAndEncodesTheFileItCameFrom) {
  const MapFileHeader h = read_map_header(bytes_, path_);
  auto spill = std::make_shared<FeatureSpill>();
  Map map;
  decode_map(MapFileBytes::in_memory(bytes_, path_), h, camera_for(h.settings), &map, spill);
  std::lock_guard<std::mutex> lock(map.mutex());
  ASSERT_FALSE(map.keyframes().empty());
  for (const auto& [id, kf] : map.keyframes()) {
    EXPECT_TRUE(kf->frame().features_spilled()) << id;
    const FrameMemory m = kf->frame().memory();
    EXPECT_EQ(m.keypoints + m.descriptors + m.grid, 0u) << id;  // nothing of them left on the heap
    EXPECT_GT(m.spilled, 0u) << id;
  }
  EXPECT_EQ(map.memory().keyframes_spilled, map.keyframes().size());
  EXPECT_GT(spill->stats().live_bytes(), 0u);
  EXPECT_EQ(encode_map(map, h.settings, h.sessions, h.app_json), bytes_);
}

TEST_F(MapFile, ARunWithTheSpillLoadsTheMapIntoItAndSavesTheSameBytesFromIt) {
  Settings with = read_settings(kTum3), without = with;
  with.spill_features = true;
  without.spill_features = false;
  System spilled(with, sync_options()), in_memory(without, sync_options());
  spilled.load_map(path_, MapStart::kExtend);
  in_memory.load_map(path_, MapStart::kExtend);
  const SystemMemory a = spilled.memory(), b = in_memory.memory();
  EXPECT_EQ(a.map.keyframes_spilled, a.map.keyframes);
  EXPECT_EQ(b.map.keyframes_spilled, 0u);
  EXPECT_GT(a.feature_spill.live_bytes(), 0u);
  EXPECT_LT(a.map.keyframe_bytes.total(), b.map.keyframe_bytes.total());
  spilled.shutdown();
  const std::string again = tmp_path("from_spill.pvbmap");
  spilled.save_map(again, R"({"station": "fr3"})");
  EXPECT_TRUE(read_file(again) == bytes_);
}

/// The error decoding `bytes` throws ("" when none), read in memory or from
/// a file in pieces of `piece_bytes`.
std::string decode_error(const std::string& bytes, const std::string& path, std::uint64_t piece_bytes) {
  try {
    std::optional<MapFileBytes> src;
    if (piece_bytes == 0) {
      src = MapFileBytes::in_memory(bytes, path);
    } else {
      write_file(path, bytes);
      src = MapFileBytes::open(path, piece_bytes);
    }
    const MapFileHeader h = read_map_header(*src);
    Map map;
    decode_map(*src, h, camera_for(h.settings), &map);
    std::lock_guard<std::mutex> lock(map.mutex());
    EXPECT_EQ(encode_map(map, h.settings, h.sessions, h.app_json), bytes);
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

TEST_F(MapFile, AFileReadInPiecesGivesTheMapAndTheErrorsOfOneReadWhole) {
  // Pieces of 1 byte, and of an odd size that splits values and descriptors.
  const std::string p = tmp_path("pieces.pvbmap");
  for (std::uint64_t piece : {std::uint64_t(1), std::uint64_t(37), std::uint64_t(4093)})
    EXPECT_EQ(decode_error(bytes_, p, piece), "") << piece;
  // A payload byte flipped (the checksum check streams the section) and a
  // file cut short: the same message either way.
  std::string flipped = bytes_;
  flipped[bytes_.size() / 2] = static_cast<char>(flipped[bytes_.size() / 2] ^ 0x40);
  const std::string in_memory = decode_error(flipped, p, 0);
  EXPECT_NE(in_memory.find("checksum does not match"), std::string::npos) << in_memory;
  EXPECT_EQ(decode_error(flipped, p, 37), in_memory);
  for (std::size_t cut : {bytes_.size() / 3, bytes_.size() - 9}) {
    const std::string head = decode_error(bytes_.substr(0, cut), p, 0);
    EXPECT_FALSE(head.empty());
    EXPECT_EQ(decode_error(bytes_.substr(0, cut), p, 37), head);
  }
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

TEST_F(MapFile, APointBeyondTheReadersBoundIsLeftOutSoTheFileLoads) {
  // Nearly parallel rays can triangulate a point a thousand kilometres
  // off; a file holding it would be refused by its own reader.
  const MapFileHeader h = read_map_header(bytes_, path_);
  Map map;
  decode_map(bytes_, path_, h, camera_for(h.settings), &map);
  std::lock_guard<std::mutex> lock(map.mutex());
  const std::size_t points = map.num_points();
  map.points().begin()->second->set_p_w(Eigen::Vector3d(5.4e5, 5.4e5, -2.1e6));
  const std::string bytes = encode_map(map, h.settings, h.sessions, h.app_json);
  const MapFileHeader h2 = read_map_header(bytes, path_);
  Map loaded;
  EXPECT_NO_THROW(decode_map(bytes, path_, h2, camera_for(h2.settings), &loaded));
  EXPECT_EQ(loaded.num_points(), points - 1);
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
  future[8] = 4;  // version, little-endian u32 after the magic
  EXPECT_NE(load_error(future, "future.pvbmap").find("version 4 is newer than this build reads (3)"),
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
                              sensor::SensorSetup setup = sensor::SensorSetup::kCameraImu,
                              const std::function<void(Map&)>& give_state = test::give_tiny_inertial_state) {
  const MapFileHeader h = read_map_header(bytes, file);
  Map map;
  decode_map(bytes, file, h, camera_for(h.settings), &map);
  std::lock_guard<std::mutex> lock(map.mutex());
  give_state(map);
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

Settings wheel_settings(const geom::SE3d& T_b_c) {
  Settings s = imu_settings(T_b_c);
  s.motion.setup = sensor::SensorSetup::kCameraImuWheels;
  s.motion.robot.present = true;
  return s;
}

// A map's wheel fit is taken over by a run whose wheels are those it was
// fitted to (the same described radius and track, the calibration on),
// which saves it again unchanged; any other run drops it and says why.
TEST_F(MapFile, AWheelFitIsTakenOverOnlyForTheWheelsItWasFittedTo) {
  const geom::SE3d T_b_c = test::tiny_inertial_settings().T_b_c;
  const std::string p = tmp_path("wheel_pair.pvbmap");
  const std::string bytes =
      inertial_pair_map(bytes_, path_, T_b_c, sensor::SensorSetup::kCameraImuWheels, test::give_tiny_wheel_fit);
  write_file(p, bytes);
  {
    System system(wheel_settings(T_b_c), sync_options());
    const MapLoadInfo info = system.load_map(p, MapStart::kExtend);
    EXPECT_TRUE(info.wheel_fit_taken);
    EXPECT_EQ(info.wheel_fit_note, "");
    EXPECT_EQ(system.wheels().intervals, 48);
    EXPECT_EQ(system.wheels().calibration, (WheelCalibration{0.998, 1.002, 1.05}));
    system.shutdown();
    const std::string again = tmp_path("wheel_again.pvbmap");
    system.save_map(again, R"({"station": "fr3"})");
    EXPECT_TRUE(read_file(again) == bytes);
  }
  Settings wider = wheel_settings(T_b_c);
  wider.motion.robot.drive.track_m = 0.45;
  System other(wider, sync_options());
  const MapLoadInfo info = other.load_map(p, MapStart::kLocalise);
  EXPECT_FALSE(info.wheel_fit_taken);
  EXPECT_EQ(info.wheel_fit_note,
            "not used: fitted to wheels of radius 0.1 m and track 0.42 m as described, this run's are 0.1 m and "
            "0.45 m");
  EXPECT_EQ(other.wheels().intervals, 0);
  EXPECT_EQ(other.wheels().calibration, WheelCalibration{});
  Settings uncalibrated = wheel_settings(T_b_c);
  uncalibrated.motion.robot.wheel_calibration.enabled = false;
  System off(uncalibrated, sync_options());
  EXPECT_EQ(off.load_map(p, MapStart::kLocalise).wheel_fit_note, "not used: Robot.CalibrateWheels is 0");
  System camera(read_settings(kTum3), sync_options());
  EXPECT_EQ(camera.load_map(p, MapStart::kLocalise).wheel_fit_note, "not used: this run reads no wheels");
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

}  // namespace
}  // namespace pvb::slam
