// pvbench eval-map end to end: a short pv_station drive (the shared recording), mapped by
// pvbench slam (the shared run of its first 120 frames) and scored against the scene's true surface.  The bounds are
// sanity bounds (a map put in the wrong frame is metres off, not
// centimetres); the figures themselves are in docs/map_accuracy.md.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "pvb/common/text.hpp"
#include "run_pvbench.hpp"
#include "station_sequence.hpp"

namespace {

std::string fresh(const std::string& name) {
  const std::string d = ::testing::TempDir() + "pvb_eval_map_" + name + "_" + std::to_string(::getpid());
  std::filesystem::remove_all(d);
  return d;
}

double number_after(const std::string& text, const std::string& pattern) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(pattern + "([-0-9.eE+]+)"))) return -1;
  return std::stod(m[1]);
}

/// A copy of a dense map (x y z float, red green blue uchar per vertex)
/// moved by `dy_m` along the first camera's y axis (down).
void write_moved_map(const std::string& from, const std::string& to, float dy_m) {
  std::string ply = pvb::read_file(from);
  const std::size_t body = ply.find("end_header\n") + 11;
  for (std::size_t at = body; at + 15 <= ply.size(); at += 15) {
    float y = 0;
    std::memcpy(&y, ply.data() + at + 4, 4);
    y += dy_m;
    std::memcpy(ply.data() + at + 4, &y, 4);
  }
  std::filesystem::create_directories(to.substr(0, to.rfind('/')));
  pvb::write_file(to, ply);
}

/// Two sessions' maps in one frame: the same map twice is one surface;
/// the map and a copy 8 cm above it are the surface drawn twice, apart.
void expect_merged_maps_judged(const std::string& dir, const std::string& slam, const std::string& scenario) {
  const std::string map = slam + "/PointCloud.ply", inputs = " --scenario " + scenario + " --trajectory " + slam +
                                                              "/CameraTrajectory.txt --gt " + dir +
                                                              "/seq/groundtruth.txt";
  write_moved_map(map, dir + "/moved/PointCloud.ply", -0.08f);
  auto r = pvb::test::run_pvbench("eval-map --map " + map + " --map " + map + inputs + " --out " + dir + "/same");
  ASSERT_EQ(r.code, 0) << r.output;
  std::string js = pvb::read_file(dir + "/same/map_accuracy.json");
  EXPECT_NE(js.find("\"maps_merged\": 2"), std::string::npos) << js;
  std::string all = js.substr(js.find("\"all\""));
  EXPECT_EQ(number_after(all, "\"ghosting_between_maps\": "), 0.0) << all;
  EXPECT_GT(number_after(all, "\"ghosting_between_maps_judged\": "), 1000) << all;
  r = pvb::test::run_pvbench("eval-map --map " + map + " --map " + dir + "/moved/PointCloud.ply" + inputs +
                             " --out " + dir + "/apart");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("ghosting between the 2 maps: "), std::string::npos) << r.output;
  js = pvb::read_file(dir + "/apart/map_accuracy.json");
  all = js.substr(js.find("\"all\""));
  EXPECT_GT(number_after(all, "\"ghosting_between_maps\": "), 0.5) << all;
}

/// The shared recording of the station cut to its first `frames` frames as
/// far as eval-map reads it: `dir` gets its meta.json and the ground truth
/// of those frames.
void excerpt_of_station(const std::string& dir, std::size_t frames) {
  const std::string& seq = pvb::test::station_sequence();
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(seq + "/meta.json", dir + "/meta.json");
  std::istringstream in(pvb::read_file(seq + "/groundtruth.txt"));
  std::string gt;
  std::size_t poses = 0;
  for (std::string line; poses < frames && std::getline(in, line);) {
    gt += line + "\n";
    poses += !line.empty() && line[0] != '#';
  }
  pvb::write_file(dir + "/groundtruth.txt", gt);
}

}  // namespace

TEST(EvalMapCli, ScoresAShortPvStationMap) {
  const std::string dir = fresh("pv");
  const std::string scenario = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  const std::string& slam = pvb::test::station_slam_120();  // slam --sync, its dense map
  excerpt_of_station(dir + "/seq", 120);
  const auto r = pvb::test::run_pvbench("eval-map --map " + slam + "/PointCloud.ply --scenario " + scenario +
                                        " --trajectory " + slam + "/CameraTrajectory.txt --gt " + dir +
                                        "/seq/groundtruth.txt --out " + dir + "/eval");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string js = pvb::read_file(dir + "/eval/map_accuracy.json");
  EXPECT_NE(js.find("\"panel\""), std::string::npos) << js;
  EXPECT_NE(js.find("\"ground\""), std::string::npos) << js;
  const std::string all = js.substr(js.find("\"all\""));
  const double median = number_after(all, "\"median\": ");
  EXPECT_GT(median, 0.0) << all;
  EXPECT_LT(median, 0.10) << all;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(all, m, std::regex("\"completeness_at\": \\[([^\\]]*)\\]")));
  const std::string comp = m[1];
  EXPECT_GT(std::stod(comp.substr(comp.rfind(',') + 1)), 0.5) << comp;  // within 10 cm
  const std::string ply = pvb::read_file(dir + "/eval/map_errors.ply");
  EXPECT_NE(ply.find("property uchar class"), std::string::npos);
  EXPECT_NE(ply.find("property float error"), std::string::npos);
  expect_merged_maps_judged(dir, slam, scenario);
  std::filesystem::remove_all(dir);
}

