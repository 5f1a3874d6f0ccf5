// Ground-truth labels of loops and relocalisations on synthetic trajectories.
#include <gtest/gtest.h>

#include <cmath>

#include "pvb/eval/place_labels.hpp"

namespace pvb::eval {
namespace {

constexpr std::int64_t kSecond = 1'000'000'000;

/// A camera looking along +x (optical axis) driving east at 0.5 m/s for
/// 40 s, then carried back: at 40 s + t it is where it was at t.
Trajectory out_and_back() {
  Trajectory gt;
  geom::Mat3d R;  // camera z (optical axis) = world x, camera x = -world y, camera y = -world z
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  for (int i = 0; i <= 600; ++i) {
    const double t_s = i * 0.1;
    const double x = 0.5 * (t_s < 40 ? t_s : t_s - 40);
    gt.poses.push_back({static_cast<std::int64_t>(std::llround(t_s * 1e9)), geom::make_se3(R, {x, 0, 0})});
  }
  return gt;
}

/// The true relative pose of the views at ta and tb, moved by a shift along the world x.
PlaceEvent event_between(const Trajectory& gt, double ta_s, double tb_s, double shift_x_m = 0) {
  const auto pose = [&](double t_s) { return gt.poses.at(static_cast<std::size_t>(std::llround(t_s * 10))).T_w_c; };
  geom::SE3d T_w_r = pose(tb_s);
  T_w_r.translation().x() += shift_x_m;  // what a look-alike one panel along gives
  PlaceEvent e;
  e.t_ns = static_cast<std::int64_t>(std::llround(ta_s * 1e9));
  e.ref_t_ns = static_cast<std::int64_t>(std::llround(tb_s * 1e9));
  e.T_q_r = pose(ta_s).inverse() * T_w_r;
  return e;
}

TEST(PlaceLabels, ExactRelativePoseIsTrue) {
  const Trajectory gt = out_and_back();
  const auto l = label_place_event(gt, event_between(gt, 45, 5), {});
  EXPECT_TRUE(l.judged);
  EXPECT_TRUE(l.correct);
  EXPECT_NEAR(l.error_m, 0, 1e-9);
  EXPECT_NEAR(l.error_deg, 0, 1e-6);
}

TEST(PlaceLabels, OnePanelAwayIsFalse) {
  const Trajectory gt = out_and_back();
  const auto l = label_place_event(gt, event_between(gt, 45, 5, 0.99), {});
  EXPECT_TRUE(l.judged);
  EXPECT_FALSE(l.correct);
  EXPECT_NEAR(l.error_m, 0.99, 1e-9);
}

TEST(PlaceLabels, ToleranceIsInclusiveAndConfigurable) {
  const Trajectory gt = out_and_back();
  PlaceLabelOptions o;
  EXPECT_TRUE(label_place_event(gt, event_between(gt, 45, 5, 0.09), o).correct);
  EXPECT_FALSE(label_place_event(gt, event_between(gt, 45, 5, 0.11), o).correct);
  o.max_translation_m = 0.2;
  EXPECT_TRUE(label_place_event(gt, event_between(gt, 45, 5, 0.11), o).correct);
}

TEST(PlaceLabels, RotationErrorCounts) {
  const Trajectory gt = out_and_back();
  PlaceEvent e = event_between(gt, 45, 5);
  e.T_q_r = e.T_q_r * geom::SE3d(Eigen::AngleAxisd(10 * M_PI / 180, Eigen::Vector3d::UnitY()));
  const auto l = label_place_event(gt, e, {});
  EXPECT_NEAR(l.error_deg, 10, 1e-6);
  EXPECT_FALSE(l.correct);
}

TEST(PlaceLabels, NoGroundTruthIsUnjudged) {
  const Trajectory gt = out_and_back();
  PlaceEvent e = event_between(gt, 45, 5);
  e.t_ns = 100 * kSecond;  // after the ground truth ends
  const auto l = label_place_event(gt, e, {});
  EXPECT_FALSE(l.judged);
  EXPECT_FALSE(l.correct);
}

TEST(PlaceLabels, RevisitEpisodesAndMissedLoops) {
  const Trajectory gt = out_and_back();
  std::vector<std::int64_t> kfs;
  for (int s = 0; s < 60; ++s) kfs.push_back(s * kSecond);  // a keyframe a second
  PlaceLabelOptions o;
  const auto episodes = find_revisits(gt, kfs, o);
  // From 40 s on each keyframe is where one 40 s older was: one episode.
  ASSERT_EQ(episodes.size(), 1u);
  EXPECT_EQ(episodes[0].first_t_ns, 40 * kSecond);
  EXPECT_EQ(episodes[0].last_t_ns, 59 * kSecond);
  EXPECT_EQ(episodes[0].keyframes, 20);

  // Nothing closed it: one missed; a false loop inside does not close it.
  PlaceLabels none = label_place_events(gt, {event_between(gt, 45, 5, 1.0)}, {}, kfs, o);
  EXPECT_EQ(none.loops_missed, 1);
  EXPECT_EQ(none.loops_false, 1);
  EXPECT_EQ(none.loops_true, 0);
  // A true relocalisation inside closes it.
  PlaceLabels reloc = label_place_events(gt, {}, {event_between(gt, 41, 1)}, kfs, o);
  EXPECT_EQ(reloc.loops_missed, 0);
  EXPECT_EQ(reloc.relocalisations_true, 1);
  EXPECT_TRUE(reloc.revisits[0].closed);
  // A relocalisation just before the episode leads into it; a loop does not.
  EXPECT_EQ(label_place_events(gt, {}, {event_between(gt, 39.5, 0)}, kfs, o).loops_missed, 0);
  EXPECT_EQ(label_place_events(gt, {event_between(gt, 39.5, 0)}, {}, kfs, o).loops_missed, 1);
  // Without the lead, only when the next keyframe starts the episode
  // (39.5 s: the next is 40 s; 38.5 s: the next, 39 s, is no revisit).
  o.relocalisation_lead_s = 0;
  EXPECT_EQ(label_place_events(gt, {}, {event_between(gt, 39.5, 0)}, kfs, o).loops_missed, 0);
  EXPECT_EQ(label_place_events(gt, {}, {event_between(gt, 38.5, 0)}, kfs, o).loops_missed, 1);
}

TEST(PlaceLabels, ARelocalisationClosesTheEpisodeOfItsNextKeyframeHoweverLate) {
  const Trajectory gt = out_and_back();
  // Relocalised at 30 s; tracking then made no keyframe until the
  // episode's first, 10 s later (beyond the 5 s lead).
  std::vector<std::int64_t> kfs;
  for (int s = 0; s < 60; ++s)
    if (s < 30 || s >= 40) kfs.push_back(s * kSecond);
  PlaceLabelOptions o;
  ASSERT_EQ(find_revisits(gt, kfs, o).at(0).first_t_ns, 40 * kSecond);
  EXPECT_EQ(label_place_events(gt, {}, {event_between(gt, 30, 0)}, kfs, o).loops_missed, 0);
  // A keyframe made in between (elsewhere): the episode is not its to close.
  kfs.insert(kfs.begin() + 30, 35 * kSecond);
  EXPECT_EQ(label_place_events(gt, {}, {event_between(gt, 30, 0)}, kfs, o).loops_missed, 1);
  // A false relocalisation closes nothing.
  kfs.erase(kfs.begin() + 30);
  EXPECT_EQ(label_place_events(gt, {}, {event_between(gt, 30, 0, 1.0)}, kfs, o).loops_missed, 1);
}

TEST(PlaceLabels, TooRecentOrLookingElsewhereIsNoRevisit) {
  Trajectory gt;
  geom::Mat3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  // Standing still for 60 s: each keyframe is where the previous ones were,
  // but with a min gap of 100 s none counts.
  for (int i = 0; i <= 60; ++i) gt.poses.push_back({i * kSecond, geom::make_se3(R, {0, 0, 0})});
  std::vector<std::int64_t> kfs;
  for (int s = 0; s <= 60; s += 5) kfs.push_back(s * kSecond);
  PlaceLabelOptions o;
  o.revisit_min_gap_s = 100;
  EXPECT_TRUE(find_revisits(gt, kfs, o).empty());
  o.revisit_min_gap_s = 20;
  EXPECT_EQ(find_revisits(gt, kfs, o).size(), 1u);
  // Turned round after 30 s: a keyframe facing west is no revisit of one
  // facing east.  Keyframes 20-30 s revisit 0-10 s; 55-60 s revisit 35-40 s.
  for (auto& p : gt.poses)
    if (p.t_ns > 30 * kSecond) p.T_w_c.linear() = R * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).matrix();
  const auto episodes = find_revisits(gt, kfs, o);
  ASSERT_EQ(episodes.size(), 2u);
  EXPECT_EQ(episodes[0].first_t_ns, 20 * kSecond);
  EXPECT_EQ(episodes[0].last_t_ns, 30 * kSecond);
  EXPECT_EQ(episodes[1].first_t_ns, 55 * kSecond);
}

TEST(PlaceLabels, JsonCarriesCountsAndEvents) {
  const Trajectory gt = out_and_back();
  PlaceLabelOptions o;
  const auto labels = label_place_events(gt, {event_between(gt, 45, 5)}, {}, {}, o);
  const std::string j = to_json(labels, o);
  EXPECT_NE(j.find("\"loops_true\": 1"), std::string::npos) << j;
  EXPECT_NE(j.find("\"loops_false\": 0"), std::string::npos) << j;
  EXPECT_NE(j.find("\"correct\": true"), std::string::npos) << j;
}

}  // namespace
}  // namespace pvb::eval
