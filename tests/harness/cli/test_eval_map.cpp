// pvbench eval-map end to end: a short pv_station drive recorded, mapped by
// pvbench slam and scored against the scene's true surface.  The bounds are
// sanity bounds (a map put in the wrong frame is metres off, not
// centimetres); the figures themselves are in docs/map_accuracy.md.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "pvb/common/text.hpp"
#include "run_pvbench.hpp"

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

}  // namespace

TEST(EvalMapCli, ScoresAShortPvStationMap) {
  const std::string dir = fresh("pv");
  const std::string scenario = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  auto r = pvb::test::run_pvbench("record --scenario " + scenario + " --frames 90 --out " + dir + "/seq");
  ASSERT_EQ(r.code, 0) << r.output;
  r = pvb::test::run_pvbench("slam --sequence " + dir + "/seq --settings " + dir + "/seq/camera.yaml --sync --out " +
                             dir + "/slam");
  ASSERT_EQ(r.code, 0) << r.output;
  r = pvb::test::run_pvbench("eval-map --map " + dir + "/slam/PointCloud.ply --scenario " + scenario +
                             " --trajectory " + dir + "/slam/CameraTrajectory.txt --gt " + dir +
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
