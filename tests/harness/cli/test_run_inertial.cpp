// pvbench run with motion sensors, end to end: the gravity, tilt, inertial
// and dead-reckoning keys of metrics.json on a short camera+imu run (the
// biases against the run's own imu0/truth.csv), their figures, and
// --compare-sensors naming the two systems by their setups.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "cli_output.hpp"
#include "pvb/common/io_paths.hpp"
#include "pvb/common/text.hpp"
#include "pvb/run/output_names.hpp"
#include "run_pvbench.hpp"
#include "station_sequence.hpp"

using namespace pvb;

namespace {

const std::string kStation = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_run_inertial_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + d).c_str());
  return d;
}

bool exists(const std::string& path) { return std::ifstream(path).good(); }

YAML::Node metrics(const std::string& dir) { return YAML::Load(read_file(dir + "/metrics.json")); }

/// Rows of timing.csv in tracking state `state`.
int frames_in_state(const std::string& dir, const std::string& state) {
  int n = 0;
  for (const std::string& line : test::data_lines(dir + "/timing.csv")) {
    const std::vector<std::string> f = split_ws(line, ",");
    n += f.size() > 2 && f[2] == state;
  }
  return n;
}

/// imu0/truth.csv's gyro bias (bw_x..z) of the reading nearest t_s.
std::vector<double> true_gyro_bias_near(const std::string& dir, double t_s) {
  std::vector<double> best;
  double best_dt = std::numeric_limits<double>::infinity();
  for (const std::string& line : test::data_lines(dir + "/imu0/truth.csv")) {
    const std::vector<std::string> f = split_ws(line, ",");
    if (f.size() != 13 || f[0][0] == '#') continue;
    const double dt = std::abs(std::stod(f[0]) * 1e-9 - t_s);
    if (dt < best_dt) best_dt = dt, best = {std::stod(f[7]), std::stod(f[8]), std::stod(f[9])};
  }
  return best;
}

// The shared 200-frame camera+imu run: the inertial state is trusted after
// about 3 s of the station's drive, within the first 4 s.
TEST(RunInertialCli, CameraImuRunReportsGravityTiltAndBiases) {
  const std::string d = test::station_imu_run();
  const std::string log = read_file(d + "/run.log");
  const YAML::Node m = metrics(d);
  EXPECT_EQ(m["sensors"].as<std::string>(), "camera+imu");
  EXPECT_EQ(m["dead_reckoned_frames"].as<int>(), frames_in_state(d, "dead_reckoning"));
  // Gravity: every tracked frame; tilt: every keyframe of KeyFrameTrajectory.txt.
  EXPECT_EQ(m["gravity"]["map_frame"].as<std::string>(), "gravity_aligned");
  EXPECT_EQ(m["gravity"]["frames"].as<int>(),
            static_cast<int>(test::data_lines(d + "/CameraTrajectory.txt").size()));
  EXPECT_EQ(m["gravity"]["angle_deg"].size(), m["gravity"]["t_s"].size());
  EXPECT_LE(m["gravity"]["median_deg"].as<double>(), m["gravity"]["p95_deg"].as<double>());
  EXPECT_EQ(m["tilt"]["keyframes"].as<int>(),
            static_cast<int>(test::data_lines(d + "/KeyFrameTrajectory.txt").size()));
  EXPECT_TRUE(std::isfinite(m["tilt"]["pitch_slope_deg_per_keyframe"].as<double>()));
  // The inertial state: trusted within the run, its biases against the run's truth.
  const YAML::Node in = m["inertial"];
  ASSERT_TRUE(in["trusted"].as<bool>()) << log;
  EXPECT_GT(in["trusted_t_s"].as<double>(), 0.0);
  EXPECT_LT(in["trusted_t_s"].as<double>(), 4.0);
  EXPECT_GT(in["trusted_keyframe"].as<int>(), 0);
  EXPECT_GE(in["gravity_tilt_deg"].as<double>(), 0.0);
  EXPECT_NE(log.find("inertial state trusted (camera+imu, keyframe " + in["trusted_keyframe"].as<std::string>()),
            std::string::npos)
      << log;
  const YAML::Node b = in["biases"];
  ASSERT_TRUE(b && b.IsMap());
  const int kfs = b["keyframes"].as<int>();
  EXPECT_GT(kfs, 1);
  EXPECT_EQ(static_cast<int>(b["t_s"].size()), kfs);
  EXPECT_EQ(static_cast<int>(b["gyro_true_radps"].size()), kfs);
  // The true series are imu0/truth.csv's biases at the keyframes' times,
  // interpolated; the nearest reading is within one 5 ms step of the bias
  // walk (2e-5 rad/s/sqrt(s): 1.4e-6 rad/s at one sigma), a second away
  // would be 2e-5 off.
  for (int k : {0, kfs - 1}) {
    const std::vector<double> truth = true_gyro_bias_near(d, b["t_s"][k].as<double>());
    ASSERT_EQ(truth.size(), 3u);
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(b["gyro_true_radps"][k][a].as<double>(), truth[a], 4e-6) << k << a;
  }
  // The gyro bias (about 0.016 rad/s in the station's IMU) is estimated well; zero would not pass.
  EXPECT_LT(b["gyro_rms_radps"].as<double>(), 0.005);
  EXPECT_GT(b["accel_rms_mps2"].as<double>(), 0.0);
  for (const char* f : {"gravity_error", "tilt_error", "imu_gyro_bias", "imu_accel_bias"}) {
    EXPECT_TRUE(exists(d + "/" + f + ".png")) << f;
    EXPECT_NE(read_file(d + "/index.html").find(std::string(f) + ".png"), std::string::npos) << f;
  }
  EXPECT_NE(read_file(d + "/index.html").find("<tr><th>dead-reckoned frames</th>"), std::string::npos);
}

