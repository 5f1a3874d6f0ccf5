#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "pvb/eval/evaluate.hpp"

using namespace pvb;
using namespace pvb::eval;
using geom::Mat3d;
using geom::SE3d;
using geom::Vec3d;

namespace {
// A closed, non-planar loop of n poses at 10 Hz with changing heading.
Trajectory loop(int n, const std::string& name = "gt") {
  Trajectory t;
  t.source = name;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    geom::StampedPose p;
    p.t_ns = 1000000000LL + i * 100000000LL;
    p.T_w_c = geom::make_se3(geom::so3_exp(Vec3d(0.05 * std::sin(3 * a), 0.0, a)),
                             Vec3d(5 * std::cos(a), 3 * std::sin(a), 0.5 * std::sin(2 * a)));
    t.poses.push_back(p);
  }
  return t;
}

Trajectory transformed(const Trajectory& in, const SE3d& T, double scale = 1.0) {
  Trajectory out = in;
  out.source = "est";
  for (auto& p : out.poses) {
    const Vec3d pos = scale * p.T_w_c.translation();
    p.T_w_c.linear() = T.linear() * p.T_w_c.linear();
    p.T_w_c.translation() = T * pos;
  }
  return out;
}

const SE3d kOffset = geom::make_se3(geom::so3_exp(Vec3d(0.3, -0.2, 1.1)), Vec3d(4.0, -7.0, 1.5));
}  // namespace

TEST(Align, PureRigidOffsetGivesZeroAfterSe3) {
  const Trajectory gt = loop(100);
  const Trajectory est = transformed(gt, kOffset);
  const EvalResult r = evaluate(gt, est, {});
  EXPECT_EQ(r.pairs.size(), 100u);
  EXPECT_LT(r.ate.rmse, 1e-9);
  EXPECT_LT(r.ate.max, 1e-9);
  EXPECT_LT(r.rpe_trans_m.max, 1e-9);
  EXPECT_LT(r.rpe_rot_deg.max, 1e-5);
  EXPECT_NEAR(r.alignment.s, 1.0, 0.0);
  EXPECT_TRUE(r.alignment.R.isApprox(kOffset.linear().transpose(), 1e-9));
  // Without alignment the offset is the error; origin alignment removes it too.
  EvalOptions none;
  none.alignment = Alignment::kNone;
  EXPECT_GT(evaluate(gt, est, none).ate.rmse, 1.0);
  EvalOptions origin;
  origin.alignment = Alignment::kOrigin;
  EXPECT_LT(evaluate(gt, est, origin).ate.rmse, 1e-9);
}

TEST(Align, Sim3RecoversKnownScale) {
  const Trajectory gt = loop(80);
  const double kScale = 0.37;  // the estimate is 0.37x too small
  const Trajectory est = transformed(gt, kOffset, kScale);
  EvalOptions o;
  o.alignment = Alignment::kSim3;
  const EvalResult r = evaluate(gt, est, o);
  EXPECT_NEAR(r.alignment.s, 1.0 / kScale, 1e-9);
  EXPECT_LT(r.ate.rmse, 1e-9);
  EXPECT_LT(r.rpe_trans_m.max, 1e-9);  // RPE uses the recovered scale
  o.alignment = Alignment::kSe3;
  EXPECT_GT(evaluate(gt, est, o).ate.rmse, 0.5);
}

