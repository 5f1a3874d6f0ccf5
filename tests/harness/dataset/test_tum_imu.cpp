// The motion readings of a TUM folder: the Kinect's accelerometer.txt in
// the optical frame, attached to the frames since the previous one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/tum_imu.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/geometry/time.hpp"

using namespace pvb;

namespace {
std::string imu_temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_imu_" + name;
  std::system(("rm -rf " + d + " && mkdir -p " + d).c_str());
  return d;
}
}  // namespace

TEST(TumImu, KinectAccelerometerGoesIntoTheOpticalFrameWithoutGyro) {
  const std::string dir = imu_temp_dir("axes");
  write_file(dir + "/accelerometer.txt",
             "# accelerometer data\n# timestamp ax ay az\n1.001 1 2 3\n1.002 0.5 -9.7 1.25\n");
  const std::vector<sensor::ImuSample> s = dataset::read_tum_accelerometer(dir + "/accelerometer.txt");
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].t_ns, 1'001'000'000);
  EXPECT_EQ(s[1].accel_mps2, Eigen::Vector3d(-0.5, 9.7, 1.25));  // x, y change sign; z stays
  EXPECT_FALSE(sensor::has_gyro(s[1]));
  EXPECT_TRUE(std::isnan(s[1].gyro_radps.x()));
  sensor::ImuSample full;
  EXPECT_TRUE(sensor::has_gyro(full));
  EXPECT_NEAR(dataset::kinect_accel_to_optical().determinant(), 1.0, 1e-12);  // a rotation
}

TEST(TumImu, ABadLineNamesTheFileTheLineAndWhatWasExpected) {
  const std::string dir = imu_temp_dir("bad");
  write_file(dir + "/accelerometer.txt", "# timestamp ax ay az\n1.0 1 2 3\n1.1 1 two 3\n");
  try {
    dataset::read_tum_accelerometer(dir + "/accelerometer.txt");
    FAIL() << "no error";
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("accelerometer.txt"), std::string::npos) << what;
    EXPECT_NE(what.find(":3"), std::string::npos) << what;
    EXPECT_NE(what.find("timestamp ax ay az"), std::string::npos) << what;
  }
  write_file(dir + "/accelerometer.txt", "1.0 1 2\n");
  EXPECT_THROW(dataset::read_tum_accelerometer(dir + "/accelerometer.txt"), IoError);
  write_file(dir + "/accelerometer.txt", "1.0 1 2 nan\n");
  EXPECT_THROW(dataset::read_tum_accelerometer(dir + "/accelerometer.txt"), IoError);
}

TEST(TumImu, EachFrameGetsTheReadingsSinceThePreviousFrame) {
  const std::string dir = imu_temp_dir("frames") + "/seq";
  {
    dataset::TumSequenceWriter w(dir);
    for (int i = 0; i < 3; ++i) {
      sensor::RgbdFrame f;
      f.t_ns = geom::frame_time_ns(0, i, 10.0);  // 0, 0.1, 0.2 s
      f.rgb = cv::Mat(8, 8, CV_8UC3, cv::Scalar(i, i, i));
      f.depth_m = cv::Mat(8, 8, CV_32FC1, cv::Scalar(1.0));
      w.write(f, geom::SE3d::Identity());
    }
  }
  write_file(dir + "/accelerometer.txt", "-0.5 0 0 9.8\n0.0 0 0 9.8\n0.05 0 0 9.8\n0.1 0 0 9.8\n0.15 0 0 9.8\n0.3 0 0 9.8\n");
  EXPECT_EQ(dataset::tum_imu_source(dir), dataset::TumImuSource::kKinectAccelerometer);
  dataset::TumSequenceReader r(dir);
  std::vector<std::size_t> counts;
  while (const auto f = r.next()) counts.push_back(f->imu.size());
  EXPECT_EQ(counts, (std::vector<std::size_t>{2, 2, 1}));  // up to and with each frame's time
}
