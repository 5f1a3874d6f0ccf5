// The inertial state against the truth (inertial_eval.hpp) on synthetic
// data: imu0/truth.csv read back, the true bias interpolated at keyframe
// times, the keyframes' bias errors with known values; and the report's
// gravity, tilt, inertial and dead-reckoning pieces: metrics.json keys, the
// comparison named by sensor setups, index.html and the figures.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <random>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/report/report.hpp"
#include "pvb/run/inertial_eval.hpp"

namespace pvb::run {
namespace {

std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_inertial_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + d + " && mkdir -p " + d).c_str());
  return d;
}

/// True biases ramping linearly: gyro (1e-3 t, -2e-3 t, 0.01), accel (0.05 t, 0.1, -0.02 t), t in seconds.
std::vector<BiasTruth> ramp_truth(std::int64_t t0_ns, int readings, std::int64_t step_ns) {
  std::vector<BiasTruth> out;
  for (int i = 0; i < readings; ++i) {
    const std::int64_t t_ns = t0_ns + i * step_ns;
    const double t = static_cast<double>(i * step_ns) * 1e-9;
    out.push_back(
        {t_ns, Eigen::Vector3d(1e-3 * t, -2e-3 * t, 0.01), Eigen::Vector3d(0.05 * t, 0.1, -0.02 * t)});
  }
  return out;
}

TEST(InertialEval, ReadsTheBiasColumnsOfTheTruthFile) {
  const std::string path = temp_dir("read") + "/truth.csv";
  write_file(path,
             "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z,bw_x,bw_y,bw_z,ba_x,ba_y,ba_z\n"
             "1000000000,0.1,0.2,0.3,0,0,9.81,0.001,0.002,0.003,0.01,0.02,0.03\n"
             "1005000000,0.1,0.2,0.3,0,0,9.81,0.004,0.005,0.006,0.04,0.05,0.06\n");
  const std::vector<BiasTruth> t = read_bias_truth(path);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].t_ns, 1000000000);
  EXPECT_EQ(t[1].t_ns, 1005000000);
  EXPECT_DOUBLE_EQ(t[0].gyro_radps.z(), 0.003);
  EXPECT_DOUBLE_EQ(t[1].gyro_radps.x(), 0.004);
  EXPECT_DOUBLE_EQ(t[0].accel_mps2.y(), 0.02);
  EXPECT_DOUBLE_EQ(t[1].accel_mps2.z(), 0.06);
  // A short line, a word where a number belongs, readings back in time: the file and line named.
  for (const std::string& bad :
       {std::string("1000000000,0.1,0.2\n"), std::string("1000000000,0.1,0.2,0.3,0,0,9.81,x,0,0,0,0,0\n"),
        std::string("2,0,0,0,0,0,0,0,0,0,0,0,0\n1,0,0,0,0,0,0,0,0,0,0,0,0\n")}) {
    write_file(path, "# header\n" + bad);
    try {
      read_bias_truth(path);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const IoError& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_GE(e.line(), 2) << e.what();
    }
  }
  EXPECT_THROW(read_bias_truth(path + ".missing"), IoError);
}