TEST(Align, NoiseOfKnownRmseIsMeasured) {
  // Planar loop in z = 0 with an even number of evenly spaced poses; the
  // estimate is displaced alternately by +r and -r along z.  The displacements
  // sum to zero and are uncorrelated with the loop, so the optimal SE(3)
  // alignment is the identity and every error is exactly r.
  const int n = 120;
  const double r_m = 0.0725;
  Trajectory gt, est;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    geom::StampedPose p{i * 50000000LL, geom::make_se3(geom::so3_exp(Vec3d(0, 0, a)), Vec3d(4 * std::cos(a), 4 * std::sin(a), 0))};
    gt.poses.push_back(p);
    p.T_w_c.translation().z() = (i % 2 ? r_m : -r_m);
    est.poses.push_back(p);
  }
  const EvalResult r = evaluate(gt, transformed(est, kOffset), {});
  EXPECT_NEAR(r.ate.rmse, r_m, 1e-9);
  EXPECT_NEAR(r.ate.mean, r_m, 1e-9);
  EXPECT_NEAR(r.ate.std, 0.0, 1e-7);
  EXPECT_NEAR(r.ate.min, r_m, 1e-9);
  EXPECT_NEAR(r.ate.max, r_m, 1e-9);
  EXPECT_EQ(r.ate.count, static_cast<std::size_t>(n));
}

TEST(Align, DoesNotMutateInputs) {
  const Trajectory gt = loop(50);
  const Trajectory est = transformed(gt, kOffset, 2.0);
  const Trajectory gt_copy = gt, est_copy = est;
  for (Alignment a : {Alignment::kSe3, Alignment::kSim3, Alignment::kNone, Alignment::kOrigin}) {
    EvalOptions o;
    o.alignment = a;
    evaluate(gt, est, o);
  }
  std::vector<SE3d> e, g;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    e.push_back(est.poses[i].T_w_c);
    g.push_back(gt.poses[i].T_w_c);
  }
  const std::vector<SE3d> e_copy = e;
  apply_alignment(compute_alignment(e, g, Alignment::kSim3), e);
  for (std::size_t i = 0; i < gt.size(); ++i) {
    EXPECT_TRUE(gt.poses[i].T_w_c.isApprox(gt_copy.poses[i].T_w_c, 0.0));
    EXPECT_TRUE(est.poses[i].T_w_c.isApprox(est_copy.poses[i].T_w_c, 0.0));
    EXPECT_EQ(est.poses[i].t_ns, est_copy.poses[i].t_ns);
    EXPECT_TRUE(e[i].isApprox(e_copy[i], 0.0));
  }
}

TEST(Align, DegenerateSetsAreErrors) {
  std::vector<Vec3d> line, pts2;
  for (int i = 0; i < 10; ++i) line.push_back(Vec3d(1, 2, 3) + i * Vec3d(0.5, -0.1, 0.2));
  try {
    umeyama(line, line, false);
    FAIL() << "no error";
  } catch (const EvalError& e) {
    EXPECT_NE(std::string(e.what()).find("collinear"), std::string::npos) << e.what();
  }
  const std::vector<Vec3d> same(5, Vec3d(1, 1, 1));
  EXPECT_THROW(umeyama(same, same, true), EvalError);
  pts2 = {Vec3d(0, 0, 0), Vec3d(1, 0, 0)};
  try {
    umeyama(pts2, pts2, false);
    FAIL() << "no error";
  } catch (const EvalError& e) {
    EXPECT_NE(std::string(e.what()).find("at least 3"), std::string::npos) << e.what();
  }
  // Through the whole pipeline: two associated poses.
  const Trajectory gt = loop(2);
  EXPECT_THROW(evaluate(gt, gt, {}), EvalError);
}