TEST(EvalMapCli, AMissingMapIsOneErrorLine) {
  const std::string dir = fresh("missing");
  const auto r = pvb::test::run_pvbench("eval-map --map " + dir + "/nothing.ply --scenario " +
                                        std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml --trajectory " + dir +
                                        "/t.txt --gt " + dir + "/g.txt");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("error"), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

namespace {

/// A binary PLY of `n` vertices, each (x, y, z) as given, coloured grey.
void write_points_ply(const std::string& path, const std::vector<std::array<float, 3>>& points) {
  std::string body = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(points.size()) +
                     "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
                     "property uchar green\nproperty uchar blue\nend_header\n";
  for (const auto& p : points) {
    body.append(reinterpret_cast<const char*>(p.data()), 12);
    body.append(3, static_cast<char>(128));
  }
  pvb::write_file(path, body);
}

}  // namespace

// An empty map is never a perfect one, non-finite vertices are left out and
// counted, a map is never scored against another scenario's world, and the
// output folder is checked before the work.
TEST(EvalMapCli, BadMapsAndMismatchedInputsAreRefused) {
  const std::string dir = fresh("bad");
  const std::string station = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  excerpt_of_station(dir + "/seq", 30);
  pvb::test::RunResult r;
  const std::string inputs = " --trajectory " + dir + "/seq/groundtruth.txt --gt " + dir + "/seq/groundtruth.txt";
  const auto eval_map = [&](const std::string& map, const std::string& scenario, const std::string& extra) {
    return pvb::test::run_pvbench("eval-map --map " + map + " --scenario " + scenario + inputs + " " + extra);
  };
  const auto one_line = [](const pvb::test::RunResult& res) {
    return std::count(res.output.begin(), res.output.end(), '\n') == 1;
  };
  write_points_ply(dir + "/empty.ply", {});
  r = eval_map(dir + "/empty.ply", station, "--out " + dir + "/e1");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(one_line(r)) << r.output;
  EXPECT_NE(r.output.find(dir + "/empty.ply: the map has no points to score"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/e1/map_accuracy.json"));

  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  write_points_ply(dir + "/nan.ply", {{nan, 0, 0}, {0, inf, 0}});
  r = eval_map(dir + "/nan.ply", station, "");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("the map has no points to score (2 vertices with a NaN or infinite coordinate)"),
            std::string::npos)
      << r.output;

  write_points_ply(dir + "/some.ply", {{0.0f, 0.0f, 1.0f}, {nan, 0, 0}, {0.2f, 0.1f, 2.0f}});
  r = eval_map(dir + "/some.ply", station, "--out " + dir + "/e2");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("1 vertices with a NaN or infinite coordinate left out"), std::string::npos) << r.output;
  const std::string js = pvb::read_file(dir + "/e2/map_accuracy.json");
  EXPECT_NE(js.find("\"non_finite_vertices_dropped\": 1"), std::string::npos) << js;
  for (const char* bad : {"inf", "nan", "NaN", "Infinity"}) EXPECT_EQ(js.find(bad), std::string::npos) << bad;
  // Two points cannot cover every class: a class without map points has no
  // accuracy (null, with the reason), never a perfect 0 mm.
  EXPECT_NE(js.find("\"accuracy_m\": null"), std::string::npos) << js;
  EXPECT_NE(js.find("\"null_reason\": \"no map points in this subset\""), std::string::npos) << js;

  // The recording's meta.json names pv_station and seed 7.
  r = eval_map(dir + "/some.ply", std::string(PVB_SOURCE_DIR) + "/scenes/lawnmower.yaml", "");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(one_line(r)) << r.output;
  EXPECT_NE(r.output.find(dir + "/seq/meta.json: scenario: expected a run of lawnmower"), std::string::npos)
      << r.output;
  r = eval_map(dir + "/some.ply", station, "--seed 3");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("seq/meta.json: seed: expected 3"), std::string::npos) << r.output;

  pvb::write_file(dir + "/a_file", "x");
  r = eval_map(dir + "/some.ply", station, "--out " + dir + "/a_file");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(one_line(r)) << r.output;  // refused before the surface is sampled
  EXPECT_NE(r.output.find(dir + "/a_file: is not a folder"), std::string::npos) << r.output;
  std::filesystem::remove_all(dir);
}
