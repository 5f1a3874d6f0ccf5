// Map-point culling and keyframe culling rules, and the covisibility graph /
// spanning tree bookkeeping, on small hand-built maps.
#include <gtest/gtest.h>

#include <algorithm>

#include "pvb/common/memory.hpp"
#include "pvb/slam/core/feature_spill.hpp"
#include "pvb/slam/core/local_mapping.hpp"
#include "pvb/slam/core/map.hpp"
#include "pvb/slam/core/matcher.hpp"

namespace pvb::slam {
namespace map_rules_test {

std::shared_ptr<const CameraModel> camera() {
  static auto cam = std::make_shared<const CameraModel>(
      CameraModel::make(StereoIntrinsics{}, 640, 480, {}, 3.0, 1.2, 8));
  return cam;
}

/// A frame with n keypoints on a row, all at `octave`, depth 1 m everywhere.
Frame make_frame(std::uint64_t id, int n, int octave = 0) {
  OrbFeatures f;
  for (int i = 0; i < n; ++i) {
    cv::KeyPoint k(cv::Point2f(100.0f + 5.0f * i, 100.0f), 31.0f, 0.0f, 0.0f, octave);
    f.keypoints.push_back(k);
  }
  f.descriptors = cv::Mat::zeros(n, 32, CV_8U);
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(1.0f));
  Frame fr(id, static_cast<std::int64_t>(id) * 1000, f, depth, camera());
  fr.has_pose = true;
  return fr;
}

/// n keyframes sharing `n_points` points, each point observed by the
/// keyframes listed in observers (indices into the returned vector).
struct SmallMap {
  Map map;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  std::vector<std::shared_ptr<MapPoint>> pts;
};

void observe(const std::shared_ptr<MapPoint>& mp, const std::shared_ptr<KeyFrame>& kf, std::size_t idx) {
  mp->add_observation(kf, idx);
  kf->set_map_point(idx, mp);
}

TEST(MapPointCulling, RecentPointRule) {
  // found / visible below 25 %: erase at once
  EXPECT_EQ(recent_point_rule(0.2, 10, 5, 5), CullDecision::kErase);
  // two keyframes after creation with <= 3 observations (RGB-D: 2 per keyframe): erase
  EXPECT_EQ(recent_point_rule(0.9, 3, 5, 7), CullDecision::kErase);
  EXPECT_EQ(recent_point_rule(0.9, 4, 5, 7), CullDecision::kKeep);
  // one keyframe after creation: still on trial
  EXPECT_EQ(recent_point_rule(0.9, 2, 5, 6), CullDecision::kKeep);
  // three keyframes after creation with enough observations: survived
  EXPECT_EQ(recent_point_rule(0.9, 6, 5, 8), CullDecision::kDone);
}

TEST(MapPointCulling, PointWithTooFewObservationsBecomesBad) {
  Map map;
  auto kf0 = map.create_keyframe(make_frame(0, 4));
  auto kf1 = map.create_keyframe(make_frame(1, 4));
  auto mp = map.create_point(Eigen::Vector3d(0, 0, 1), kf0);
  observe(mp, kf0, 0);
  observe(mp, kf1, 0);
  EXPECT_EQ(mp->num_observations(), 4);  // two RGB-D observations count 2 each
  mp->erase_observation(kf1->id());
  EXPECT_TRUE(mp->bad());
  EXPECT_EQ(kf0->map_points()[0], nullptr);
  map.remove_bad_points();
  EXPECT_EQ(map.num_points(), 0u);
}

TEST(MapPointObservations, KeptInAscendingKeyFrameIdsWhateverTheOrderAdded) {
  Map map;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  for (std::uint64_t i = 0; i < 5; ++i) kfs.push_back(map.create_keyframe(make_frame(i, 4)));
  auto mp = map.create_point(Eigen::Vector3d(0, 0, 1), kfs[0]);
  for (std::size_t k : {3, 0, 4, 1}) observe(mp, kfs[k], k % 4);
  observe(mp, kfs[3], 2);  // a second observation by keyframe 3 is refused
  std::vector<std::uint64_t> ids;
  for (const auto& [id, o] : mp->observations()) {
    ids.push_back(id);
    EXPECT_EQ(o.kf.lock(), kfs[id]);
    EXPECT_EQ(o.idx, id % 4);
  }
  EXPECT_EQ(ids, (std::vector<std::uint64_t>{0, 1, 3, 4}));
  EXPECT_EQ(mp->num_observations(), 8);
  EXPECT_EQ(mp->index_in(3), 3);
  EXPECT_EQ(mp->index_in(2), -1);
  EXPECT_EQ(mp->observations().count(2), 0u);
  EXPECT_EQ(mp->observations().find(2), mp->observations().end());
  mp->erase_observation(1);
  mp->erase_observation(2);  // none: no change
  ids.clear();
  for (const auto& [id, o] : mp->observations()) ids.push_back(id);
  EXPECT_EQ(ids, (std::vector<std::uint64_t>{0, 3, 4}));
  EXPECT_EQ(mp->num_observations(), 6);
  EXPECT_FALSE(mp->bad());
}

TEST(MapPointObservations, EightCostAboutAQuarterOfAKilobyte) {
  // Eight observations in a sorted array: 8 x 32 bytes; the point itself
  // with its descriptor inline about 200 more.  A std::map node per
  // observation (80 bytes) and a cv::Mat descriptor came to about 1,150.
  Map map;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  for (std::uint64_t i = 0; i < 8; ++i) kfs.push_back(map.create_keyframe(make_frame(i, 1)));
  auto mp = map.create_point(Eigen::Vector3d(0, 0, 1), kfs[0]);
  const std::size_t alone = mp->memory_bytes();
  for (const auto& kf : kfs) observe(mp, kf, 0);
  mp->compute_distinctive_descriptor();
  EXPECT_EQ(mp->memory_bytes() - alone, heap_block_bytes(8 * sizeof(MapPoint::Observations::value_type)));
  EXPECT_EQ(sizeof(MapPoint::Observations::value_type), 32u);
  EXPECT_LT(mp->memory_bytes(), 560u);
}

// A loop's correction updates every point of the map, and most of their
// keyframes hold their keypoints in the feature file: the point keeps what
// it needs of each observation (pyramid level, depth or not), so updating
// it or dropping an observation reads none of them back into memory.
TEST(MapPointObservations, UpdatingAPointReadsNoneOfItsKeyframesSpilledFeatures) {
  Map map;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  for (std::uint64_t i = 0; i < 3; ++i) kfs.push_back(map.create_keyframe(make_frame(i, 100, 2)));
  auto mp = map.create_point(Eigen::Vector3d(0, 0, 2), kfs[0]);
  for (const auto& kf : kfs) observe(mp, kf, 7);
  EXPECT_EQ(mp->num_observations(), 6);
  auto spill = std::make_shared<FeatureSpill>(std::string(), std::size_t(1) << 20);
  for (const auto& kf : kfs) kf->spill_features(spill);
  spill->release_resident();
  ASSERT_EQ(spill->resident_bytes(), 0u);

  mp->update_normal_and_depth();
  EXPECT_NEAR(mp->max_distance(), 1.2 * 2.0 * 1.2 * 1.2, 1e-9);  // 2 m from its reference, seen at level 2
  mp->erase_observation(kfs[2]->id());
  EXPECT_EQ(mp->num_observations(), 4);
  EXPECT_EQ(spill->resident_bytes(), 0u);
}

TEST(MapPointDescriptor, NoneUntilComputedThenTheLeastMedianDistanceObservation) {
  Map map;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  // Keypoint 0 of the keyframes has its first 0, 2, 3, 4, 7 bytes set: the
  // one with 3 is 8, 8, 24 and 32 bits from the others, the least median.
  const int set_bytes[] = {0, 2, 3, 4, 7};
  for (std::uint64_t k = 0; k < 5; ++k) {
    Frame f = make_frame(k, 2);
    f.descriptors.row(0).colRange(0, set_bytes[k]).setTo(255);
    kfs.push_back(map.create_keyframe(f));
  }
  auto mp = map.create_point(Eigen::Vector3d(0, 0, 1), kfs[0]);
  EXPECT_EQ(mp->descriptor(), nullptr);
  mp->compute_distinctive_descriptor();  // no observation yet: still none
  EXPECT_EQ(mp->descriptor(), nullptr);
  for (const auto& kf : kfs) observe(mp, kf, 0);
  mp->compute_distinctive_descriptor();
  ASSERT_NE(mp->descriptor(), nullptr);
  const unsigned char* row = kfs[2]->frame().descriptors.ptr<unsigned char>(0);
  EXPECT_TRUE(std::equal(row, row + 32, mp->descriptor()));
  EXPECT_NE(mp->descriptor(), row);  // a copy: the point keeps it when the keyframe goes
}

TEST(MapPointDescriptor, ChosenAmongTheNewestViewsOnly) {
  // 40 observations: keyframes 0-19 alike (all bits set), keyframes 20-39
  // one bit each, 2 bits apart.  Over all 40 an old one has the least
  // median (0); among the newest 32 (12 old, 20 new) a new one (2 against
  // 255).
  Map map;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  for (std::uint64_t k = 0; k < 40; ++k) {
    Frame f = make_frame(k, 1);
    if (k < 20) f.descriptors.row(0).setTo(255);
    else f.descriptors.at<unsigned char>(0, static_cast<int>(k - 20)) = 1;
    kfs.push_back(map.create_keyframe(f));
  }
  auto mp = map.create_point(Eigen::Vector3d(0, 0, 1), kfs[0]);
  for (const auto& kf : kfs) observe(mp, kf, 0);
  mp->compute_distinctive_descriptor();
  ASSERT_NE(mp->descriptor(), nullptr);
  const unsigned char* new_row = kfs[20]->frame().descriptors.ptr<unsigned char>(0);
  EXPECT_TRUE(std::equal(new_row, new_row + 32, mp->descriptor()));
  // With the newest views gone, the old ones are among the 32 again.
  for (std::uint64_t k = 20; k < 39; ++k) mp->erase_observation(k);
  mp->compute_distinctive_descriptor();
  const unsigned char* old_row = kfs[0]->frame().descriptors.ptr<unsigned char>(0);
  EXPECT_TRUE(std::equal(old_row, old_row + 32, mp->descriptor()));
}

TEST(MapPointFusion, ThePointReplacedLeavesTheMapWhenTheListFusedIsAKeyframesOwn) {
  // Keyframes 0, 1 and 2 at one pose: point a seen by keyframe 0, point b
  // at the same place by keyframes 1 and 2.  Fusing keyframe 0's own list
  // into keyframe 1 replaces a by b (more observations), which rewrites
  // that very list; a must still leave the map.
  Map map;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  for (std::uint64_t k = 0; k < 3; ++k) kfs.push_back(map.create_keyframe(make_frame(k, 4)));
  auto a = map.create_point(kfs[0]->frame().unproject_world(0), kfs[0]);
  observe(a, kfs[0], 0);
  auto b = map.create_point(kfs[1]->frame().unproject_world(0), kfs[1]);
  observe(b, kfs[1], 0);
  observe(b, kfs[2], 0);
  for (const auto& mp : {a, b}) {
    mp->compute_distinctive_descriptor();
    mp->update_normal_and_depth();
  }
  EXPECT_EQ(fuse(map, kfs[1], kfs[0]->map_points()), 1);
  EXPECT_TRUE(a->bad());
  EXPECT_EQ(kfs[0]->map_points()[0], b);
  EXPECT_EQ(b->num_observations(), 6);
  ASSERT_EQ(map.num_points(), 1u);
  EXPECT_EQ(map.points().begin()->second, b);
}

class KeyFrameCulling : public ::testing::Test {
 protected:
  // kf0..kf4, 20 points all seen by kf1; `shared` of them also by kf0, kf2, kf3.
  void build(int shared, int other_octave = 0) {
    for (std::uint64_t i = 0; i < 5; ++i)
      kfs.push_back(map.create_keyframe(make_frame(i, 20, i == 1 ? 0 : other_octave)));
    for (int p = 0; p < 20; ++p) {
      auto mp = map.create_point(Eigen::Vector3d(0, 0, 1), kfs[1]);
      observe(mp, kfs[1], p);
      if (p < shared)
        for (int k : {0, 2, 3}) observe(mp, kfs[static_cast<std::size_t>(k)], p);
      else
        observe(mp, kfs[4], p);
      mp->compute_distinctive_descriptor();
      pts.push_back(mp);
    }
  }
  Map map;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  std::vector<std::shared_ptr<MapPoint>> pts;
};

TEST_F(KeyFrameCulling, RedundantAbove90Percent) {
  build(19);  // 95 % seen by three others
  EXPECT_TRUE(is_redundant_keyframe(*kfs[1], 3.0));
}

TEST_F(KeyFrameCulling, KeptAt90PercentOrBelow) {
  build(18);  // exactly 90 %: the rule needs more than 90 %
  EXPECT_FALSE(is_redundant_keyframe(*kfs[1], 3.0));
}

TEST_F(KeyFrameCulling, CoarserObservationsDoNotCount) {
  build(20, /*other_octave=*/2);  // the others see the points two levels coarser
  EXPECT_FALSE(is_redundant_keyframe(*kfs[1], 3.0));
}

TEST_F(KeyFrameCulling, FarPointsAreIgnored) {
  build(19);
  // with a close/far threshold below every depth there are no close points
  EXPECT_FALSE(is_redundant_keyframe(*kfs[1], 0.5));
}

TEST_F(KeyFrameCulling, ErasingAKeyFrameRepairsGraphAndTree) {
  build(19);
  for (auto& kf : kfs) kf->update_connections();
  // kf1 was attached under kf0; kf2, kf3, kf4 connect to kf1 or kf0
  ASSERT_EQ(kfs[1]->parent(), kfs[0]);
  EXPECT_GE(kfs[2]->weight(kfs[1]->id()), 15);
  EXPECT_TRUE(map.erase_keyframe(kfs[1]));
  EXPECT_TRUE(kfs[1]->bad());
  EXPECT_EQ(map.num_keyframes(), 4u);
  EXPECT_EQ(kfs[2]->weight(kfs[1]->id()), 0);
  for (std::size_t k : {2u, 3u, 4u}) {
    auto p = kfs[k]->parent();
    ASSERT_NE(p, nullptr) << k;
    EXPECT_FALSE(p->bad()) << k;
  }
  for (const auto& mp : pts) EXPECT_LT(mp->index_in(kfs[1]->id()), 0);
  // the first keyframe is never erased
  EXPECT_FALSE(map.erase_keyframe(kfs[0]));
}

// A culled keyframe keeps its pose through its parent and frees what it
// held for matching: its keypoints, descriptors and grid, its bag of words,
// and its hold on the map points (a point it alone kept alive is freed).
TEST_F(KeyFrameCulling, AnErasedKeyFrameFreesWhatItHeldForMatching) {
  build(19);
  for (auto& kf : kfs) kf->update_connections();
  kfs[1]->set_bow({{3, 0.5}}, {{1, {0, 1}}});
  const geom::SE3d T_c_w = kfs[1]->T_c_w();
  // The twentieth point: seen by kf1 and kf4 only; when kf1 goes it has
  // too few observations and turns bad, and nothing else holds it.
  std::weak_ptr<MapPoint> lone = pts[19];
  pts.pop_back();
  const std::size_t held = kfs[1]->memory().total();
  ASSERT_TRUE(map.erase_keyframe(kfs[1]));
  EXPECT_EQ(kfs[1]->frame().size(), 0u);
  EXPECT_TRUE(kfs[1]->frame().descriptors.empty());
  EXPECT_TRUE(kfs[1]->map_points().empty());
  EXPECT_TRUE(kfs[1]->bow().empty());
  EXPECT_TRUE(kfs[1]->features_by_node().empty());
  EXPECT_LT(kfs[1]->memory().total(), held / 4);
  EXPECT_TRUE(kfs[1]->T_c_w_via_tree().isApprox(T_c_w, 1e-12));
  EXPECT_TRUE(lone.expired());
}

TEST(Covisibility, OrderedByWeightThenIdWithThreshold15) {
  Map map;
  std::vector<std::shared_ptr<KeyFrame>> kfs;
  for (std::uint64_t i = 0; i < 5; ++i) kfs.push_back(map.create_keyframe(make_frame(i, 40)));
  // kf0 shares 30 points with kf1, 20 with kf2, 20 with kf3 and 10 with kf4
  for (int p = 0; p < 40; ++p) {
    auto mp = map.create_point(Eigen::Vector3d(0, 0, 1), kfs[0]);
    observe(mp, kfs[0], p);
    if (p < 30) observe(mp, kfs[1], p);
    if (p < 20) observe(mp, kfs[2], p);
    if (p >= 20) observe(mp, kfs[3], p);
    if (p >= 30) observe(mp, kfs[4], p);
  }
  kfs[0]->update_connections();
  const auto best = kfs[0]->best_covisibles(-1);
  ASSERT_EQ(best.size(), 3u);  // kf4 (10 shared) is below the threshold of 15
  EXPECT_EQ(best[0], kfs[1]);
  EXPECT_EQ(best[1], kfs[2]);  // 20 shared, lower id first
  EXPECT_EQ(best[2], kfs[3]);
  EXPECT_EQ(kfs[1]->weight(0), 30);  // the other end learns the edge
  EXPECT_EQ(kfs[0]->best_covisibles(1).size(), 1u);
}

/// A provisional map a <- b <- c under its root a: each keyframe shares 20 points with the next.
TEST(ProvisionalMap, ARootStaysARootUntilItsMapIsHungUnderAnother) {
  Map map;
  const auto kf0 = map.create_keyframe(make_frame(0, 40));  // the loaded map
  const std::uint32_t p = map.begin_provisional();
  EXPECT_GT(p, 0u);
  EXPECT_NE(map.begin_provisional(), p);  // every provisional map has its own id
  std::vector<std::shared_ptr<KeyFrame>> chain;
  for (std::uint64_t i = 1; i <= 3; ++i) {
    chain.push_back(map.create_keyframe(make_frame(i, 40)));
    chain.back()->set_provisional(p);
  }
  chain[0]->make_root();
  for (std::size_t k = 0; k + 1 < chain.size(); ++k)
    for (int i = 0; i < 20; ++i) {
      auto mp = map.create_point(Eigen::Vector3d(0, 0, 1), chain[k]);
      const auto idx = static_cast<std::size_t>(20 * k) + static_cast<std::size_t>(i);  // own keypoints per pair
      observe(mp, chain[k], idx);
      observe(mp, chain[k + 1], idx);
    }
  for (const auto& kf : chain) kf->update_connections();
  // The root is never attached under its children, nor culled.
  EXPECT_EQ(chain[0]->parent(), nullptr);
  ASSERT_EQ(chain[1]->parent(), chain[0]);
  ASSERT_EQ(chain[2]->parent(), chain[1]);
  EXPECT_FALSE(map.erase_keyframe(chain[0]));
  EXPECT_EQ(map.map_of(*chain[2]), p);
  EXPECT_EQ(map.map_of(*kf0), 0u);

  // The merge hangs the last keyframe under the map's own: the path to the
  // old root is reversed, and the old root becomes an ordinary keyframe.
  chain[2]->reroot_under(kf0);
  map.merge_provisional(p, 0);
  EXPECT_EQ(chain[2]->parent(), kf0);
  EXPECT_EQ(chain[1]->parent(), chain[2]);
  EXPECT_EQ(chain[0]->parent(), chain[1]);
  EXPECT_FALSE(chain[0]->root());
  const auto kids = chain[1]->children();
  ASSERT_EQ(kids.size(), 1u);
  EXPECT_EQ(kids[0], chain[0]);
  EXPECT_TRUE(chain[0]->children().empty());
  for (const auto& kf : chain) EXPECT_EQ(map.map_of(*kf), 0u);
  EXPECT_TRUE(map.erase_keyframe(chain[0]));
}

}  // namespace map_rules_test
}  // namespace pvb::slam