// A simulated robot driving exactly straight on flat ground: the true
// positions lie on a line, and the turn about it comes from the orientations.
TEST(Align, AStraightDriveTakesTheTurnAboutItsLineFromTheOrientations) {
  Trajectory gt;
  gt.source = "gt";
  for (int i = 0; i < 60; ++i) {
    geom::StampedPose p;
    p.t_ns = 1000000000LL + i * 100000000LL;
    p.T_w_c = geom::make_se3(geom::so3_exp(Vec3d(1.8 + 0.01 * std::sin(i), 0.02 * std::cos(0.3 * i), 0.4)),
                             Vec3d(-4.1, -10.0 + 0.2 * i, 1.1));
    gt.poses.push_back(p);
  }
  std::vector<Vec3d> line;
  for (const auto& p : gt.poses) line.push_back(p.T_w_c.translation());
  EXPECT_THROW(umeyama(line, line, false), EvalError);  // positions alone leave the turn free
  for (const double scale : {1.0, 2.5}) {
    const Trajectory est = transformed(gt, kOffset, scale);
    EvalOptions o;
    o.alignment = scale == 1.0 ? Alignment::kSe3 : Alignment::kSim3;
    const EvalResult r = evaluate(gt, est, o);
    EXPECT_TRUE(r.alignment.R.isApprox(kOffset.linear().transpose(), 1e-9)) << r.alignment.R;
    EXPECT_NEAR(r.alignment.s, 1.0 / scale, 1e-9);
    EXPECT_LT(r.ate.max, 1e-9);
  }
  // Millimetres of wobble and a milliradian of attitude noise: the turn is
  // still found to about that milliradian.
  Trajectory est = transformed(gt, kOffset);
  for (std::size_t i = 0; i < est.poses.size(); ++i) {
    const double k = static_cast<double>(i);
    est.poses[i].T_w_c.translation() += 0.002 * Vec3d(std::sin(k), std::cos(1.7 * k), std::sin(2.3 * k));
    est.poses[i].T_w_c.linear() =
        est.poses[i].T_w_c.linear() * geom::so3_exp(1e-3 * Vec3d(std::cos(k), std::sin(1.3 * k), std::cos(0.7 * k)));
  }
  const EvalResult r = evaluate(gt, est, {});
  const Mat3d dR = r.alignment.R * kOffset.linear();
  EXPECT_LT(Eigen::AngleAxisd(dR).angle(), 2e-3);
  EXPECT_LT(r.ate.rmse, 0.004);
}

// One estimated position at 1e300 (or NaN) is named as such, not reported
// as "all estimated positions are the same point".
TEST(Align, AbsurdPositionIsNamed) {
  const Trajectory gt = loop(20);
  for (const double bad : {1e300, std::nan("")}) {
    Trajectory est = transformed(gt, kOffset);
    est.poses[7].T_w_c.translation().x() = bad;
    try {
      evaluate(gt, est, {});
      FAIL() << bad;
    } catch (const EvalError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("estimate 'est': the pose at t = 1.700000 s is not finite or lies beyond 1e+08 m"),
                std::string::npos)
          << what;
    }
    std::vector<Vec3d> pts;
    for (const auto& p : est.poses) pts.push_back(p.T_w_c.translation());
    EXPECT_THROW(umeyama(pts, pts, false), EvalError);
  }
}

TEST(Metrics, StatsMatchNumpyConventions) {
  const Stats s = compute_stats({3.0, 1.0, 4.0, 2.0});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);                // average of the middle two
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));      // population std (numpy.std)
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4));
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(compute_stats({5.0, 1.0, 2.0}).median, 2.0);
  EXPECT_EQ(compute_stats({}).count, 0u);
}

