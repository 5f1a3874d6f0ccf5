// LocalMapping on its worker thread: keyframes queued while it works stop
// its next local BA (ORB-SLAM2's InsertKeyFrame / InterruptBA), inline
// (synchronous) mapping never does, and the counters add up.
#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <thread>

#include "pvb/slam/core/feature_spill.hpp"
#include "pvb/slam/core/local_mapping.hpp"
#include "pvb/slam/core/map.hpp"

namespace pvb::slam {
namespace local_mapping_test {

std::shared_ptr<const CameraModel> camera() {
  static auto cam =
      std::make_shared<const CameraModel>(CameraModel::make(StereoIntrinsics{}, 640, 480, {}, 3.0, 1.2, 8));
  return cam;
}

/// A frame with n keypoints on a row, depth 1 m everywhere, at the origin.
Frame make_frame(std::uint64_t id, int n) {
  OrbFeatures f;
  for (int i = 0; i < n; ++i)
    f.keypoints.emplace_back(cv::Point2f(100.0f + 10.0f * i, 200.0f), 31.0f, 0.0f, 0.0f, 0);
  f.descriptors = cv::Mat::zeros(n, 32, CV_8U);
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(1.0f));
  Frame fr(id, static_cast<std::int64_t>(id) * 1000, f, depth, camera());
  fr.has_pose = true;
  return fr;
}

/// Keyframe `id` observing every point of `pts` (created from the first
/// keyframe when `pts` is empty).
std::shared_ptr<KeyFrame> keyframe(Map& map, std::uint64_t id, std::vector<std::shared_ptr<MapPoint>>& pts) {
  constexpr int kPoints = 30;
  auto kf = map.create_keyframe(make_frame(id, kPoints));
  for (int i = 0; i < kPoints; ++i) {
    const auto idx = static_cast<std::size_t>(i);
    if (pts.size() < kPoints) {
      auto mp = map.create_point(kf->frame().unproject_world(idx), kf);
      mp->add_observation(kf, idx);
      mp->compute_distinctive_descriptor();
      mp->update_normal_and_depth();
      pts.push_back(mp);
    }
    kf->set_map_point(idx, pts[idx]);  // observations are added when local mapping processes kf
  }
  return kf;
}

LocalMappingOptions options() {
  LocalMappingOptions o;
  o.align_patches = false;  // no images in these frames
  return o;
}

TEST(LocalMapping, InlineMappingNeverAsksToStopBa) {
  Map map;
  LocalMapping mapping(map, camera(), options());
  std::vector<std::shared_ptr<MapPoint>> pts;
  for (std::uint64_t id = 0; id < 3; ++id) {
    mapping.insert(keyframe(map, id, pts));
    EXPECT_FALSE(mapping.ba_stop_requested());
  }
  const LocalMappingStats s = mapping.stats();
  EXPECT_EQ(s.keyframes, 3);
  EXPECT_EQ(s.local_ba, 3);  // the queue is always empty inline
  EXPECT_EQ(s.local_ba_stopped, 0);
  EXPECT_TRUE(mapping.idle());
}

// The worker is held at the map lock with a keyframe in hand while two more
// are queued: the queue raises the stop flag; the held keyframe skips its
// BA (keyframes wait), the last one clears the flag and runs its BA to the end.
TEST(LocalMapping, QueuedKeyframeRaisesTheStopFlagUntilTheNextBa) {
  Map map;
  LocalMapping mapping(map, camera(), options());
  std::vector<std::shared_ptr<MapPoint>> pts;
  mapping.insert(keyframe(map, 0, pts));  // inline: not started yet
  auto kf1 = keyframe(map, 1, pts);
  auto kf2 = keyframe(map, 2, pts);
  {
    std::unique_lock<std::mutex> lock(map.mutex());
    mapping.start();
    mapping.insert(kf1);
    EXPECT_TRUE(mapping.ba_stop_requested());
    mapping.insert(kf2);
    EXPECT_TRUE(mapping.ba_stop_requested());
    EXPECT_FALSE(mapping.idle());
  }
  mapping.stop();
  EXPECT_FALSE(mapping.ba_stop_requested());  // cleared before kf2's BA
  const LocalMappingStats s = mapping.stats();
  EXPECT_EQ(s.keyframes, 3);
  EXPECT_EQ(s.local_ba, 2);  // kf0 and kf2; kf1 found kf2 waiting
  EXPECT_EQ(s.local_ba_stopped, 0);
  EXPECT_TRUE(mapping.idle());
  for (const auto& mp : pts) EXPECT_EQ(mp->num_observations(), 6);  // three RGB-D observations each
}

// A keyframe queued while the worker's local BA runs (here from the BA's
// first iteration, on the worker itself) stops that BA; the queued keyframe
// then gets a BA of its own, run to the end.
TEST(LocalMapping, KeyframeQueuedDuringTheBaStopsIt) {
  Map map;
  LocalMapping* self = nullptr;
  std::shared_ptr<KeyFrame> late;
  bool queued = false;
  LocalMappingOptions opt = options();
  opt.ba.on_iteration = [&] {
    if (late && !queued) {
      queued = true;
      self->insert(late);
    }
  };
  LocalMapping mapping(map, camera(), opt);
  self = &mapping;
  std::vector<std::shared_ptr<MapPoint>> pts;
  mapping.insert(keyframe(map, 0, pts));  // inline, before start(): no keyframe to queue yet
  auto kf1 = keyframe(map, 1, pts);
  late = keyframe(map, 2, pts);
  mapping.start();
  mapping.insert(kf1);
  // stop() would refuse kf2 if it closed the queue before the BA queued it:
  // wait until both are done (kf2 is queued before kf1 counts as done).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!mapping.idle() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  mapping.stop();
  const LocalMappingStats s = mapping.stats();
  EXPECT_TRUE(queued);
  EXPECT_EQ(s.keyframes, 3);
  EXPECT_EQ(s.local_ba, 3);
  EXPECT_EQ(s.local_ba_stopped, 1);
  EXPECT_FALSE(mapping.ba_stop_requested());
  EXPECT_TRUE(mapping.idle());
}

/// Keyframe `id` as keyframe() makes it, holding a (blank) grey pyramid.
std::shared_ptr<KeyFrame> keyframe_with_pyramid(Map& map, std::uint64_t id,
                                                std::vector<std::shared_ptr<MapPoint>>& pts) {
  auto kf = keyframe(map, id, pts);
  ImagePyramid levels;
  for (int l = 0; l < 8; ++l) levels.emplace_back(48, 64, CV_8U, cv::Scalar(0));
  kf->frame_for_alignment().pyramid = std::make_shared<const ImagePyramid>(std::move(levels));
  return kf;
}

// A keyframe keeps its pyramid while it is among the newest
// pyramid_window keyframes or covisible with the newest, and loses it for
// good once it is neither; memory counts the keyframes without one.
TEST(LocalMapping, KeyframesLeavingTheLocalMapReleaseTheirPyramid) {
  Map map;
  LocalMappingOptions opt;
  opt.pyramid_window = 1;
  LocalMapping mapping(map, camera(), opt);
  std::vector<std::shared_ptr<MapPoint>> a, b, c;
  const auto kf0 = keyframe_with_pyramid(map, 0, a);
  mapping.insert(kf0);
  EXPECT_TRUE(kf0->frame().pyramid);
  const auto kf1 = keyframe_with_pyramid(map, 1, b);  // sees none of kf0's points
  mapping.insert(kf1);
  EXPECT_FALSE(kf0->frame().pyramid);
  EXPECT_TRUE(kf1->frame().pyramid);
  const auto kf2 = keyframe_with_pyramid(map, 2, b);  // covisible with kf1
  mapping.insert(kf2);
  EXPECT_TRUE(kf1->frame().pyramid) << "covisible with the newest keyframe";
  EXPECT_TRUE(kf2->frame().pyramid);
  const auto kf3 = keyframe_with_pyramid(map, 3, c);  // a new place
  mapping.insert(kf3);
  EXPECT_FALSE(kf1->frame().pyramid);
  EXPECT_FALSE(kf2->frame().pyramid);
  EXPECT_TRUE(kf3->frame().pyramid);
  const MapMemory m = map.memory();
  EXPECT_EQ(m.keyframes, 4u);
  EXPECT_EQ(m.keyframes_outside, 3u);
  EXPECT_EQ(m.outside_bytes.frame.pyramid, 0u);
  EXPECT_GT(m.keyframe_bytes.frame.pyramid, 0u);
}

// With a feature spill, a keyframe leaving the local map moves its
// features into it (the same values, off the heap); the spill's pages are
// dropped from memory every spill_release_every keyframes and read back
// where the keyframe is used again.
TEST(LocalMapping, KeyframesLeavingTheLocalMapSpillTheirFeatures) {
  Map map;
  LocalMappingOptions opt = options();
  opt.pyramid_window = 1;
  opt.spill_release_every = 1;
  LocalMapping mapping(map, camera(), opt);
  const auto spill = std::make_shared<FeatureSpill>();
  mapping.set_feature_spill(spill);
  std::vector<std::shared_ptr<MapPoint>> a, b;
  const auto kf0 = keyframe(map, 0, a);
  const std::vector<Keypoint> keys0(kf0->frame().keys_un.begin(), kf0->frame().keys_un.end());
  const cv::Mat descriptors0 = kf0->frame().descriptors.clone();
  mapping.insert(kf0);
  EXPECT_FALSE(kf0->frame().features_spilled()) << "the newest keyframe";
  const auto kf1 = keyframe(map, 1, b);  // sees none of kf0's points
  mapping.insert(kf1);
  ASSERT_TRUE(kf0->frame().features_spilled());
  EXPECT_FALSE(kf1->frame().features_spilled());
  EXPECT_GT(spill->stats().live_bytes(), 0u);
  EXPECT_EQ(spill->stats().releases, 1u);
  EXPECT_EQ(spill->resident_bytes(), 0u);
  ASSERT_EQ(kf0->frame().keys_un.size(), keys0.size());
  for (std::size_t i = 0; i < keys0.size(); ++i) EXPECT_EQ(kf0->frame().keys_un[i].pt, keys0[i].pt);
  EXPECT_EQ(cv::norm(kf0->frame().descriptors, descriptors0, cv::NORM_HAMMING), 0.0);
  EXPECT_EQ(kf0->frame().features_in_area(100.0f, 200.0f, 5.0f).size(), 1u);
  const FrameMemory f = kf0->frame().memory();
  EXPECT_EQ(f.keypoints + f.descriptors, 0u);
  EXPECT_GE(f.spilled, keys0.size() * 2 * sizeof(Keypoint) + descriptors0.total());
  EXPECT_EQ(map.memory().keyframes_spilled, 1u);
}

TEST(LocalMapping, StatsAsJson) {
  LocalMappingStats s;
  s.keyframes = 12;
  s.local_ba = 9;
  s.local_ba_stopped = 4;
  s.busy_ms = 250.5;
  s.local_ba_ms = 180.25;
  EXPECT_EQ(to_json(s), "{\"keyframes\": 12, \"local_ba\": 9, \"local_ba_stopped\": 4, \"busy_ms\": 250.5, "
                        "\"local_ba_ms\": 180.25}");
}

}  // namespace local_mapping_test
}  // namespace pvb::slam
