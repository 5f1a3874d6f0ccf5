#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "pvb/common/text.hpp"
#include "pvb/eval/trajectory.hpp"

using namespace pvb;
using namespace pvb::eval;

namespace {
std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / ("pvb_eval_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}
}  // namespace

TEST(Trajectory, ParsesTumWithCommentsBlankLinesAndUnsortedStamps) {
  const Trajectory t = parse_tum(
      "# timestamp tx ty tz qx qy qz qw\n\n"
      "2.5 1 2 3 0 0 0 1\n"
      "   \n"
      "1305031102.175304 4,5,6 0 0 0.7071068 0.7071068\n"
      "\t1.0\t0 0 0 0 0 0 2\r\n",
      "mem");
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t.poses[0].t_ns, 1000000000);
  EXPECT_EQ(t.poses[1].t_ns, 2500000000);
  EXPECT_EQ(t.poses[2].t_ns, 1305031102175304000);  // exact, no double rounding
  EXPECT_TRUE(t.poses[0].T_w_c.linear().isIdentity(1e-12));  // quaternion normalised
  EXPECT_NEAR(t.poses[2].T_w_c.translation().y(), 5.0, 1e-12);
  EXPECT_NEAR(geom::rotation_angle_rad(t.poses[2].T_w_c.linear()), M_PI / 2, 1e-6);
}

TEST(Trajectory, MalformedLineNamesFileAndLine) {
  try {
    parse_tum("# header\n1.0 0 0 0 0 0 0 1\n2.0 0 0 zero 0 0 0 1\n", "traj.txt");
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.file(), "traj.txt");
    EXPECT_EQ(e.line(), 3);
    EXPECT_NE(std::string(e.what()).find("traj.txt:3:"), std::string::npos) << e.what();
  }
  try {
    parse_tum("1.0 0 0 0 0 0 0 1\n\n2.0 0 0 0 0 0 1\n", "short.txt");
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_NE(std::string(e.what()).find("expected 8 fields"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_tum("1.0 0 0 0 0 0 0 0\n", "zeroq.txt"), IoError);
  EXPECT_THROW(parse_tum("1.0 0 0 0 0 0 0 1\n1.0 1 0 0 0 0 0 1\n", "dup.txt"), IoError);
  EXPECT_THROW(parse_tum("1.0 nan 0 0 0 0 0 1\n", "nan.txt"), IoError);
}

TEST(Trajectory, EmptyFileIsAClearError) {
  const std::string path = temp_path("empty.txt");
  write_file(path, "# only a comment\n\n");
  try {
    read_tum(path);
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("empty trajectory"), std::string::npos) << e.what();
    EXPECT_EQ(e.file(), path);
  }
  EXPECT_THROW(read_tum(temp_path("does_not_exist.txt")), IoError);
}

TEST(Trajectory, TumWriteReadRoundTrip) {
  Trajectory t;
  for (int i = 0; i < 5; ++i) {
    geom::StampedPose p;
    p.t_ns = 1700000000123456000 + i * 33333000LL;
    p.T_w_c = geom::make_se3(geom::so3_exp(geom::Vec3d(0.1 * i, -0.2, 0.3)), geom::Vec3d(i, -2.0 * i, 0.5));
    t.poses.push_back(p);
  }
  const std::string path = temp_path("round.txt");
  write_tum(path, t);
  const Trajectory back = read_tum(path);
  ASSERT_EQ(back.size(), t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_EQ(back.poses[i].t_ns, t.poses[i].t_ns);
    EXPECT_TRUE(back.poses[i].T_w_c.isApprox(t.poses[i].T_w_c, 1e-8));
  }
}

