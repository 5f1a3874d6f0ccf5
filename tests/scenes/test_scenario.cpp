// Scenario files: the shipped ones load, defaults, keys, types, ranges and
// sections read or refused in one line (kidnaps, covers and the blind
// bounds in test_scenario_events.cpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/scenes/scenario.hpp"
#include "scenario_errors.hpp"

using namespace pvb::scenes;

using pvb::test::error_of;
using pvb::test::kMinimal;

TEST(Scenario, ShippedScenariosLoad) {
  for (const char* name : {"pv_station", "along_row", "lawnmower", "loop", "wall_pass", "dusty_panels",
                           "low_sun_glare", "high_noise", "fast_turns", "tracking_failure", "kidnapped",
                           "kidnapped_short", "aliasing", "lawnmower_return", "blind"}) {
    const Scenario s = load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + name + ".yaml");
    EXPECT_EQ(s.name, name);
    EXPECT_GE(s.duration_s, 20.0) << name;
    EXPECT_FALSE(s.pv_arrays.empty()) << name;
  }
}

TEST(Scenario, DefaultsAreKinectLike) {
  const Scenario s = parse_scenario(kMinimal, "min.yaml");
  EXPECT_EQ(s.camera.width, 640);
  EXPECT_EQ(s.camera.height, 480);
  EXPECT_DOUBLE_EQ(s.camera.fx, 525.0);
  EXPECT_DOUBLE_EQ(s.camera.fps, 30.0);
  EXPECT_DOUBLE_EQ(s.camera.depth_range_m.x(), 0.5);
  EXPECT_DOUBLE_EQ(s.camera.depth_range_m.y(), 4.5);
  EXPECT_DOUBLE_EQ(s.camera.cx(), 319.5);
  EXPECT_EQ(frame_count(s), 601);
  EXPECT_EQ(frame_count(s, 120), 120);
}

TEST(Scenario, UnknownKeyIsNamedWithFileAndLine) {
  const std::string msg = error_of(std::string(kMinimal) + "camera:\n  widht: 320\n");
  EXPECT_NE(msg.find("bad.yaml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("camera.widht"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown key"), std::string::npos) << msg;
}

// A list or a map used as a key (found by fuzz_scenario) is a ConfigError
// naming the line, not a yaml-cpp conversion error escaping the reader.
TEST(Scenario, NonScalarKeyIsNamedWithFileAndLine) {
  const std::string msg = error_of(std::string(kMinimal) + "ground: {type: gravel, [1, 2]: 3}\n");
  EXPECT_NE(msg.find("bad.yaml:2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("ground.?: expected a key name, got a list or a map as a key"), std::string::npos) << msg;
  const std::string top = error_of(std::string(kMinimal) + "? [a, b]\n: 1\n");
  EXPECT_NE(top.find("expected a key name"), std::string::npos) << top;
}

TEST(Scenario, WrongTypeIsNamed) {
  const std::string msg = error_of(std::string(kMinimal) + "light:\n  shadows: maybe\n");
  EXPECT_NE(msg.find("light.shadows: expected true or false, got maybe"), std::string::npos) << msg;
  const std::string msg3 = error_of(std::string(kMinimal) + "light:\n  box_quads: 0\n");
  EXPECT_NE(msg3.find("light.box_quads"), std::string::npos) << msg3;
  const std::string msg2 = error_of(std::string(kMinimal) + "duration_s: long\n");
  EXPECT_NE(msg2.find("duration_s: expected a number, got long"), std::string::npos) << msg2;
}

TEST(Scenario, OutOfRangeIsNamed) {
  const std::string msg = error_of(std::string(kMinimal) + "pv_arrays:\n  - tilt_deg: 75\n");
  EXPECT_NE(msg.find("pv_arrays[0].tilt_deg: expected a value in [0, 60], got 75"), std::string::npos) << msg;
  const std::string cells = error_of(std::string(kMinimal) + "pv_arrays:\n  - cells: 96\n");
  EXPECT_NE(cells.find("pv_arrays[0].cells: expected one of 60, 72, 144, got 96"), std::string::npos) << cells;
}

TEST(Scenario, BadEnumListsChoices) {
  const std::string msg = error_of(std::string(kMinimal) + "ground: {type: sand}\n");
  EXPECT_NE(msg.find("ground.type: expected one of soil, gravel, got sand"), std::string::npos) << msg;
  const std::string tiling = error_of(std::string(kMinimal) + "ground: {tiling: random}\n");
  EXPECT_NE(tiling.find("ground.tiling: expected one of repeat, varied, got random"), std::string::npos) << tiling;
}

TEST(Scenario, CrossFieldChecks) {
  EXPECT_NE(error_of("seed: 1\n").find("route.waypoints_m"), std::string::npos);
  EXPECT_NE(error_of("route: {pattern: loop}\n").find("no pv_arrays"), std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "camera: {fx: 500, fy: 525}\n").find("fx equal to fy"), std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "camera: {depth_range_m: [4, 1]}\n").find("min <= max"),
            std::string::npos);
  EXPECT_NE(error_of("seed: -3\n" + std::string(kMinimal)).find("seed: expected a non-negative integer"),
            std::string::npos);
}