// Two live synchronous runs with the IMU (the shared one and this test's,
// cut 50 frames short: a shorter run is the start of a longer one) write
// the same trajectory bit for bit, well past the inertial initialisation
// (trusted at frame 99 of the shared run): local BA's velocity and bias
// blocks once took their order from the heap, which the rendering thread's
// allocations changed from run to run.
TEST(RunInertialCli, LiveRunsWithAnImuAreBitIdentical) {
  constexpr int kFrames = test::kStationImuRunFrames - 50;
  const std::string shared = test::station_imu_run(), d = fresh("imu_sync");
  const test::RunResult r =
      test::run_pvbench("run --scenario " + kStation + " --out " + d + " --sync --frames " +
                        std::to_string(kFrames) + " --no-map-eval --sensors camera+imu");
  ASSERT_EQ(r.code, 0) << r.output;
  for (const std::string& dir : {shared, d}) ASSERT_TRUE(metrics(dir)["inertial"]["trusted"].as<bool>()) << dir;
  const YAML::Node m = metrics(shared);  // trusted a second or more before the shorter run ends
  EXPECT_LT(m["inertial"]["trusted_t_s"].as<double>() * m["fps"].as<double>(), kFrames - m["fps"].as<double>());
  const std::string whole = read_file(shared + "/CameraTrajectory.txt"), cut = read_file(d + "/CameraTrajectory.txt");
  ASSERT_FALSE(cut.empty());
  EXPECT_EQ(std::count(cut.begin(), cut.end(), '\n'),
            std::count(whole.begin(), whole.end(), '\n') - (test::kStationImuRunFrames - kFrames));
  EXPECT_TRUE(whole.compare(0, cut.size(), cut) == 0) << "the shorter run is not the start of the longer one";
}

// pvbench slam on a recording (the first 120 frames of the shared one):
// the same keys in stats.json, the biases against the recording's
// imu0/truth.csv.
TEST(RunInertialCli, SlamOnARecordingComparesTheBiasesWithItsTruth) {
  const std::string& rec = test::station_sequence();
  const std::string out = fresh("slam");
  const test::RunResult r =
      test::run_pvbench("slam --sequence " + rec + " --settings " + rec + "/camera.yaml --out " + out +
                        " --sync --no-dense --max-frames 120 --sensors camera+imu");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("inertial state trusted at t = "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("bias error RMS over "), std::string::npos) << r.output;
  const YAML::Node s = YAML::Load(read_file(out + "/stats.json"));
  EXPECT_EQ(s["dead_reckoned_frames"].as<int>(), frames_in_state(out, "dead_reckoning"));
  EXPECT_EQ(s["gravity"]["map_frame"].as<std::string>(), "gravity_aligned");
  ASSERT_TRUE(s["inertial"]["trusted"].as<bool>());
  const YAML::Node b = s["inertial"]["biases"];
  ASSERT_TRUE(b && b.IsMap());
  EXPECT_GT(b["keyframes"].as<int>(), 1);
  EXPECT_LT(b["gyro_rms_radps"].as<double>(), 0.005);
  const std::vector<double> truth = true_gyro_bias_near(rec, b["t_s"][0].as<double>());
  ASSERT_EQ(truth.size(), 3u);
  EXPECT_NEAR(b["gyro_true_radps"][0][2].as<double>(), truth[2], 4e-7);
  // Camera alone: no inertial state.
  const std::string cam = fresh("slam_cam");
  ASSERT_EQ(test::run_pvbench("slam --sequence " + rec + " --settings " + rec + "/camera.yaml --out " + cam +
                              " --sync --no-dense --max-frames 10 --sensors camera")
                .code,
            0);
  EXPECT_FALSE(YAML::Load(read_file(cam + "/stats.json"))["inertial"]);
  EXPECT_EQ(YAML::Load(read_file(cam + "/stats.json"))["dead_reckoned_frames"].as<int>(), 0);
}