TEST(InertialEval, InterpolatesTheTrueBiasBetweenReadings) {
  const std::vector<BiasTruth> truth = ramp_truth(1'000'000'000, 11, 100'000'000);  // 0 .. 1 s
  const BiasTruth mid = bias_truth_at(truth, 1'000'000'000 + 250'000'000);          // between readings
  EXPECT_NEAR(mid.gyro_radps.x(), 0.25e-3, 1e-15);
  EXPECT_NEAR(mid.accel_mps2.x(), 0.05 * 0.25, 1e-15);
  EXPECT_NEAR(mid.accel_mps2.z(), -0.02 * 0.25, 1e-15);
  EXPECT_EQ(mid.t_ns, 1'250'000'000);
  // Outside the readings: the first or the last.
  EXPECT_NEAR(bias_truth_at(truth, 0).gyro_radps.x(), 0.0, 1e-15);
  EXPECT_NEAR(bias_truth_at(truth, 9'000'000'000).gyro_radps.y(), -2e-3, 1e-15);
  // On a reading exactly.
  EXPECT_NEAR(bias_truth_at(truth, 1'300'000'000).accel_mps2.x(), 0.015, 1e-15);
}

TEST(InertialEval, EachFramesFirstAndLastReadingGiveTheBiasesAtEveryFrameTime) {
  // Readings at 200 Hz on a seeded random walk, frames at 30 Hz; a frame's
  // readings taken either up to and including its time or up to before it.
  std::mt19937 rng(7);
  std::normal_distribution<double> step(0.0, 1e-4);
  std::vector<BiasTruth> all;
  Eigen::Vector3d g = Eigen::Vector3d::Zero(), a = Eigen::Vector3d::Zero();
  for (int i = 0; i <= 400; ++i) {
    g += Eigen::Vector3d(step(rng), step(rng), step(rng));
    a += 10 * Eigen::Vector3d(step(rng), step(rng), step(rng));
    all.push_back({i * 5'000'000LL, g, a});
  }
  std::vector<std::int64_t> frame_ns;
  for (int k = 0; k <= 59; ++k) frame_ns.push_back((k * 1'000'000'000LL + 15) / 30);
  for (const bool up_to_and_including : {true, false}) {
    std::vector<BiasTruth> delivered, kept, batch;
    std::size_t r = 0;
    for (const std::int64_t t_ns : frame_ns) {
      batch.clear();
      while (r < all.size() && (up_to_and_including ? all[r].t_ns <= t_ns : all[r].t_ns < t_ns))
        batch.push_back(all[r++]);
      delivered.insert(delivered.end(), batch.begin(), batch.end());
      keep_frame_ends(batch, &kept);
    }
    EXPECT_LT(kept.size(), delivered.size() / 2);
    for (const std::int64_t t_ns : frame_ns) {
      EXPECT_EQ(bias_truth_at(kept, t_ns).gyro_radps, bias_truth_at(delivered, t_ns).gyro_radps) << t_ns;
      EXPECT_EQ(bias_truth_at(kept, t_ns).accel_mps2, bias_truth_at(delivered, t_ns).accel_mps2) << t_ns;
    }
  }
}

TEST(InertialEval, KeyframeBiasErrorsOfKnownSize) {
  const std::int64_t t0_ns = 1'000'000'000;
  const std::vector<BiasTruth> truth = ramp_truth(t0_ns, 21, 100'000'000);  // 2 s
  // Four keyframes, given out of time order; each estimate off the truth by
  // a known vector: gyro errors of norm 3e-3, 0, 4e-3, 0 (RMS 2.5e-3),
  // accel errors of norm 0.1, 0.2, 0.2, 0.1 (RMS sqrt(0.025)).
  const std::int64_t t_ns[] = {t0_ns + 1'500'000'000, t0_ns + 150'000'000, t0_ns + 700'000'000,
                               t0_ns + 1'950'000'000};
  const Eigen::Vector3d gyro_err[] = {{0, 0, 4e-3}, {3e-3, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  const Eigen::Vector3d accel_err[] = {{0.2, 0, 0}, {0, 0.1, 0}, {0, 0, -0.2}, {0.06, 0.08, 0}};
  std::vector<KeyframeBias> kfs;
  for (int i = 0; i < 4; ++i) {
    const BiasTruth t = bias_truth_at(truth, t_ns[i]);
    kfs.push_back({static_cast<std::uint64_t>(10 + i),
                   t_ns[i],
                   {t.gyro_radps + gyro_err[i], t.accel_mps2 + accel_err[i]}});
  }
  const BiasComparison c = compare_biases(kfs, truth, t0_ns, true);
  ASSERT_EQ(c.t_s.size(), 4u);
  EXPECT_EQ(c.keyframe_id, (std::vector<std::uint64_t>{11, 12, 10, 13}));  // in time order
  EXPECT_NEAR(c.t_s[0], 0.15, 1e-12);
  EXPECT_NEAR(c.t_s[3], 1.95, 1e-12);
  EXPECT_NEAR(c.gyro_rms_radps, 2.5e-3, 1e-12);
  EXPECT_NEAR(c.accel_rms_mps2, std::sqrt(0.025), 1e-12);
  EXPECT_NEAR(c.gyro_final_radps, 0.0, 1e-12);  // the last keyframe in time
  EXPECT_NEAR(c.accel_final_mps2, 0.1, 1e-12);
  // The series: true at 0.15 s and the estimate beside it.
  EXPECT_NEAR(c.gyro_true_radps[0][0], 0.15e-3, 1e-15);
  EXPECT_NEAR(c.gyro_est_radps[0][0], 0.15e-3 + 3e-3, 1e-15);
  EXPECT_NEAR(c.accel_true_mps2[1][0], 0.1, 1e-15);
  EXPECT_NEAR(c.accel_est_mps2[1][0], 0.2, 1e-15);
  // A biased estimate is not within the error of a good one.
  std::vector<KeyframeBias> exact = kfs;
  for (int i = 0; i < 4; ++i)
    exact[i].bias = {bias_truth_at(truth, t_ns[i]).gyro_radps, bias_truth_at(truth, t_ns[i]).accel_mps2};
  EXPECT_NEAR(compare_biases(exact, truth, t0_ns, true).gyro_rms_radps, 0.0, 1e-15);
  EXPECT_NEAR(compare_biases(exact, truth, t0_ns, true).accel_rms_mps2, 0.0, 1e-15);

  const YAML::Node j = YAML::Load(inertial_json({true, 0.5, 12, 1.0, 0.8, c, std::nullopt, std::nullopt, std::nullopt}))["biases"];
  EXPECT_EQ(j["keyframes"].as<int>(), 4);
  EXPECT_NEAR(j["gyro_rms_radps"].as<double>(), 2.5e-3, 1e-9);
  EXPECT_NEAR(j["accel_rms_mps2"].as<double>(), std::sqrt(0.025), 1e-9);
  EXPECT_EQ(j["keyframe_id"][0].as<int>(), 11);
  ASSERT_EQ(j["gyro_est_radps"].size(), 4u);
  EXPECT_NEAR(j["gyro_est_radps"][0][0].as<double>(), 0.15e-3 + 3e-3, 1e-12);
  EXPECT_NEAR(j["accel_true_mps2"][0][1].as<double>(), 0.1, 1e-12);  // [keyframe][axis]
  // An accelerometer alone: no gyro bias to compare.
  const YAML::Node a =
      YAML::Load(inertial_json({true, 0.5, 12, 1.0, 0.8, compare_biases(kfs, truth, t0_ns, false), std::nullopt, std::nullopt, std::nullopt}));
  EXPECT_TRUE(a["biases"]["gyro_rms_radps"].IsNull());
  EXPECT_TRUE(a["biases"]["gyro_est_radps"].IsNull());
  EXPECT_NEAR(a["biases"]["accel_rms_mps2"].as<double>(), std::sqrt(0.025), 1e-9);
}

TEST(InertialEval, TrustedStateAndGravityTilt) {
  slam::MapGravity g;
  const InertialReport not_yet = inertial_report(g, 5'000'000'000);
  EXPECT_FALSE(not_yet.trusted);
  const YAML::Node n = YAML::Load(inertial_json(not_yet));
  EXPECT_FALSE(n["trusted"].as<bool>());
  for (const char* k : {"trusted_t_s", "trusted_keyframe", "gravity_tilt_deg", "init_rms", "biases"})
    EXPECT_TRUE(n[k].IsNull()) << k;

  g.ready = true;
  g.g_w = Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()) * Eigen::Vector3d(0, 0, -9.81);
  g.ready_keyframe_id = 9;
  g.ready_t_ns = 7'250'000'000;
  g.init_rms = 1.25;
  const InertialReport r = inertial_report(g, 5'000'000'000);
  EXPECT_TRUE(r.trusted);
  EXPECT_NEAR(r.trusted_t_s, 2.25, 1e-12);  // from the first frame
  EXPECT_EQ(r.trusted_keyframe, 9u);
  EXPECT_NEAR(r.gravity_tilt_deg, 3.0, 1e-9);
  EXPECT_NEAR(gravity_tilt_deg(Eigen::Vector3d(0, 0, 9.81)), 180.0, 1e-9);
  const YAML::Node y = YAML::Load(inertial_json(r));
  EXPECT_TRUE(y["trusted"].as<bool>());
  EXPECT_NEAR(y["trusted_t_s"].as<double>(), 2.25, 1e-9);
  EXPECT_EQ(y["trusted_keyframe"].as<int>(), 9);
  EXPECT_NEAR(y["gravity_tilt_deg"].as<double>(), 3.0, 1e-6);
  EXPECT_NEAR(y["init_rms"].as<double>(), 1.25, 1e-9);
  EXPECT_TRUE(y["biases"].IsNull());  // no truth
}

TEST(InertialEval, WheelCalibrationAgainstTheRobotsTruth) {
  const std::string dir = temp_dir("wheels");
  {
    std::ofstream f(dir + "/robot_truth.yaml");
    f << "wheel_radius_m: 0.1\ntrack_m: 0.42\neffective_wheel_radius_m: 0.0998\neffective_track_m: 0.4536\n"
         "nominal_wheel_radius_m: 0.1\nnominal_track_m: 0.42\nradius_difference: 0.004\n";
  }
  const slam::WheelCalibration t = read_wheels_true(dir + "/robot_truth.yaml");
  EXPECT_NEAR(t.left_scale, 0.998 * 0.998, 1e-12);
  EXPECT_NEAR(t.right_scale, 0.998 * 1.002, 1e-12);
  EXPECT_NEAR(t.track_scale, 1.08, 1e-12);
  {
    std::ofstream f(dir + "/bad.yaml");
    f << "effective_wheel_radius_m: 0.0998\nnominal_wheel_radius_m: -1\n";
  }
  try {
    read_wheels_true(dir + "/bad.yaml");
    ADD_FAILURE() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("nominal_wheel_radius_m"), std::string::npos) << e.what();
  }

  InertialReport r;
  EXPECT_TRUE(YAML::Load(inertial_json(r))["wheels"].IsNull());  // no online calibration
  slam::WheelFit w;
  w.calibration = {0.9961, 0.9999, 1.079};
  w.radii_known = true;
  w.intervals = 800;
  w.refused = 2;
  w.rolled_m = 230.5;
  w.turned_rad = 4.1;
  r.wheels = w;
  YAML::Node j = YAML::Load(inertial_json(r))["wheels"];
  EXPECT_NEAR(j["left_scale"].as<double>(), 0.9961, 1e-9);
  EXPECT_NEAR(j["track_scale"].as<double>(), 1.079, 1e-9);
  EXPECT_TRUE(j["radii_known"].as<bool>());
  EXPECT_FALSE(j["track_known"].as<bool>());
  EXPECT_EQ(j["intervals"].as<int>(), 800);
  EXPECT_EQ(j["refused"].as<int>(), 2);
  EXPECT_TRUE(j["true_left_scale"].IsNull());
  r.wheels_true = t;
  j = YAML::Load(inertial_json(r))["wheels"];
  EXPECT_NEAR(j["true_right_scale"].as<double>(), t.right_scale, 1e-9);
  const std::string line = wheels_text(w, t);
  EXPECT_NE(line.find("track x1.0790 (not yet observed)"), std::string::npos) << line;
  EXPECT_NE(line.find("the robot:"), std::string::npos) << line;
}

// --- The report ---

SlamRun inertial_run(const std::string& sensors, std::size_t dead_reckoned) {
  SlamRun r;
  r.mode = "pe-slam";
  r.sensors = sensors;
  r.frames = 40;
  r.dead_reckoned_frames = dead_reckoned;
  for (int i = 0; i < 40; ++i) r.per_frame.push_back({i, i / 30.0, true, 10.0 + i % 3, 200, 190, {}, {}});
  eval::GravityError g;
  g.map_frame = sensors == "camera" ? "first_camera" : "gravity_aligned";
  g.t_s = {0.0, 0.5, 1.0};
  g.angle_deg = {0.5, 1.0, 2.0};
  g.median_deg = 1.0, g.p95_deg = 1.9, g.final_deg = 2.0;
  r.gravity = g;
  eval::TiltDrift t;
  t.t_s = {0.0, 0.6, 1.2};
  t.pitch_deg = {0.0, 0.1, 0.2};
  t.roll_deg = {0.0, -0.05, -0.1};
  t.pitch_mean_deg = 0.1, t.roll_mean_deg = -0.05;
  t.pitch_slope_deg_per_kf = 0.1, t.roll_slope_deg_per_kf = -0.05;
  t.pitch_slope_sign = 1, t.roll_slope_sign = -1;
  r.tilt = t;
  if (sensors != "camera") {
    const std::vector<BiasTruth> truth = ramp_truth(0, 21, 100'000'000);
    std::vector<KeyframeBias> kfs;
    for (int i = 0; i < 5; ++i) kfs.push_back({static_cast<std::uint64_t>(i), i * 300'000'000LL, {}});
    r.inertial = InertialReport{true, 0.9, 3, 0.4, 1.1, compare_biases(kfs, truth, 0, true), std::nullopt, std::nullopt, std::nullopt};
  }
  return r;
}

RunReport sensors_report() {
  RunReport r;
  r.scenario = "pv_station";
  r.scenario_file = "scenes/pv_station.yaml";
  r.seed = 7;
  r.renderer = "test";
  r.sim_s = 40 / 30.0;
  r.wall_s = 1;
  r.primary = inertial_run("camera+imu", 6);
  r.baseline = inertial_run("camera", 0);
  return r;
}

TEST(RunReportInertial, MetricsJsonPerSystem) {
  const YAML::Node m = YAML::Load(metrics_json(sensors_report()));
  EXPECT_EQ(m["sensors"].as<std::string>(), "camera+imu");
  EXPECT_EQ(m["dead_reckoned_frames"].as<int>(), 6);
  EXPECT_EQ(m["gravity"]["map_frame"].as<std::string>(), "gravity_aligned");
  EXPECT_NEAR(m["gravity"]["median_deg"].as<double>(), 1.0, 1e-9);
  EXPECT_NEAR(m["gravity"]["final_deg"].as<double>(), 2.0, 1e-9);
  EXPECT_EQ(m["gravity"]["angle_deg"].size(), 3u);
  EXPECT_EQ(m["tilt"]["pitch_slope_sign"].as<int>(), 1);
  EXPECT_EQ(m["tilt"]["roll_slope_sign"].as<int>(), -1);
  EXPECT_EQ(m["tilt"]["pitch_deg"].size(), 3u);
  EXPECT_TRUE(m["inertial"]["trusted"].as<bool>());
  EXPECT_EQ(m["inertial"]["trusted_keyframe"].as<int>(), 3);
  EXPECT_EQ(m["inertial"]["biases"]["keyframes"].as<int>(), 5);
  EXPECT_GT(m["inertial"]["biases"]["accel_rms_mps2"].as<double>(),
            0.05);  // zero estimates of a ramping truth
  // The reference: camera alone, no inertial state.
  EXPECT_EQ(m["baseline"]["sensors"].as<std::string>(), "camera");
  EXPECT_EQ(m["baseline"]["dead_reckoned_frames"].as<int>(), 0);
  EXPECT_EQ(m["baseline"]["gravity"]["map_frame"].as<std::string>(), "first_camera");
  EXPECT_FALSE(m["baseline"]["inertial"]);
}

TEST(RunReportInertial, CompareSensorsNamesTheSystemsBySetup) {
  const RunReport r = sensors_report();
  EXPECT_TRUE(compares_sensors(r));
  EXPECT_EQ(system_label(r, r.primary), "camera+imu");
  EXPECT_EQ(system_label(r, *r.baseline), "camera");
  EXPECT_EQ(comparison_heading(r), "camera+imu against camera");
  const YAML::Node c = YAML::Load(metrics_json(r))["comparison"];
  EXPECT_EQ(c["primary"].as<std::string>(), "camera+imu");
  EXPECT_EQ(c["reference"].as<std::string>(), "camera");
  EXPECT_TRUE(c["tracking_ms_median"]["camera+imu"].IsScalar());
  EXPECT_TRUE(c["tracking_ms_median"]["camera"].IsScalar());
  EXPECT_FALSE(c["tracking_ms_median"]["baseline"]);
  EXPECT_EQ(c["dead_reckoned_frames"]["camera+imu"].as<int>(), 6);
  EXPECT_EQ(c["dead_reckoned_frames"]["camera"].as<int>(), 0);

  // PE-SLAM against the baseline keeps its names.
  RunReport pe = sensors_report();
  pe.baseline->mode = "baseline";
  pe.baseline->sensors = "camera+imu";
  EXPECT_FALSE(compares_sensors(pe));
  EXPECT_EQ(comparison_heading(pe), "PE-SLAM against the baseline (ORB-SLAM2 motion model)");
  const YAML::Node pc = YAML::Load(metrics_json(pe))["comparison"];
  EXPECT_EQ(pc["primary"].as<std::string>(), "pe-slam");
  EXPECT_EQ(pc["reference"].as<std::string>(), "baseline");
  EXPECT_TRUE(pc["tracking_ms_median"]["pe-slam"].IsScalar());
  EXPECT_TRUE(pc["tracking_ms_median"]["baseline"].IsScalar());
}

TEST(RunReportInertial, IndexHtmlAndFigures) {
  const std::string dir = temp_dir("report");
  const RunReport r = sensors_report();
  const std::vector<std::string> figures = write_report(r, dir);
  for (const char* f : {"gravity_error", "tilt_error", "imu_gyro_bias", "imu_accel_bias"}) {
    EXPECT_NE(std::find(figures.begin(), figures.end(), f), figures.end()) << f;
    EXPECT_TRUE(std::ifstream(dir + "/" + f + ".png").good()) << f;
  }
  // Camera alone has no biases to plot.
  EXPECT_EQ(std::find(figures.begin(), figures.end(), "imu_accel_bias_baseline"), figures.end());
  const std::string svg = read_file(dir + "/imu_accel_bias.svg");
  EXPECT_NE(svg.find("x estimated"), std::string::npos);
  EXPECT_NE(svg.find("z true"), std::string::npos);
  const std::string html = read_file(dir + "/index.html");
  EXPECT_NE(html.find("<h2>Gravity and inertial state</h2>"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>dead-reckoned frames</th><td>6</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>sensors fused</th><td>camera+imu</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("trusted at t = 0.90 s (keyframe 3)"), std::string::npos);
  EXPECT_NE(html.find("same system fusing camera"), std::string::npos);

  // Without the data: none of these figures, no section.
  RunReport bare = r;
  bare.primary.gravity.reset(), bare.primary.tilt.reset(), bare.primary.inertial.reset();
  bare.baseline.reset();
  const std::vector<std::string> none = write_report(bare, temp_dir("bare"));
  for (const char* f : {"gravity_error", "tilt_error", "imu_gyro_bias", "imu_accel_bias"})
    EXPECT_EQ(std::find(none.begin(), none.end(), f), none.end()) << f;
  EXPECT_EQ(index_html(bare, none).find("Gravity and inertial state"), std::string::npos);
}

}  // namespace
}  // namespace pvb::run
