// Map files on a real Kinect pair (TUM fr3 long_office_household): a map
// made on the pair is saved, loaded and saved again byte for byte; every
// kind of bad file is one IoError or ConfigError naming the file; and a
// run that loads the map to localise in it starts lost, relocalises on the
// first frame at the map's own pose, never adds a keyframe, and tracks the
// second frame where the mapping run put it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

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

std::string tmp_path(const std::string& name) {
  const char* dir = std::getenv("TEST_TMPDIR");
  return std::string(dir ? dir : "/tmp") + "/map_file_" + name;
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
  future[8] = 2;  // version, little-endian u32 after the magic
  EXPECT_NE(load_error(future, "future.pvbmap").find("version 2 is newer"), std::string::npos);
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

}  // namespace
}  // namespace pvb::slam