TEST(Metrics, RpeHandComputedCase) {
  // gt: identity, then 90 deg about z at (1, 0, 0), then two more steps.
  // est: as gt but the second pose is at (1, 0.1, 0) and rotated 100 deg.
  // Pair (0, 1): A = est_0^-1 est_1, B = gt_0^-1 gt_1, E = A B^-1 has rotation
  // Rz(10 deg) and translation t_A - Rz(10 deg) t_B = (1 - cos 10, 0.1 - sin 10, 0).
  const double d10 = 10.0 * M_PI / 180.0;
  std::vector<SE3d> gt = {SE3d::Identity(), geom::make_se3(geom::so3_exp(Vec3d(0, 0, M_PI / 2)), Vec3d(1, 0, 0)),
                          geom::make_se3(geom::so3_exp(Vec3d(0, 0, M_PI / 2)), Vec3d(1, 1, 0)),
                          geom::make_se3(geom::so3_exp(Vec3d(0, 0, M_PI / 2)), Vec3d(1, 2, 0))};
  std::vector<SE3d> est = gt;
  est[1] = geom::make_se3(geom::so3_exp(Vec3d(0, 0, M_PI / 2 + d10)), Vec3d(1, 0.1, 0));
  const std::vector<std::int64_t> t_ns = {0, 100, 200, 300};
  const std::vector<RpePair> r = rpe(est, gt, t_ns, {});
  // evaluate_rpe.py --fixed_delta drops pairs ending at the last pose: (0,1), (1,2) remain.
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].i, 0u);
  EXPECT_EQ(r[0].j, 1u);
  EXPECT_NEAR(r[0].trans_m, std::hypot(1 - std::cos(d10), 0.1 - std::sin(d10)), 1e-12);
  EXPECT_NEAR(r[0].rot_deg, 10.0, 1e-9);
  // signed, on the start camera's axes
  EXPECT_TRUE(r[0].rot_err_deg.isApprox(Vec3d(0, 0, 10.0), 1e-9));
  EXPECT_TRUE(r[0].trans_err_m.isApprox(Vec3d(1 - std::cos(d10), 0.1 - std::sin(d10), 0), 1e-9));
  // Pair (1, 2): B = (I, Rz(-90)(0,1,0) = (1,0,0)), A = est_1^-1 est_2 has
  // rotation Rz(-10 deg) and translation Rz(-100 deg)(0, 0.9, 0).
  const Vec3d tA = geom::so3_exp(Vec3d(0, 0, -(M_PI / 2 + d10))) * Vec3d(0, 0.9, 0);
  const Vec3d tE = tA - geom::so3_exp(Vec3d(0, 0, -d10)) * Vec3d(1, 0, 0);
  EXPECT_NEAR(r[1].trans_m, tE.norm(), 1e-12);
  EXPECT_NEAR(r[1].rot_deg, 10.0, 1e-9);

  RpeOptions consecutive;
  consecutive.pairs = PairMode::kConsecutive;
  EXPECT_EQ(rpe(est, gt, t_ns, consecutive).size(), 3u);  // (0,1) (1,2) (2,3)
}

// An estimate whose every step k is the true step B_k with a left error D_k,
// est_k = est_{k-1} D_k B_k: then A = D_k B_k and E = A B^-1 = D_k exactly.
TEST(Metrics, RpePerAxisSeparatesABiasFromAlternatingErrors) {
  const Trajectory gt = loop(40);
  const double eps_rad = 0.002, dy_m = 0.0005, dz_m = 0.003;
  Trajectory est = gt;
  est.source = "est";
  for (std::size_t k = 1; k < est.poses.size(); ++k) {
    const SE3d B = gt.poses[k - 1].T_w_c.inverse() * gt.poses[k].T_w_c;
    const double sign = k % 2 ? 1.0 : -1.0;
    const SE3d D = geom::make_se3(geom::so3_exp(Vec3d(eps_rad, 0, 0)), Vec3d(0, dy_m, sign * dz_m));
    est.poses[k].T_w_c = est.poses[k - 1].T_w_c * D * B;
  }
  EvalOptions options;
  options.rpe.pairs = PairMode::kConsecutive;
  const EvalResult r = evaluate(gt, est, options);
  ASSERT_EQ(r.rpe_rot_axes_deg.count, 39u);
  const double eps_deg = eps_rad * 180.0 / M_PI;
  EXPECT_TRUE(r.rpe_rot_axes_deg.mean.isApprox(Vec3d(eps_deg, 0, 0), 1e-6)) << r.rpe_rot_axes_deg.mean.transpose();
  EXPECT_LT(r.rpe_rot_axes_deg.std.norm(), 1e-9);
  // 20 steps at +dz and 19 at -dz
  const double mean_z = dz_m / 39.0;
  EXPECT_NEAR(r.rpe_trans_axes_m.mean.x(), 0.0, 1e-9);
  EXPECT_NEAR(r.rpe_trans_axes_m.mean.y(), dy_m, 1e-9);
  EXPECT_NEAR(r.rpe_trans_axes_m.mean.z(), mean_z, 1e-9);
  EXPECT_NEAR(r.rpe_trans_axes_m.std.y(), 0.0, 1e-9);
  EXPECT_NEAR(r.rpe_trans_axes_m.std.z(), std::sqrt(dz_m * dz_m - mean_z * mean_z), 1e-9);
  // The report gives t only where the spread allows it: z's t is small.
  const std::string text = format_rpe_axes(r);
  EXPECT_NE(text.find("over 39 pairs; t = mean"), std::string::npos) << text;
  const double t_z = mean_z / (r.rpe_trans_axes_m.std.z() / std::sqrt(38.0));
  char expected[32];
  std::snprintf(expected, sizeof expected, "(t %+5.1f)", t_z);
  EXPECT_NE(text.find(expected), std::string::npos) << text;
  // With overlapping pairs there is no t.
  EvalOptions all;
  EXPECT_EQ(format_rpe_axes(evaluate(gt, est, all)).find("(t"), std::string::npos);
}