TEST(RunInertialCli, CompareSensorsNamesTheSystemsBySetup) {
  const std::string d = fresh("compare");
  const test::RunResult r =
      test::run_pvbench("run --scenario " + kStation + " --out " + d +
                        " --sync --frames 30 --no-map-eval --compare-sensors camera,camera+imu");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("camera+imu against camera on the same frames:"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("PE-SLAM against"), std::string::npos) << r.output;
  const YAML::Node m = metrics(d);
  EXPECT_EQ(m["sensors"].as<std::string>(), "camera+imu");
  EXPECT_EQ(m["baseline"]["sensors"].as<std::string>(), "camera");
  EXPECT_EQ(m["baseline"]["mode"].as<std::string>(), "pe-slam");
  const YAML::Node c = m["comparison"];
  EXPECT_EQ(c["primary"].as<std::string>(), "camera+imu");
  EXPECT_EQ(c["reference"].as<std::string>(), "camera");
  EXPECT_TRUE(c["tracking_ms_median"]["camera+imu"].IsScalar());
  EXPECT_TRUE(c["tracking_ms_median"]["camera"].IsScalar());
  EXPECT_EQ(c["dead_reckoned_frames"]["camera+imu"].as<int>(), m["dead_reckoned_frames"].as<int>());
  // 30 frames: too early for the inertial state; camera alone has none.
  EXPECT_FALSE(m["inertial"]["trusted"].as<bool>());
  EXPECT_TRUE(m["inertial"]["trusted_t_s"].IsNull());
  EXPECT_TRUE(m["inertial"]["biases"].IsNull());
  EXPECT_FALSE(m["baseline"]["inertial"]);
  EXPECT_EQ(m["baseline"]["gravity"]["map_frame"].as<std::string>(), "first_camera");
  const std::string html = read_file(d + "/index.html");
  EXPECT_NE(html.find("<h2>camera+imu against camera</h2>"), std::string::npos);
  EXPECT_NE(html.find("<h2>Gravity and inertial state</h2>"), std::string::npos);
}

// Both runs of --compare-sensors share one mode: the log named each by it
// ("baseline (ORB-SLAM2 motion model): ..." twice with --baseline); each is
// named by its sensors.
TEST(RunInertialCli, CompareSensorsNamesEachRunByItsSensorsInTheLog) {
  const std::string d = fresh("compare_log");
  const test::RunResult r =
      test::run_pvbench("run --scenario " + kStation + " --out " + d +
                        " --sync --frames 15 --no-map-eval --baseline --compare-sensors camera,camera+imu");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("\ncamera+imu: refined trajectory ATE rmse"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\ncamera: refined trajectory ATE rmse"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("motion model): refined trajectory"), std::string::npos) << r.output;
  // Every file the run wrote (its .pvbench list: the reference run's
  // folder, the motion files, the figures) is one the IoPlan refuses as
  // --save-map (pvb/run/output_names.hpp).
  std::istringstream list(read_file(d + "/.pvbench"));
  int files = 0;
  for (std::string line; std::getline(list, line);) {
    if (line.rfind("file ", 0) != 0) continue;
    ++files;
    EXPECT_TRUE(is_written_name(line.substr(5), run::run_output_names())) << line;
  }
  EXPECT_GT(files, 30);
}

}  // namespace