TEST(Trajectory, ReadsKittiWithTimestamps) {
  const std::string poses = temp_path("kitti_poses.txt");
  const std::string times = temp_path("kitti_times.txt");
  write_file(poses,
             "1 0 0 0 0 1 0 0 0 0 1 0\n"
             "0 -1 0 1.5 1 0 0 2.5 0 0 1 -0.5\n");
  write_file(times, "0.000000e+00\n1.036400e-01\n");
  const Trajectory t = read_kitti(poses, times);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t.poses[1].t_ns, 103640000);
  EXPECT_TRUE(t.poses[1].T_w_c.translation().isApprox(geom::Vec3d(1.5, 2.5, -0.5)));
  EXPECT_NEAR(geom::rotation_angle_rad(t.poses[1].T_w_c.linear()), M_PI / 2, 1e-12);

  write_file(times, "0.0\n");
  EXPECT_THROW(read_kitti(poses, times), IoError);  // count mismatch
  write_file(times, "0.0\n0.1\n");
  write_file(poses, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n");
  try {
    read_kitti(poses, times);
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), 2);
  }
  EXPECT_THROW(read_trajectory(poses, TrajectoryFormat::kKitti), ConfigError);
}

TEST(Trajectory, ParsesSecondsExactly) {
  std::int64_t t = 0;
  ASSERT_TRUE(parse_seconds_to_ns("0.000000001", &t));
  EXPECT_EQ(t, 1);
  ASSERT_TRUE(parse_seconds_to_ns("-1.5", &t));
  EXPECT_EQ(t, -1500000000);
  ASSERT_TRUE(parse_seconds_to_ns("12", &t));
  EXPECT_EQ(t, 12000000000);
  ASSERT_TRUE(parse_seconds_to_ns("1e-3", &t));
  EXPECT_EQ(t, 1000000);
  EXPECT_FALSE(parse_seconds_to_ns("abc", &t));
  EXPECT_FALSE(parse_seconds_to_ns("1.0x", &t));
  EXPECT_FALSE(parse_seconds_to_ns(".", &t));
}

// A time stamp beyond +-9e9 s would leave int64 as t_ns: an error naming
// the line, including the ten-digit decimals converted exactly.
TEST(Trajectory, TimeStampsBeyondRangeAreErrors) {
  std::int64_t t = 0;
  ASSERT_TRUE(parse_seconds_to_ns("8999999999.999999999", &t));
  EXPECT_EQ(t, 8999999999999999999);
  for (const char* bad :
       {"9999999999.5", "9300000000", "9.3e9", "-9999999999", "99999999999999999999", "1e300", "nan", "inf"})
    EXPECT_FALSE(parse_seconds_to_ns(bad, &t)) << bad << " -> " << t;
  try {
    parse_tum("1.0 0 0 0 0 0 0 1\n9999999999.5 0 0 0 0 0 0 1\n", "late.txt");
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(std::string(e.what()).find("time stamp '9999999999.5'"), std::string::npos) << e.what();
  }
}

// An absurd position (one estimate at 1e300) or a quaternion too large to
// normalise is an error naming the file and line, not a degenerate alignment.
TEST(Trajectory, AbsurdPositionsAndQuaternionsAreErrors) {
  const std::string head = "1.0 0 0 0 0 0 0 1\n";
  for (const std::string bad : {"2.0 1e300 0 0 0 0 0 1", "2.0 0 -2e8 0 0 0 0 1", "2.0 0 0 0 1e300 0 0 1"}) {
    try {
      parse_tum(head + bad + "\n", "est.txt");
      FAIL() << bad;
    } catch (const IoError& e) {
      EXPECT_EQ(e.line(), 2) << bad;
      const std::string what = e.what();
      EXPECT_TRUE(what.find("position (") != std::string::npos ||
                  what.find("quaternion (") != std::string::npos)
          << what;
    }
  }
  EXPECT_NO_THROW(
      parse_tum(head + "2.0 6378137.0 -4.5e6 120.25 0 0 0 1\n", "ecef.txt"));  // Earth-scale is fine
}

TEST(Trajectory, FolderIsNotAnEmptyTrajectory) {
  const std::string dir = std::filesystem::path(temp_path("x")).parent_path().string();
  try {
    read_tum(dir);
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder, not a file"), std::string::npos) << e.what();
  }
}