TEST(Metrics, RpePairSelection) {
  const std::vector<double> idx = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  const auto all = select_rpe_pairs(idx, 3, PairMode::kAll);
  ASSERT_EQ(all.size(), 6u);  // i = 0..5 -> j = 3..8; i >= 6 hits the last pose
  EXPECT_EQ(all.back(), std::make_pair(std::size_t{5}, std::size_t{8}));
  const auto cons = select_rpe_pairs(idx, 3, PairMode::kConsecutive);
  ASSERT_EQ(cons.size(), 3u);  // (0,3) (3,6) (6,9)
  EXPECT_EQ(cons.back(), std::make_pair(std::size_t{6}, std::size_t{9}));
}

TEST(Report, ComparisonShowsReduction) {
  EXPECT_DOUBLE_EQ(reduction_percent(0.2, 0.15), 25.0);
  EXPECT_DOUBLE_EQ(reduction_percent(0.0, 0.15), 0.0);
  const Trajectory gt = loop(60);
  Trajectory est = transformed(gt, kOffset);
  for (std::size_t i = 0; i < est.size(); ++i) est.poses[i].T_w_c.translation().x() += (i % 3) * 0.01;
  EvalResult a = evaluate(gt, est, {});
  EvalResult b = a;
  a.est_source = "runs/pe_slam/CameraTrajectory.txt";
  b.est_source = "runs/baseline/CameraTrajectory.txt";
  const std::string table = format_comparison({a, b});
  // same file names: the columns name their folders
  EXPECT_NE(table.find("[1] pe_slam/CameraTraj"), std::string::npos) << table;
  EXPECT_NE(table.find("[2] baseline/CameraTra"), std::string::npos) << table;
  EXPECT_NE(table.find("ATE rmse"), std::string::npos);
  EXPECT_NE(table.find("+0.0%"), std::string::npos) << table;
  const std::string json = format_json(a);
  for (const char* key : {"\"ate\"", "\"rmse\"", "\"rpe\"", "\"trans\"", "\"rot_deg\"", "\"pairs\": 60", "\"alignment\"",
                          "\"R\"", "\"t\"", "\"s\""})
    EXPECT_NE(json.find(key), std::string::npos) << key;
}

TEST(Align, NearlyStraightDriveStillAligns) {
  // A robot along a 20 m PV row: 2 mm of lateral and vertical wobble.  The
  // estimate is the ground truth moved rigidly; SE(3) alignment must undo it.
  std::vector<Vec3d> gt, est;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Vec3d(0.2, 0.3, 0.9).normalized()).toRotationMatrix();
  for (int i = 0; i < 600; ++i) {
    const double x = i * 20.0 / 600;
    gt.push_back(Vec3d(x, 0.002 * std::sin(i * 0.05), 1.1 + 0.002 * std::cos(i * 0.11)));
    est.push_back(R * gt.back() + Vec3d(1, -2, 0.5));
  }
  const Sim3Transform a = umeyama(est, gt, false);
  double worst = 0;
  for (std::size_t i = 0; i < gt.size(); ++i) worst = std::max(worst, (a.apply(est[i]) - gt[i]).norm());
  EXPECT_LT(worst, 1e-6);
}