TEST(Scenario, SyntaxErrorNamesLine) {
  const std::string msg = error_of("route: {waypoints_m: [[0, 0], [5, 0]]\nseed: [\n");
  EXPECT_NE(msg.find("bad.yaml:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("valid YAML"), std::string::npos) << msg;
}

TEST(Scenario, ANulByteIsNamedNotTakenForAnEscape) {
  // A raw NUL in the text (yaml-cpp called it "unknown escape character").
  std::string raw = "name: ab";
  raw += '\0';
  raw += "cd\n" + std::string(kMinimal);
  const std::string msg = error_of(raw);
  EXPECT_NE(
      msg.find(
          "bad.yaml:1: (file): expected YAML text (a NUL byte is never in one), got a NUL byte at byte 8"),
      std::string::npos)
      << msg;
  // A quoted escape that makes one (it would cut the scene's XML short).
  const std::string quoted = error_of("name: \"ab\\0cd\"\n" + std::string(kMinimal));
  EXPECT_NE(quoted.find("bad.yaml:1: name: expected a string without control characters, got ab\\x00cd"),
            std::string::npos)
      << quoted;
  EXPECT_EQ(parse_scenario("description: |\n  two\n  lines\n" + std::string(kMinimal), "ok.yaml").description,
            "two\nlines\n");
}

TEST(Scenario, MissingFileIsAnIoError) { EXPECT_THROW(load_scenario("/nonexistent/x.yaml"), pvb::IoError); }

TEST(Scenario, ExpectSectionIsReadAndOptional) {
  const Scenario none = parse_scenario(kMinimal, "min.yaml");
  EXPECT_FALSE(none.expect.any());
  EXPECT_EQ(none.expect.ci_frames, 0);

  const Scenario s = parse_scenario(std::string(kMinimal) +
                                        "expect:\n"
                                        "  ate_rmse_m_max: 0.01\n"
                                        "  rpe_trans_rmse_m_max: 0.005\n"
                                        "  lost_frames_max: 0\n"
                                        "  keyframes_max: 400\n"
                                        "  ci_frames: 240\n"
                                        "  sweep: {pe_not_significantly_worse: true, min_seeds: 12}\n",
                                    "e.yaml");
  EXPECT_TRUE(s.expect.any());
  ASSERT_TRUE(s.expect.ate_rmse_m_max);
  EXPECT_DOUBLE_EQ(*s.expect.ate_rmse_m_max, 0.01);
  ASSERT_TRUE(s.expect.rpe_trans_rmse_m_max);
  EXPECT_DOUBLE_EQ(*s.expect.rpe_trans_rmse_m_max, 0.005);
  ASSERT_TRUE(s.expect.lost_frames_max);
  EXPECT_EQ(*s.expect.lost_frames_max, 0);
  ASSERT_TRUE(s.expect.keyframes_max);
  EXPECT_EQ(*s.expect.keyframes_max, 400);
  EXPECT_FALSE(none.expect.keyframes_max);
  EXPECT_FALSE(s.expect.tracking_loss_expected);
  EXPECT_EQ(s.expect.ci_frames, 240);
  EXPECT_TRUE(s.expect.sweep.pe_not_significantly_worse);
  EXPECT_EQ(s.expect.sweep.min_seeds, 12);
  EXPECT_EQ(none.expect.sweep.min_seeds, 10);

  // A sweep expectation alone sets no bound on a single run.
  const Scenario only_sweep = parse_scenario(
      std::string(kMinimal) + "expect:\n  sweep: {pe_not_significantly_worse: true}\n", "w.yaml");
  EXPECT_TRUE(only_sweep.expect.any());
  EXPECT_FALSE(only_sweep.expect.any_run_bound());
}

TEST(Scenario, ExpectSectionIsStrict) {
  const std::string base = std::string(kMinimal) + "expect:\n";
  EXPECT_NE(error_of(base + "  ate_rmse_max: 0.01\n").find("bad.yaml:3: expect.ate_rmse_max: expected a known key"),
            std::string::npos)
      << error_of(base + "  ate_rmse_max: 0.01\n");
  EXPECT_NE(error_of(base + "  ate_rmse_m_max: 1cm\n").find("expect.ate_rmse_m_max: expected a number, got 1cm"),
            std::string::npos);
  EXPECT_NE(error_of(base + "  ate_rmse_m_max: -0.01\n").find("expect.ate_rmse_m_max: expected a value in"),
            std::string::npos);
  EXPECT_NE(error_of(base + "  lost_frames_max: 2.5\n").find("expect.lost_frames_max: expected an integer, got 2.5"),
            std::string::npos);
  EXPECT_NE(error_of(base + "  sweep: {pe_not_significantly_worse: maybe}\n")
                .find("expect.sweep.pe_not_significantly_worse: expected true or false, got maybe"),
            std::string::npos);
  EXPECT_NE(
      error_of(base + "  sweep: {min_seeds: 5}\n").find("expect.sweep.min_seeds: expected a value in [10, "),
      std::string::npos)
      << error_of(base + "  sweep: {min_seeds: 5}\n");
  // The single-run comparison is gone; an old file is told where it went.
  const std::string old_key = error_of(base + "  pe_not_worse_than_baseline: true\n");
  EXPECT_NE(old_key.find("bad.yaml:3: expect.pe_not_worse_than_baseline: expected "
                         "expect.sweep.pe_not_significantly_worse instead"),
            std::string::npos)
      << old_key;
  EXPECT_NE(error_of(base + "  ci_frames: 1\n").find("expect.ci_frames"), std::string::npos);
  EXPECT_NE(error_of(base + "  tracking_loss_expected: true\n  lost_frames_max: 0\n").find("expect.lost_frames_max"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "expect: [1, 2]\n").find("expect: expected a mapping of keys"),
            std::string::npos);
}

TEST(Scenario, SlamSectionIsReadAndOptional) {
  const Scenario none = parse_scenario(kMinimal, "min.yaml");
  EXPECT_EQ(none.slam.orb_features, 1000);
  EXPECT_FALSE(none.slam.keyframe_min_tracked_close);
  EXPECT_FALSE(none.slam.keyframe_ref_overlap);

  const Scenario s = parse_scenario(
      std::string(kMinimal) +
          "slam: {orb_features: 2000, keyframe_min_tracked_close: 400, keyframe_ref_overlap: 0.4}\n",
      "s.yaml");
  EXPECT_EQ(s.slam.orb_features, 2000);
  ASSERT_TRUE(s.slam.keyframe_min_tracked_close);
  EXPECT_EQ(*s.slam.keyframe_min_tracked_close, 400);
  ASSERT_TRUE(s.slam.keyframe_ref_overlap);
  EXPECT_DOUBLE_EQ(*s.slam.keyframe_ref_overlap, 0.4);

  const std::string base = std::string(kMinimal) + "slam:\n";
  EXPECT_NE(error_of(base + "  orb_features: 50\n").find("bad.yaml:3: slam.orb_features: expected a value in"),
            std::string::npos)
      << error_of(base + "  orb_features: 50\n");
  EXPECT_NE(error_of(base + "  keyframe_min_tracked_close: 0\n").find("slam.keyframe_min_tracked_close"),
            std::string::npos);
  EXPECT_NE(error_of(base + "  keyframe_ref_overlap: 1.5\n").find("slam.keyframe_ref_overlap"),
            std::string::npos);
  EXPECT_NE(error_of(base + "  nFeatures: 2000\n").find("slam.nFeatures: expected a known key"), std::string::npos);
  EXPECT_FALSE(none.slam.sensors);
  const Scenario fused = parse_scenario(std::string(kMinimal) + "slam: {sensors: camera+imu+wheels}\n", "f.yaml");
  ASSERT_TRUE(fused.slam.sensors);
  EXPECT_EQ(*fused.slam.sensors, pvb::sensor::SensorSetup::kCameraImuWheels);
  const std::string bad_setup = error_of(base + "  sensors: camera+gps\n");
  EXPECT_NE(bad_setup.find("slam.sensors"), std::string::npos) << bad_setup;
  EXPECT_NE(bad_setup.find("camera+imu+wheels"), std::string::npos) << bad_setup;
}

TEST(Scenario, WallFinish) {
  const std::string wall = "walls:\n  - {start_m: [0, 0], end_m: [4, 0]}\n  - {start_m: [0, 2], end_m: [4, 2], finish: plaster}\n";
  const Scenario s = parse_scenario(std::string(kMinimal) + wall, "w.yaml");
  ASSERT_EQ(s.walls.size(), 2u);
  EXPECT_EQ(s.walls[0].finish, WallFinish::kBrick);
  EXPECT_EQ(s.walls[1].finish, WallFinish::kPlaster);
  EXPECT_NE(error_of(std::string(kMinimal) + "walls:\n  - {finish: glass}\n").find("walls[0].finish: expected one of brick, plaster, got glass"),
            std::string::npos);
}

// The suite: every shipped scenario states its bounds, and the fast CI
// subset (expect.ci_frames > 0) stays at five scenarios at most: the
// default station, a kidnap, a tracking failure, a plant's U-turn and a
// blind stretch among look-alike rows.
TEST(Scenario, EveryShippedScenarioHasBoundsAndTheCiSubsetIsSmall) {
  int in_ci = 0, files = 0;
  for (const auto& e : std::filesystem::directory_iterator(std::string(PVB_SOURCE_DIR) + "/scenes")) {
    if (e.path().extension() != ".yaml") continue;
    ++files;
    const Scenario s = load_scenario(e.path().string());
    EXPECT_TRUE(s.expect.any()) << e.path();
    EXPECT_EQ(s.name, e.path().stem().string()) << "the CTest names follow the file names";
    if (s.expect.ci_frames > 0) ++in_ci;
  }
  EXPECT_GE(files, 10);
  EXPECT_GE(in_ci, 1);
  EXPECT_LE(in_ci, 5);
}

// A scene larger than MuJoCo compiles in seconds (20 000 geoms) is refused
// with one line naming the key, the limit and the largest array, even when
// every key is within its own range: 50 x 50 tables of 240 panels did not
// compile in 5 minutes.
TEST(Scenario, SceneLargerThanTheRendererDrawsIsRefused) {
  const std::string big = std::string(kMinimal) + "pv_arrays:\n  - {rows: 50, tables_per_row: 50}\n";
  const std::string e = error_of(big);
  EXPECT_EQ(e.rfind("bad.yaml:2: pv_arrays: expected at most 20000 geoms in the scene", 0), 0u) << e;
  // 2500 tables x (16 panels + backsheet + 2 rails + 4 posts)
  EXPECT_NE(e.find("got 57500 (pv_arrays[0]: 50 rows x 50 tables x 23 geoms)"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;

  const std::string huge =
      std::string(kMinimal) +
      "pv_arrays:\n  - {rows: 50, tables_per_row: 50, panels_per_table: 60, panel_lines: 4, "
      "row_pitch_m: 9}\n";
  EXPECT_NE(error_of(huge).find("got 617500 (pv_arrays[0]: 50 rows x 50 tables x 247 geoms)"),
            std::string::npos)
      << error_of(huge);
}

// The limit counts every array, wall, shrub and tree: a scene of exactly
// 20 000 geoms loads, one more shrub (two geoms) does not.
TEST(Scenario, SceneSizeLimitCountsEveryPart) {
  const std::string arrays =
      "pv_arrays:\n"
      "  - {rows: 50, tables_per_row: 10, panels_per_table: 30, panel_lines: 1}\n"  // 500 x 37 = 18500
      "  - {origin_m: [0, 400], rows: 2, tables_per_row: 10, panels_per_table: 30, panel_lines: 1,"
      " posts: false, rails: false}\n";  // 20 x 31 = 620
  const std::string walls =
      "walls:\n  - {start_m: [0, -5], end_m: [5, -5]}\n  - {start_m: [0, -8], end_m: [5, -8]}\n";
  const auto with_shrubs = [&](int n) {
    return std::string(kMinimal) + arrays + walls + "vegetation: {shrubs: " + std::to_string(n) + "}\n";
  };
  EXPECT_EQ(error_of(with_shrubs(439)), "");  // 18500 + 620 + 2 + 878 = 20000
  const std::string e = error_of(with_shrubs(440));
  EXPECT_NE(e.find("got 20002 (pv_arrays[0]: 50 rows x 10 tables x 37 geoms)"), std::string::npos) << e;
}

TEST(Scenario, LoopLapsAreReadAndRefusedOnOtherPatterns) {
  const std::string arrays = "pv_arrays:\n  - {rows: 2, tables_per_row: 2, panels_per_table: 4}\n";
  EXPECT_EQ(parse_scenario(std::string(kMinimal) + arrays, "a.yaml").route.laps, 1);
  EXPECT_EQ(parse_scenario(arrays + "route: {pattern: loop, laps: 5}\n", "l.yaml").route.laps, 5);
  std::string e = error_of(arrays + "route:\n  pattern: lawnmower\n  laps: 2\n");
  EXPECT_NE(e.find("bad.yaml:5"), std::string::npos) << e;
  EXPECT_NE(e.find("route.laps: expected no laps unless route.pattern is loop or roads (it would be ignored), got 2"),
            std::string::npos)
      << e;
  e = error_of(arrays + "route: {pattern: loop, laps: 0}\n");
  EXPECT_NE(e.find("route.laps"), std::string::npos) << e;
}

TEST(Scenario, IdenticalTablesAndLawnmowerReturnAreRead) {
  const std::string arrays = "pv_arrays:\n  - {rows: 2, tables_per_row: 2, panels_per_table: 4}\n";
  const Scenario none = parse_scenario(std::string(kMinimal) + arrays, "a.yaml");
  EXPECT_FALSE(none.pv_arrays[0].identical_tables);
  EXPECT_FALSE(none.route.return_to_start);
  const Scenario s = parse_scenario(
      "pv_arrays:\n  - {rows: 2, tables_per_row: 2, panels_per_table: 4, identical_tables: true}\n"
      "route: {pattern: lawnmower, aisles: 2, return_to_start: true, return_overlap_m: 3}\n",
      "r.yaml");
  EXPECT_TRUE(s.pv_arrays[0].identical_tables);
  EXPECT_TRUE(s.route.return_to_start);
  EXPECT_DOUBLE_EQ(s.route.return_overlap_m, 3.0);

  std::string e = error_of("route:\n  waypoints_m: [[0, 0], [5, 0]]\n  return_to_start: true\n");
  EXPECT_NE(e.find("bad.yaml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("route.return_to_start: expected false unless route.pattern is lawnmower, got true"),
            std::string::npos)
      << e;
  // 2 tables of 4 panels of 0.99 m with 2 cm gaps, 1 m apart, 2 m run-out at each end: an aisle of 13.04 m
  e = error_of(arrays + "route: {pattern: lawnmower, return_to_start: true, return_overlap_m: 14}\n");
  EXPECT_NE(e.find("route.return_overlap_m: expected at most the first aisle's length, 13.04 m, got 14"),
            std::string::npos)
      << e;
  e = error_of(arrays + "route: {pattern: lawnmower, return_to_start: true, return_overlap_m: 0.1}\n");
  EXPECT_NE(e.find("route.return_overlap_m: expected a value in [0.5, 100], got 0.1"), std::string::npos)
      << e;
}

// yaml-cpp finds the first of two equal keys and never reads the second: a
// key given twice is an error naming both lines, at any depth.
TEST(Scenario, DuplicateKeysAreRefusedWithBothLines) {
  std::string e = error_of(std::string(kMinimal) + "seed: 43\nseed: -1\n");
  EXPECT_NE(e.find("bad.yaml:3: seed: expected each key once in its section (first given at line 2), got a second seed"),
            std::string::npos)
      << e;
  e = error_of(std::string(kMinimal) + "duration_s: 20\nkidnap: {at_s: 10, to_route_s: 3}\nkidnap: {at_s: 12, to_route_s: 3}\n");
  EXPECT_NE(e.find("bad.yaml:4: kidnap: expected each key once in its section (first given at line 3)"),
            std::string::npos)
      << e;
  e = error_of(std::string(kMinimal) + "camera:\n  width: 320\n  fps: 15\n  width: 640\n");
  EXPECT_NE(e.find("bad.yaml:5: camera.width: expected each key once in its section (first given at line 3)"),
            std::string::npos)
      << e;
  e = error_of("pv_arrays:\n  - {rows: 2, rows: 3}\n" + std::string(kMinimal));
  EXPECT_NE(e.find("pv_arrays[0].rows: expected each key once"), std::string::npos) << e;
  // The same key in two sections is not a duplicate.
  EXPECT_EQ(error_of(std::string(kMinimal) + "camera: {fps: 15}\nlight: {ambient: 0.3}\nrobot: {track_m: 0.4}\n"), "");
}

// Three levels down, the error names the full key and the line of the value.
TEST(Scenario, NestedMistakesNameTheFullKeyAndItsLine) {
  const std::string cam = std::string(kMinimal) + "camera:\n  fps: 15\n  depth_noise:\n";
  std::string e = error_of(cam + "    axial_scale: 0.5\n    axial_scale: 2\n");
  EXPECT_NE(e.find("bad.yaml:6: camera.depth_noise.axial_scale: expected each key once in its section (first given at "
                   "line 5), got a second axial_scale"),
            std::string::npos)
      << e;
  e = error_of(cam + "    axial_scale: [2]\n");
  EXPECT_NE(e.find("bad.yaml:5: camera.depth_noise.axial_scale: expected a number, got a non-scalar"), std::string::npos)
      << e;
  e = error_of(cam + "    axial_scale: 2\n    axial_scael: 2\n");
  EXPECT_NE(e.find("bad.yaml:6: camera.depth_noise.axial_scael: expected a known key ("), std::string::npos) << e;
  EXPECT_NE(e.find("got unknown key"), std::string::npos) << e;
}

TEST(Scenario, SunlightOnTheDepthPatternIsOnUnlessTurnedOff) {
  EXPECT_TRUE(parse_scenario(kMinimal, "min.yaml").camera.depth_noise.sunlight.on);
  EXPECT_FALSE(parse_scenario(std::string(kMinimal) + "camera:\n  depth_noise: {sunlight: off}\n", "off.yaml")
                   .camera.depth_noise.sunlight.on);
  const Scenario s = parse_scenario(std::string(kMinimal) +
                                        "camera:\n  depth_noise: {sunlight: on, sunlight_filter_nm: 20, "
                                        "sunlight_min_contrast: 0.01}\n",
                                    "sun.yaml");
  EXPECT_TRUE(s.camera.depth_noise.sunlight.on);
  EXPECT_DOUBLE_EQ(s.camera.depth_noise.sunlight.filter_width_nm, 20.0);
  EXPECT_DOUBLE_EQ(s.camera.depth_noise.sunlight.min_contrast, 0.01);
  const std::string e = error_of(std::string(kMinimal) + "camera:\n  depth_noise: {sunlight: bright}\n");
  EXPECT_NE(e.find("bad.yaml:3: camera.depth_noise.sunlight:"), std::string::npos) << e;
}

TEST(Scenario, TheD435ModelBringsItsColourCameraAndStereoKeys) {
  const Scenario kinect = parse_scenario(kMinimal, "min.yaml");
  EXPECT_EQ(kinect.camera.model, CameraKind::kKinect);
  EXPECT_DOUBLE_EQ(kinect.camera.depth_baseline_m(), 0.075);
  const Scenario d = parse_scenario(std::string(kMinimal) +
                                        "camera:\n  model: d435\n  stereo: {disparities: 96, block_px: 5, "
                                        "projector_power_w: 0}\n",
                                    "d435.yaml");
  EXPECT_EQ(d.camera.model, CameraKind::kD435);
  EXPECT_DOUBLE_EQ(d.camera.fx, 615.0) << "the D435's colour camera unless given";
  EXPECT_DOUBLE_EQ(d.camera.depth_baseline_m(), 0.050);
  EXPECT_EQ(d.camera.stereo.disparities, 96);
  EXPECT_EQ(d.camera.stereo.block_px, 5);
  EXPECT_DOUBLE_EQ(d.camera.stereo.projector_power_w, 0.0);
  const Scenario given = parse_scenario(std::string(kMinimal) + "camera:\n  model: d435\n  fy: 500\n", "d.yaml");
  EXPECT_DOUBLE_EQ(given.camera.fx, 500.0);
  std::string e = error_of(std::string(kMinimal) + "camera:\n  model: d435\n  stereo: {disparities: 100}\n");
  EXPECT_NE(e.find("bad.yaml:4: camera.stereo.disparities: expected a multiple of 16"), std::string::npos) << e;
  e = error_of(std::string(kMinimal) + "camera:\n  stereo: {block_px: 5}\n");
  EXPECT_NE(e.find("camera.stereo: expected no stereo: section unless model is d435"), std::string::npos) << e;
  e = error_of(std::string(kMinimal) + "camera:\n  model: zed\n");
  EXPECT_NE(e.find("bad.yaml:3: camera.model:"), std::string::npos) << e;
}

TEST(Scenario, ReturnOverlapOnlyWithReturnToStart) {
  const std::string arrays = "pv_arrays:\n  - {rows: 2, tables_per_row: 2, panels_per_table: 4}\n";
  std::string e = error_of(arrays + "route:\n  pattern: lawnmower\n  return_overlap_m: 40\n");
  EXPECT_NE(e.find("bad.yaml:5: route.return_overlap_m: expected no return_overlap_m unless route.return_to_start "
                   "is true (it would be ignored), got 40"),
            std::string::npos)
      << e;
  // Too long for the aisle: the error names the line it was written on.
  e = error_of(arrays + "route:\n  pattern: lawnmower\n  return_to_start: true\n  return_overlap_m: 14\n");
  EXPECT_NE(e.find("bad.yaml:6: route.return_overlap_m: expected at most the first aisle's length"), std::string::npos)
      << e;
}

TEST(Scenario, TooDeepNestingSaysSo) {
  const std::string e = error_of(std::string(kMinimal) + "ground: " + std::string(2000, '[') + std::string(2000, ']') + "\n");
  EXPECT_NE(e.find("(syntax): expected YAML nested at most a few hundred levels deep, got nesting too deep"),
            std::string::npos)
      << e;
}

// A huge file is refused before it is parsed (an 11 MB file of 200 000
// walls took 20 s and 1.1 GB before its geom count was checked).
TEST(Scenario, HugeFilesAndWallListsAreRefusedBeforeTheyAreBuilt) {
  std::string walls = "walls:\n";
  for (int i = 0; i < 4000; ++i) walls += "  - {start_m: [0, 0], end_m: [1, 0]}\n";
  std::string e = error_of(std::string(kMinimal) + walls);
  EXPECT_NE(e.find("bad.yaml:2: walls: expected at most 3800 walls in a file, got 4000"),
            std::string::npos)
      << e;
  std::string huge = std::string(kMinimal) + "description: \"" + std::string(2 * 1024 * 1024, 'x') + "\"\n";
  e = error_of(huge);
  EXPECT_NE(e.find("bad.yaml: (file): expected a scenario file of at most 1024 KiB"), std::string::npos) << e;
}
