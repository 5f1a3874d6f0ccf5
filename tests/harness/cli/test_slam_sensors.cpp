// pvbench slam --sensors: the setup reaches the settings and stats.json,
// a bad value is one error line naming the flag, and camera+accel on a
// folder with a Kinect accelerometer.txt gets the Kinect's IMU description.
// The core does not fuse the readings yet: the trajectories stay those of
// camera alone.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <string>

#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/time.hpp"
#include "run_pvbench.hpp"

using namespace pvb;

namespace {

constexpr int kFrames = 15, kWidth = 320, kHeight = 240;
constexpr double kFocalPx = 300, kDepthM = 2.0, kShiftPx = 2.0;

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_slam_sensors_" + name + "_" + std::to_string(::getpid());
  std::filesystem::remove_all(d);
  return d;
}

/// A textured plane sliding past the camera (seeded), with ground truth,
/// camera.yaml (no IMU.* keys) and, with `accel`, a Kinect accelerometer.txt
/// reading 1 g along the accelerometer's -y at 500 Hz.
std::string make_sequence(const std::string& name, bool accel) {
  const std::string dir = fresh(name);
  cv::Mat texture(kHeight + 20, kWidth + 2 * kFrames * static_cast<int>(kShiftPx), CV_8UC3);
  cv::RNG(11).fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.5);
  dataset::TumSequenceWriter writer(dir);
  for (int i = 0; i < kFrames; ++i) {
    sensor::RgbdFrame f;
    f.t_ns = geom::frame_time_ns(0, i, 30.0);
    f.index = static_cast<std::size_t>(i);
    texture(cv::Rect(static_cast<int>(i * kShiftPx), 10, kWidth, kHeight)).copyTo(f.rgb);
    f.depth_m = cv::Mat(kHeight, kWidth, CV_32FC1, cv::Scalar(kDepthM));
    writer.write(f, geom::make_se3(geom::Mat3d::Identity(), geom::Vec3d(i * kShiftPx * kDepthM / kFocalPx, 0, 0)));
  }
  dataset::OrbSlamSettings s;
  s.K = {kFocalPx, kFocalPx, 159.5, 119.5, kWidth, kHeight};
  s.bf = 0.075 * kFocalPx;
  dataset::write_orbslam_settings(dir + "/camera.yaml", s);
  if (accel) {
    std::string text = "# accelerometer data\n# timestamp ax ay az\n";
    for (int k = 0; k < kFrames * 500 / 30; ++k)
      text += geom::format_tum_time(k * 2'000'000LL) + " 0.0 -9.80665 0.0\n";
    write_file(dir + "/accelerometer.txt", text);
  }
  return dir;
}

test::RunResult slam(const std::string& seq, const std::string& out, const std::string& extra) {
  return test::run_pvbench("slam --sequence " + seq + " --settings " + seq + "/camera.yaml --out " + out +
                           " --sync --no-dense " + extra);
}

}  // namespace

TEST(SlamSensors, TheSetupReachesStatsAndCameraTrajectoriesStay) {
  const std::string seq = make_sequence("accel", true);
  const std::string cam = fresh("cam_out"), acc = fresh("acc_out");
  const test::RunResult a = slam(seq, cam, "");
  ASSERT_EQ(a.code, 0) << a.output;
  EXPECT_NE(read_file(cam + "/stats.json").find("\"sensors\": \"camera\""), std::string::npos);
  const test::RunResult b = slam(seq, acc, "--sensors camera+accel");
  ASSERT_EQ(b.code, 0) << b.output;
  EXPECT_NE(read_file(acc + "/stats.json").find("\"sensors\": \"camera+accel\""), std::string::npos);
  EXPECT_NE(b.output.find("Kinect v1 accelerometer's description"), std::string::npos) << b.output;
  // The flag's default is the settings' own (camera here): the same bytes.
  const std::string cam2 = fresh("cam2_out");
  ASSERT_EQ(slam(seq, cam2, "--sensors camera").code, 0);
  EXPECT_EQ(read_file(cam + "/CameraTrajectory.txt"), read_file(cam2 + "/CameraTrajectory.txt"));
  // With the accelerometer the map begins level: the first pose is no
  // longer the identity.
  EXPECT_NE(read_file(cam + "/CameraTrajectory.txt"), read_file(acc + "/CameraTrajectory.txt"));
  EXPECT_NE(read_file(acc + "/stats.json").find("\"gravity\": {\"map_frame\": \"gravity_aligned\""),
            std::string::npos);
}

TEST(SlamSensors, ABadSetupIsOneLineNamingTheFlagAndTheValues) {
  const std::string seq = make_sequence("bad", false);
  const test::RunResult r = slam(seq, fresh("bad_out"), "--sensors camera+gps");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output,
            "pvbench: error: command line: --sensors: expected camera, camera+imu, camera+imu+wheels or "
            "camera+accel, got camera+gps\n");
}

TEST(SlamSensors, ASetupWhoseSensorsTheSettingsLackIsRefused) {
  const std::string seq = make_sequence("lacking", false);
  const test::RunResult imu = slam(seq, fresh("imu_out"), "--sensors camera+imu");
  EXPECT_EQ(imu.code, 1) << imu.output;
  EXPECT_NE(imu.output.find("IMU.NoiseGyro"), std::string::npos) << imu.output;
  // camera+accel without accelerometer.txt: no Kinect description to supply
  const test::RunResult accel = slam(seq, fresh("accel_out"), "--sensors camera+accel");
  EXPECT_EQ(accel.code, 1) << accel.output;
  EXPECT_NE(accel.output.find("IMU.NoiseGyro"), std::string::npos) << accel.output;
}
