// The map snapshot's text format (map_snapshot.hpp): a round trip keeps every
// value, and malformed records fail with the file and line.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/slam/core/map_snapshot.hpp"

namespace {

using pvb::slam::MapSnapshot;

MapSnapshot small_snapshot() {
  MapSnapshot s;
  s.K = {520.5, 521.25, 318.75, 241.5, 41.0};
  s.scale_factor = 1.25;
  const pvb::geom::SE3d T = pvb::geom::make_se3(
      pvb::geom::Quatd(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())), {0.1, -0.2, 0.3});
  s.keyframes = {{0, 1000, pvb::geom::SE3d::Identity()}, {7, 123456789012, T}};
  s.points = {{3, {1.5, -0.25, 4.125}, 0}, {9, {-2, 1, 7.5}, 7}};
  s.measurements = {{0, 0, {100.125, 200.5}, 95.0, 0}, {1, 0, {110.0, 190.25}, -1.0, 3}, {1, 1, {5.5, 6.5}, 1.0, 7}};
  return s;
}

MapSnapshot parse(const std::string& text) {
  std::istringstream is(text);
  return pvb::slam::read_map_snapshot(is, "Map.txt");
}

std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const pvb::IoError& e) {
    return e.what();
  }
  return "no error";
}

TEST(MapSnapshot, RoundTripKeepsEveryValue) {
  const MapSnapshot a = small_snapshot();
  std::ostringstream os;
  pvb::slam::write_map_snapshot(a, os, "Map.txt");
  const MapSnapshot b = parse(os.str());
  EXPECT_EQ(b.K.fx, a.K.fx);
  EXPECT_EQ(b.K.cy, a.K.cy);
  EXPECT_EQ(b.K.bf, a.K.bf);
  EXPECT_EQ(b.scale_factor, a.scale_factor);
  ASSERT_EQ(b.keyframes.size(), 2u);
  EXPECT_EQ(b.keyframes[1].id, 7u);
  EXPECT_EQ(b.keyframes[1].t_ns, 123456789012);
  EXPECT_TRUE(b.keyframes[1].T_c_w.isApprox(a.keyframes[1].T_c_w, 1e-12));
  ASSERT_EQ(b.points.size(), 2u);
  EXPECT_EQ(b.points[1].id, 9u);
  EXPECT_EQ(b.points[1].reference_keyframe_id, 7u);
  EXPECT_EQ(b.points[0].p_w, a.points[0].p_w);
  ASSERT_EQ(b.measurements.size(), 3u);
  EXPECT_EQ(b.measurements[1].keyframe, 1u);
  EXPECT_EQ(b.measurements[1].uv, a.measurements[1].uv);
  EXPECT_EQ(b.measurements[1].u_right, -1.0);
  EXPECT_EQ(b.measurements[2].octave, 7);
}

TEST(MapSnapshot, MalformedRecordsNameTheLine) {
  const std::string k = "K 525 525 319.5 239.5 40 1.2\n";
  const std::string f = "F 0 0 0 0 0 1 0 0 0\n";
  const std::string p = "P 1 0 0 3 0\n";
  EXPECT_NE(error_of(k + f + "X 1 2\n").find("Map.txt:3:"), std::string::npos) << error_of(k + f + "X 1 2\n");
  EXPECT_NE(error_of(k + "F 0 0 0 0 1\n").find("Map.txt:2: expected F id"), std::string::npos);
  EXPECT_NE(error_of(k + "F 0 0 0 0 0 2 0 0 0\n").find("unit quaternion"), std::string::npos);
  EXPECT_NE(error_of(k + f + p + "O 0 1 10 10 -1 0\n").find("Map.txt:4: point index 1 out of range"),
            std::string::npos);
  EXPECT_NE(error_of(k + f + p + "O 2 0 10 10 -1 0\n").find("keyframe index 2"), std::string::npos);
  EXPECT_NE(error_of(k + f + p + "O 0 0 10 10 -1 0 9\n").find("end of line"), std::string::npos);
  EXPECT_NE(error_of(f + p).find("no K record"), std::string::npos);
  // comments and blank lines are fine
  EXPECT_EQ(parse("# map\n\n" + k + f + p + "O 0 0 10 10 -1 0\n").measurements.size(), 1u);
}

}  // namespace
