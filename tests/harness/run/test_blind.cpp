// The blind stretch of a run (a cover, or a kidnap's covered frames) on
// synthetic trajectories with known errors: the covered frames' poses, the
// first frame after the cover against the truth (across the stretch and in
// the aligned frame), its tracking, and the stretch in metrics.json and
// index.html.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "pvb/geometry/time.hpp"
#include "pvb/run/blind.hpp"
#include "pvb/report/report.hpp"

namespace pvb::run {
namespace {

constexpr double kFps = 30.0;
constexpr int kFrames = 60;
const scenes::CoverFrames kCover{20, 30};  // frames 20-29 covered, 30 the first after

/// The true camera: along x with a slow turn and some height.
geom::SE3d true_pose(int i) {
  geom::SE3d T = geom::SE3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.01 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.02 * i, 0.001 * i * i, 0.5);
  return T;
}

/// The error the estimate picks up across the cover: 3 cm along the camera's
/// x and 0.5 degrees about its y, on every frame from the first after it.
geom::SE3d stretch_error() {
  geom::SE3d D = geom::SE3d::Identity();
  D.linear() = Eigen::AngleAxisd(0.5 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  D.translation() = Eigen::Vector3d(0.03, 0, 0);
  return D;
}

/// The world drift the estimate had before the cover: 10 cm along the world's x.
geom::SE3d drift() {
  geom::SE3d W = geom::SE3d::Identity();
  W.translation() = Eigen::Vector3d(0.1, 0, 0);
  return W;
}

struct Synthetic {
  eval::Trajectory gt, est;
  std::vector<FrameRecord> frames;
};

/// `frames` frames; covered frames with a pose when `dead_reckoning`; the
/// first after the cover tracked by `after_method` (or lost when "").
Synthetic synthetic(bool dead_reckoning, const std::string& after_method, int frames = kFrames) {
  Synthetic s;
  for (int i = 0; i < frames; ++i) {
    const std::int64_t t_ns = geom::frame_time_ns(0, i, kFps);
    s.gt.poses.push_back({t_ns, true_pose(i)});
    const bool covered = kCover.covered(i);
    bool tracked = !covered || dead_reckoning;
    std::string state = covered ? (dead_reckoning ? "dead_reckoning" : "lost") : "ok";
    std::string method = covered ? "none" : "motion";
    if (i == kCover.end) {
      tracked = !after_method.empty();
      state = tracked ? "ok" : "lost";
      method = tracked ? after_method : "none";
    }
    s.frames.push_back({i, i / kFps, tracked, 10.0, 0, 0, state, method});
    if (!tracked) continue;
    const geom::SE3d T = i < kCover.begin ? drift() * true_pose(i) : drift() * true_pose(i) * stretch_error();
    s.est.poses.push_back({t_ns, T});
  }
  return s;
}

eval::EvalResult unaligned(const Synthetic& s) {
  eval::EvalOptions eo;
  eo.alignment = eval::Alignment::kNone;
  return eval::evaluate(s.gt, s.est, eo);
}

TEST(PoseError, DistanceAndAngle) {
  geom::SE3d a = true_pose(5);
  const PoseError same = pose_error(a, a);
  EXPECT_NEAR(same.trans_m, 0.0, 1e-12);
  EXPECT_NEAR(same.rot_deg, 0.0, 1e-6);
  const PoseError e = pose_error(a, a * stretch_error());
  EXPECT_NEAR(e.trans_m, 0.03, 1e-12);
  EXPECT_NEAR(e.rot_deg, 0.5, 1e-9);
}

// Camera only: no pose while covered; the first frame after the cover
// relocalised, 3 cm and 0.5 deg off across the stretch, and in the
// unaligned world also 10 cm of drift.
TEST(BlindStretch, CameraOnlyRelocalisedAfterTheCover) {
  const Synthetic s = synthetic(false, "reloc");
  const BlindStretch b = blind_stretch(kCover, kFps, s.frames, s.est, s.gt, unaligned(s));
  EXPECT_EQ(b.first_covered, 20);
  EXPECT_EQ(b.last_covered, 29);
  EXPECT_EQ(b.covered_frames(), 10);
  EXPECT_EQ(b.covered_processed, 10);
  EXPECT_EQ(b.covered_with_pose, 0);
  EXPECT_EQ(b.relocalised_frames, 1);
  EXPECT_EQ(b.last_before.value_or(-1), 19);
  EXPECT_EQ(b.first_after.value_or(-1), 30);
  EXPECT_TRUE(b.first_after_tracked);
  EXPECT_EQ(b.first_after_method, "reloc");
  EXPECT_EQ(b.first_after_state, "ok");
  ASSERT_TRUE(b.first_after_error);
  EXPECT_NEAR(b.first_after_error->trans_m, 0.03, 1e-9);
  EXPECT_NEAR(b.first_after_error->rot_deg, 0.5, 1e-6);
  ASSERT_TRUE(b.first_after_ate);
  const Eigen::Vector3d off = drift().translation() + true_pose(30).linear() * stretch_error().translation();
  EXPECT_NEAR(b.first_after_ate->trans_m, off.norm(), 1e-9);
  EXPECT_NEAR(b.first_after_ate->rot_deg, 0.5, 1e-6);
  EXPECT_GT(b.first_after_ate->trans_m, 0.1);
}

// Dead reckoning: every covered frame has a pose and tracking goes on by
// the motion model; the error across the stretch is the same.
TEST(BlindStretch, DeadReckoningGivesEveryCoveredFrameAPose) {
  const Synthetic s = synthetic(true, "motion");
  const BlindStretch b = blind_stretch(kCover, kFps, s.frames, s.est, s.gt, std::nullopt);
  EXPECT_EQ(b.covered_with_pose, 10);
  EXPECT_EQ(b.relocalised_frames, 0);
  EXPECT_EQ(b.last_before.value_or(-1), 19);
  EXPECT_EQ(b.first_after_method, "motion");
  ASSERT_TRUE(b.first_after_error);
  EXPECT_NEAR(b.first_after_error->trans_m, 0.03, 1e-9);
  EXPECT_NEAR(b.first_after_error->rot_deg, 0.5, 1e-6);
  EXPECT_FALSE(b.first_after_ate) << "no evaluation, no aligned error";
}

// Lost on the first frame after the cover: no error to measure.
TEST(BlindStretch, LostAfterTheCoverHasNoError) {
  const Synthetic s = synthetic(false, "");
  const BlindStretch b = blind_stretch(kCover, kFps, s.frames, s.est, s.gt, unaligned(s));
  EXPECT_EQ(b.first_after.value_or(-1), 30);
  EXPECT_FALSE(b.first_after_tracked);
  EXPECT_EQ(b.first_after_state, "lost");
  EXPECT_FALSE(b.first_after_error);
  EXPECT_FALSE(b.first_after_ate);
  EXPECT_NE(blind_summary(b).find("frame 30 after it has no pose (state lost)"), std::string::npos)
      << blind_summary(b);
}

// A run that ended inside the cover.
TEST(BlindStretch, RunEndedInsideTheCover) {
  const Synthetic s = synthetic(false, "motion", 26);
  const BlindStretch b = blind_stretch(kCover, kFps, s.frames, s.est, s.gt, std::nullopt);
  EXPECT_EQ(b.covered_processed, 6);
  EXPECT_FALSE(b.first_after);
  EXPECT_FALSE(b.first_after_tracked);
  EXPECT_NE(blind_summary(b).find("ended before the camera's return"), std::string::npos) << blind_summary(b);
}

TEST(BlindStretch, InMetricsJsonAndIndexHtml) {
  const Synthetic s = synthetic(false, "reloc");
  RunReport r;
  r.scenario = "drive";
  r.primary.mode = "pe-slam";
  r.primary.per_frame = s.frames;
  r.primary.frames = s.frames.size();
  const std::string without = metrics_json(r);
  EXPECT_EQ(without.find("\"blind\""), std::string::npos) << "no key in a run without a cover";
  EXPECT_EQ(index_html(r, {}).find("Blind stretch"), std::string::npos);
  r.primary.blind = blind_stretch(kCover, kFps, s.frames, s.est, s.gt, unaligned(s));
  const YAML::Node m = YAML::Load(metrics_json(r))["blind"];
  ASSERT_TRUE(m.IsMap());
  EXPECT_EQ(m["covered_frames"][0].as<int>(), 20);
  EXPECT_EQ(m["covered_frames"][1].as<int>(), 29);
  EXPECT_EQ(m["covered_frames_with_pose"].as<int>(), 0);
  EXPECT_EQ(m["covered_frames_processed"].as<int>(), 10);
  EXPECT_EQ(m["relocalised_frames"].as<int>(), 1);
  EXPECT_EQ(m["last_before_frame"].as<int>(), 19);
  EXPECT_EQ(m["first_after_frame"].as<int>(), 30);
  EXPECT_TRUE(m["first_after_tracked"].as<bool>());
  EXPECT_EQ(m["first_after_state"].as<std::string>(), "ok");
  EXPECT_EQ(m["first_after_method"].as<std::string>(), "reloc");
  EXPECT_NEAR(m["first_after_error"]["trans_m"].as<double>(), 0.03, 1e-9);
  EXPECT_NEAR(m["first_after_error"]["rot_deg"].as<double>(), 0.5, 1e-6);
  EXPECT_GT(m["first_after_ate"]["trans_m"].as<double>(), 0.1);
  const std::string html = index_html(r, {});
  EXPECT_NE(html.find("<h2>Blind stretch</h2>"), std::string::npos);
  EXPECT_NE(html.find("<td>20-29</td><td>0 of 10</td><td>30</td><td>yes (reloc)</td><td>0.0300 / 0.500</td>"),
            std::string::npos)
      << html;
  // Lost after the cover: nulls, not numbers.
  const Synthetic lost = synthetic(false, "");
  r.primary.blind = blind_stretch(kCover, kFps, lost.frames, lost.est, lost.gt, unaligned(lost));
  const YAML::Node n = YAML::Load(metrics_json(r))["blind"];
  EXPECT_TRUE(n["first_after_error"].IsNull());
  EXPECT_TRUE(n["first_after_ate"].IsNull());
  EXPECT_FALSE(n["first_after_tracked"].as<bool>());
  EXPECT_EQ(n["first_after_state"].as<std::string>(), "lost");
}

}  // namespace
}  // namespace pvb::run
