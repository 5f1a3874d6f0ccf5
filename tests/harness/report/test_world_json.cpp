// The world a run was made in (meta.json's and metrics.json's "world"):
// the ground appears only when it is uneven or its friction is the day's.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <string>

#include "pvb/report/plan_view.hpp"
#include "pvb/report/world_json.hpp"
#include "pvb/scenes/route.hpp"

using namespace pvb;

namespace {

YAML::Node world_of(const std::string& file) {
  return YAML::Load(run::world_json(scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + file)));
}

}  // namespace

TEST(WorldJson, TheGroundIsThereOnlyWhenItIsNotTheFlatDefault) {
  EXPECT_FALSE(world_of("pv_station.yaml")["ground"].IsDefined());
  const YAML::Node rough = world_of("rough_station.yaml")["ground"];
  ASSERT_TRUE(rough.IsMap());
  EXPECT_DOUBLE_EQ(rough["relief"]["amplitude_cm"].as<double>(), 2.0);
  EXPECT_DOUBLE_EQ(rough["relief"]["slope_percent"].as<double>(), 3.0);
  EXPECT_TRUE(rough["friction"].IsNull());
  const YAML::Node wet = world_of("days/rough_station_wet.yaml")["ground"];
  EXPECT_DOUBLE_EQ(wet["friction"].as<double>(), 0.4);
  EXPECT_DOUBLE_EQ(wet["relief"]["scale_m"].as<double>(), 1.0);
}

// The plan of a plant: its tables cover the share of the rows' area that
// the row footprint takes of the pitch, and the route is drawn.
TEST(PlanView, APlantsTablesCoverTheirShareOfTheRowsAndTheRouteIsDrawn) {
  const pvb::scenes::Scenario s = pvb::scenes::parse_scenario(
      "ground: {size_m: [400, 400], tiling: repeat}\n"
      "plant: {mount: single_axis, rows: 30, origin_m: [-50, -100]}\n"
      "route: {pattern: lawnmower, aisles: 3}\n",
      "plan.yaml");
  const cv::Mat img = pvb::run::make_plan_view(s, 3000);
  ASSERT_EQ(img.type(), CV_8UC3);
  const pvb::scenes::PvArray& a = s.pv_arrays[0];
  int tables = 0, route = 0;
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c) {
      const cv::Vec3b px = img.at<cv::Vec3b>(r, c);
      route += px == pvb::run::kPlanRouteRgb ? 1 : 0;
      tables += px == pvb::run::kPlanTableRgb ? 1 : 0;
    }
  EXPECT_GT(route, 500);
  // Table pixels over the block's area in pixels: the footprint over the pitch.
  const double block_m2 = pvb::scenes::row_length_m(a) * a.rows * a.row_pitch_m;
  // The plan spans the plant's extent and 10 m around it (azimuth 0: u is x, v is y).
  const double px_per_m = 3000.0 / std::max(s.plant->corners_m[1].x() - s.plant->corners_m[0].x() + 20,
                                            s.plant->corners_m[3].y() - s.plant->corners_m[0].y() + 20);
  const double table_m2 = tables / (px_per_m * px_per_m);
  const double tables_over_length = static_cast<double>(a.tables_per_row) * a.table_length_m() /
                                    pvb::scenes::row_length_m(a);
  EXPECT_NEAR(table_m2 / block_m2, s.plant->ground_coverage_ratio * tables_over_length, 0.03);
}
