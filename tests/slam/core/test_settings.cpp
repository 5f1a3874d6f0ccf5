// The settings reader on ORB-SLAM2's own TUM1.yaml and on broken copies.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <regex>
#include <utility>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/slam/core/settings.hpp"
#include "pvb/slam/core/system.hpp"
#include "shared_data.hpp"

namespace pvb::slam {
namespace {

/// ORB-SLAM2's TUM1.yaml in ../shared/data.
std::string tum1() { return pvb::test::shared_path("data/tum/TUM1.yaml"); }
const std::string kTum3 = std::string(PVB_SOURCE_DIR) + "/configs/tum/TUM3.yaml";

std::string temp_copy(const std::string& name, const std::string& content) {
  const std::string path =
      ::testing::TempDir() + "pvb_settings_" + name + "_" + std::to_string(::getpid()) + ".yaml";
  write_file(path, content);
  return path;
}

TEST(Settings, ReadsTum1Unchanged) {
  const Settings s = read_settings(tum1());
  EXPECT_DOUBLE_EQ(s.K.fx, 517.306408);
  EXPECT_DOUBLE_EQ(s.K.fy, 516.469215);
  EXPECT_DOUBLE_EQ(s.K.cx, 318.643040);
  EXPECT_DOUBLE_EQ(s.K.cy, 255.313989);
  EXPECT_DOUBLE_EQ(s.k1, 0.262383);
  EXPECT_DOUBLE_EQ(s.k3, 1.163314);
  EXPECT_EQ(s.K.width, 640);
  EXPECT_EQ(s.K.height, 480);
  EXPECT_DOUBLE_EQ(s.bf, 40.0);
  EXPECT_TRUE(s.rgb_order);
  EXPECT_DOUBLE_EQ(s.depth_map_factor, 5000.0);
  EXPECT_NEAR(s.th_depth_m(), 40.0 * 40.0 / 517.306408, 1e-12);
  EXPECT_EQ(s.orb.num_features, 1000);
  EXPECT_EQ(s.orb.num_levels, 8);
  EXPECT_EQ(s.orb.ini_fast_threshold, 20);
  EXPECT_EQ(s.orb.min_fast_threshold, 7);
  // No PEMatch section: the paper's SLAM search values (sec. 5.2.2) with the
  // filter chosen against ground truth (Sampson distance, 2 px, refinement).
  EXPECT_TRUE(s.pe_match.enabled);
  EXPECT_EQ(s.pe_match.num_fitness_samples, 50);
  EXPECT_EQ(s.pe_match.stall_iterations, 6);
  EXPECT_DOUBLE_EQ(s.pe_match.threshold_px, 2.0);
  EXPECT_TRUE(s.pe_match.sampson);
  EXPECT_TRUE(s.pe_match.refine);
  EXPECT_FALSE(s.pe_match.skip_low_parallax);
  // Viewer.* keys are ORB-SLAM2's own: no warnings.
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
}

// The freiburg3 file we ship is a complete settings file: TUM's fr3
// calibration, no distortion (the dataset's fr3 images are undistorted),
// and no key the reader does not know.
TEST(Settings, ShippedTum3IsCompleteAndUndistorted) {
  const Settings s = read_settings(kTum3);
  EXPECT_DOUBLE_EQ(s.K.fx, 535.4);
  EXPECT_DOUBLE_EQ(s.K.fy, 539.2);
  EXPECT_DOUBLE_EQ(s.K.cx, 320.1);
  EXPECT_DOUBLE_EQ(s.K.cy, 247.6);
  EXPECT_FALSE(s.has_distortion());
  EXPECT_DOUBLE_EQ(s.depth_map_factor, 5000.0);
  EXPECT_NEAR(s.th_depth_m(), 40.0 * 40.0 / 535.4, 1e-12);
  EXPECT_EQ(s.orb.num_features, 1000);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
}

TEST(Settings, ReadsPeMatchSection) {
  const std::string path =
      temp_copy("pe", read_file(tum1()) +
                          "\nPEMatch.enabled: 0\nPEMatch.population: 30\nPEMatch.j: 80\n"
                          "PEMatch.stallIterations: 9\nPEMatch.threshold: 2.5\nPEMatch.refine: 0\n"
                          "PEMatch.sampson: 0\nPEMatch.skipLowParallax: 1\n");
  const Settings s = read_settings(path);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  EXPECT_TRUE(s.pe_match.skip_low_parallax);
  EXPECT_FALSE(s.pe_match.enabled);
  EXPECT_EQ(s.pe_match.population, 30);
  EXPECT_EQ(s.pe_match.num_fitness_samples, 80);
  EXPECT_EQ(s.pe_match.stall_iterations, 9);
  EXPECT_DOUBLE_EQ(s.pe_match.threshold_px, 2.5);
  EXPECT_FALSE(s.pe_match.refine);  // the paper's filter: eq. 8, no refinement
  EXPECT_FALSE(s.pe_match.sampson);
}

TEST(Settings, ReadsKeyFrameSection) {
  const Settings d = read_settings(tum1());  // absent: the documented defaults
  EXPECT_EQ(d.keyframe.min_tracked_close, 200);
  EXPECT_EQ(d.keyframe.min_untracked_close, 70);
  EXPECT_EQ(d.keyframe.ref_overlap, 0.0);  // ORB-SLAM2's 75 % rule
  const Settings s = read_settings(temp_copy("kf", read_file(tum1()) + "\nKeyFrame.minTrackedClose: 100\n"
                                                                       "KeyFrame.minUntrackedClose: 50\n"
                                                                       "KeyFrame.refOverlap: 0.4\n"));
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.keyframe.min_tracked_close, 100);  // ORB-SLAM2's value
  EXPECT_EQ(s.keyframe.min_untracked_close, 50);
  EXPECT_DOUBLE_EQ(s.keyframe.ref_overlap, 0.4);
  for (const std::string bad :
       {"KeyFrame.minTrackedClose: 0", "KeyFrame.minUntrackedClose: -3", "KeyFrame.minTrackedClose: 1.5",
        "KeyFrame.refOverlap: 1.0", "KeyFrame.refOverlap: -0.1", "KeyFrame.refOverlap: many"}) {
    try {
      read_settings(temp_copy("kfbad", read_file(tum1()) + "\n" + bad + "\n"));
      FAIL() << "expected ConfigError for " << bad;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), bad.substr(0, bad.find(':')));
    }
  }
}

/// An optional 0/1 key of ours: on when absent, off with 0 (no warning),
/// a ConfigError naming the key for `bad_value`.
void expect_optional_flag(const std::string& key, const std::string& bad_value,
                          bool (*get)(const Settings&)) {
  SCOPED_TRACE(key);
  EXPECT_TRUE(get(read_settings(tum1())));
  const Settings s = read_settings(temp_copy("flag", read_file(tum1()) + "\n" + key + ": 0\n"));
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_FALSE(get(s));
  try {
    read_settings(temp_copy("flagbad", read_file(tum1()) + "\n" + key + ": " + bad_value + "\n"));
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), key);
  }
}

TEST(Settings, ReadsOrbSubPixelFlag) {
  // 0: ORB-SLAM2's whole level pixels
  expect_optional_flag("ORBextractor.subPixel", "2", [](const Settings& s) { return s.orb.sub_pixel; });
}

TEST(Settings, ReadsTrackingAlignPatchesFlag) {
  expect_optional_flag("Tracking.alignPatches", "yes", [](const Settings& s) { return s.align_patches; });
}

TEST(Settings, ReadsMapSpillFeaturesFlag) {
  expect_optional_flag("Map.spillFeatures", "2", [](const Settings& s) { return s.spill_features; });
}

TEST(Settings, ReadsLoopClosingSection) {
  const Settings d = read_settings(tum1());  // absent: on, with the documented defaults
  EXPECT_TRUE(d.loop.enabled);
  EXPECT_EQ(d.loop.min_inliers, 40);
  const std::string path =
      temp_copy("loop", read_file(tum1()) +
                            "\nLoopClosing.enabled: 0\nLoopClosing.searchRadius: 2.5\n"
                            "LoopClosing.maxAngle: 45\nLoopClosing.minKeyFrameGap: 20\n"
                            "LoopClosing.maxCandidates: 3\nLoopClosing.minMatches: 25\n"
                            "LoopClosing.consistency: 3\nLoopClosing.minInliers: 60\n"
                            "LoopClosing.maxCorrection: 0.2\nLoopClosing.maxCorrectionAngle: 5\n"
                            "LoopClosing.maxCorrectionAnglePerKm: 2.5\n"
                            "LoopClosing.lookalikeCheckAbove: 0.3\n"
                            "LoopClosing.essentialWeight: 80\nLoopClosing.globalBA: 1\n"
                            "LoopClosing.rotationWeight: 3\n");
  const Settings s = read_settings(path);
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_FALSE(s.loop.enabled);
  EXPECT_DOUBLE_EQ(s.loop.search_radius_m, 2.5);
  EXPECT_DOUBLE_EQ(s.loop.max_angle_deg, 45);
  EXPECT_EQ(s.loop.min_keyframe_gap, 20);
  EXPECT_EQ(s.loop.max_candidates, 3);
  EXPECT_EQ(s.loop.min_matches, 25);
  EXPECT_EQ(s.loop.consistency, 3);
  EXPECT_EQ(s.loop.min_inliers, 60);
  EXPECT_DOUBLE_EQ(s.loop.max_correction_m, 0.2);
  EXPECT_DOUBLE_EQ(s.loop.max_correction_deg, 5);
  EXPECT_DOUBLE_EQ(d.loop.max_correction_deg_per_km, 5);
  EXPECT_DOUBLE_EQ(s.loop.max_correction_deg_per_km, 2.5);
  EXPECT_DOUBLE_EQ(d.loop.lookalike_check_above_m, 0.5);
  EXPECT_DOUBLE_EQ(s.loop.lookalike_check_above_m, 0.3);
  EXPECT_EQ(s.loop.essential_weight, 80);
  EXPECT_FALSE(d.loop.global_ba);  // off by default: it made the loop scenario worse (docs/slam.md)
  EXPECT_TRUE(s.loop.global_ba);
  EXPECT_DOUBLE_EQ(s.loop.rotation_weight, 3);
  for (const std::string bad :
       {"LoopClosing.enabled: 2", "LoopClosing.searchRadius: -1", "LoopClosing.minInliers: 3",
        "LoopClosing.maxAngle: 200", "LoopClosing.consistency: 1.5", "LoopClosing.rotationWeight: 0"}) {
    const std::string key = bad.substr(0, bad.find(':'));
    try {
      read_settings(temp_copy("loopbad", read_file(tum1()) + "\n" + bad + "\n"));
      FAIL() << "expected ConfigError for " << bad;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key);
    }
  }
}

TEST(Settings, MissingKeyIsAnErrorNamingIt) {
  const std::string text = std::regex_replace(read_file(tum1()), std::regex("Camera\\.bf: 40\\.0"), "");
  const std::string path = temp_copy("missing", text);
  try {
    read_settings(path);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "Camera.bf");
    EXPECT_NE(std::string(e.what()).find("Camera.bf"), std::string::npos);
  }
}

TEST(Settings, UnknownKeyIsAWarning) {
  const std::string path = temp_copy("unknown", read_file(tum1()) + "\nCamera.fxx: 500.0\n");
  const Settings s = read_settings(path);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("Camera.fxx"), std::string::npos);
}

TEST(Settings, WrongTypeAndBadValuesAreErrors) {
  EXPECT_THROW(read_settings(temp_copy(
                   "type", std::regex_replace(read_file(tum1()), std::regex("Camera.fx: 517.306408"),
                                              "Camera.fx: \"abc\""))),
               ConfigError);
  EXPECT_THROW(read_settings(temp_copy(
                   "lev", std::regex_replace(read_file(tum1()), std::regex("nLevels: 8"), "nLevels: 0"))),
               ConfigError);
}

TEST(Settings, PointCloudMappingSection) {
  // absent: enabled with the documented defaults
  const Settings d = read_settings(tum1());
  EXPECT_TRUE(d.dense.enabled);
  EXPECT_DOUBLE_EQ(d.dense.resolution_m, 0.02);
  EXPECT_EQ(d.dense.stride_px, 3);
  EXPECT_DOUBLE_EQ(d.dense.max_depth_m, 4.0);
  EXPECT_DOUBLE_EQ(d.dense.memory_budget_mb, 512);
  const Settings s = read_settings(temp_copy(
      "pc", read_file(tum1()) + "\nPointCloudMapping.Enabled: 0\nPointCloudMapping.Resolution: 0.05\n"
                                "PointCloudMapping.Stride: 2\nPointCloudMapping.MinDepth: 0.3\n"
                                "PointCloudMapping.MaxDepth: 6.5\nPointCloudMapping.MemoryBudget: 0\n"));
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_FALSE(s.dense.enabled);
  EXPECT_DOUBLE_EQ(s.dense.resolution_m, 0.05);
  EXPECT_EQ(s.dense.stride_px, 2);
  EXPECT_DOUBLE_EQ(s.dense.min_depth_m, 0.3);
  EXPECT_DOUBLE_EQ(s.dense.max_depth_m, 6.5);
  EXPECT_DOUBLE_EQ(s.dense.memory_budget_mb, 0);
  // unknown key in the section: a warning naming it
  const Settings w =
      read_settings(temp_copy("pcw", read_file(tum1()) + "\nPointCloudMapping.Resolutoin: 0.05\n"));
  ASSERT_EQ(w.warnings.size(), 1u);
  EXPECT_NE(w.warnings[0].find("PointCloudMapping.Resolutoin"), std::string::npos);
  // wrong type or value: an error naming the key
  const std::vector<std::pair<std::string, std::string>> bad = {{"PointCloudMapping.Resolution", "\"fine\""},
                                                                {"PointCloudMapping.Resolution", "0"},
                                                                {"PointCloudMapping.Stride", "1.5"},
                                                                {"PointCloudMapping.Enabled", "2"},
                                                                {"PointCloudMapping.MaxDepth", "0.05"},
                                                                {"PointCloudMapping.MemoryBudget", "-1"}};
  for (const auto& [key, value] : bad) {
    try {
      read_settings(temp_copy("pcbad", read_file(tum1()) + "\n" + key + ": " + value + "\n"));
      ADD_FAILURE() << key << ": " << value << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  }
}

/// TUM1.yaml with `key` set to `value` (replaced where TUM1 has it, else appended).
std::string tum1_with(const std::string& key, const std::string& value) {
  const std::string text = read_file(tum1());
  const std::regex line("(^|\n)" + std::regex_replace(key, std::regex("\\."), "\\.") + ":[^\n]*");
  if (std::regex_search(text, line)) return std::regex_replace(text, line, "$1" + key + ": " + value);
  return text + "\n" + key + ": " + value + "\n";
}

// Every key is range-checked when the file is read: a value that would
// reach an OpenCV assertion, a bad_alloc, a float-to-int overflow or a
// silently useless camera is a ConfigError naming the key and the range.
TEST(Settings, OutOfRangeValuesAreErrorsNamingKeyAndRange) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"ORBextractor.nLevels", "100"},
      {"ORBextractor.nLevels", "-2147483649"},
      {"ORBextractor.nLevels", "24"},  // 480 px / 1.2^23 < 8 px
      {"ORBextractor.scaleFactor", "1e300"},
      {"ORBextractor.scaleFactor", "-2147483649"},
      {"ORBextractor.scaleFactor", ".nan"},
      {"ORBextractor.nFeatures", "2000000000"},
      {"ORBextractor.nFeatures", "1e300"},
      {"ORBextractor.iniThFAST", "-5"},
      {"ORBextractor.minThFAST", "256"},
      {"Camera.k1", ".nan"},
      {"Camera.k3", "-.inf"},
      {"Camera.cx", ".inf"},
      {"Camera.cx", "700"},
      {"Camera.cy", "-1"},
      {"Camera.fx", "1e308"},
      {"Camera.fy", "0"},
      {"Camera.width", "1e10"},
      {"Camera.height", "8"},
      {"Camera.fps", ".inf"},
      {"Camera.bf", ".nan"},
      {"ThDepth", ".inf"},
      {"DepthMapFactor", "1e300"},
      {"PEMatch.population", "1000000000"},
      {"PEMatch.j", "-1"},
      {"PEMatch.stallIterations", "1e12"},
      {"PEMatch.threshold", ".inf"},
      {"KeyFrame.minTrackedClose", "3e9"},
      {"KeyFrame.refOverlap", ".nan"},
      {"PointCloudMapping.Resolution", "1e-300"},
      {"PointCloudMapping.MaxDepth", ".inf"},
      {"PointCloudMapping.Stride", "1e10"},
      {"PointCloudMapping.MemoryBudget", ".inf"},
      {"LoopClosing.searchRadius", ".inf"},
      {"LoopClosing.maxCandidates", "4294967297"},
      {"LoopClosing.maxCorrectionAngle", "1e300"},
      {"LoopClosing.maxCorrectionAnglePerKm", "-1"},
      {"LoopClosing.lookalikeCheckAbove", "0"},
      {"LoopClosing.essentialWeight", "-7"},
      {"LoopClosing.rotationWeight", ".nan"}};
  for (const auto& [key, value] : bad) {
    try {
      read_settings(temp_copy("range", tum1_with(key, value)));
      ADD_FAILURE() << key << ": " << value << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
      EXPECT_NE(std::string(e.what()).find(" in "), std::string::npos) << "no range in: " << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << key << ": " << value << " gave " << e.what();
    }
  }
}

// The limits let real files through: a pyramid as deep as 640x480 allows
// at scaleFactor 1.2, a 2x pyramid, distortion and a principal point on the
// image border.
TEST(Settings, RangesAcceptRealFiles) {
  const Settings deep = read_settings(temp_copy("deep", tum1_with("ORBextractor.nLevels", "23")));
  EXPECT_EQ(deep.orb.num_levels, 23);
  const Settings twice =
      read_settings(temp_copy("twice", std::regex_replace(tum1_with("ORBextractor.scaleFactor", "2"),
                                                          std::regex("nLevels: 8"), "nLevels: 6")));
  EXPECT_EQ(twice.orb.num_levels, 6);
  const Settings edge = read_settings(temp_copy("edge", tum1_with("Camera.cx", "640")));
  EXPECT_DOUBLE_EQ(edge.K.cx, 640);
}

// A YAML syntax error names the file, the line and OpenCV's reason (not
// OpenCV's function name).
TEST(Settings, SyntaxErrorNamesLineAndReason) {
  const std::string path = temp_copy("syntax", "%YAML:1.0\nCamera.fx: 500\nCamera.fy 500\nCamera.cx: 320\n");
  try {
    read_settings(path);
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), 3) << e.what();
    const std::string what = e.what();
    EXPECT_EQ(what.find("parseKey"), std::string::npos) << what;
    EXPECT_NE(what.find(path + ":3: cannot parse settings file: "), std::string::npos) << what;
  }
}

// A file whose top level is a list, a scalar or nothing (found by
// fuzz_settings: OpenCV asserted, an internal error) is one IoError.
TEST(Settings, TopLevelMustBeAMap) {
  for (const char* text : {"%YAML:1.0\n- Camera.fx\n- 500\n", "%YAML:1.0\n---\n", "just words\n"}) {
    const std::string path = temp_copy("toplevel", text);
    try {
      read_settings(path);
      ADD_FAILURE() << "expected IoError for " << text;
    } catch (const IoError& e) {
      EXPECT_EQ(e.file(), path);
    }
  }
}

// OpenCV's parser loops for ever on a line such as "----x" (found by
// fuzz_settings): such a line is an error naming it, before OpenCV reads.
TEST(Settings, DocumentMarkerMustStandAlone) {
  const std::string path = temp_copy("marker", "%YAML:1.0\n----x\nCamera.fx: 500\n");
  try {
    read_settings(path);
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), 2) << e.what();
    EXPECT_NE(std::string(e.what()).find("document marker '---' alone"), std::string::npos) << e.what();
  }
  // The marker itself, with spaces or a comment after it, is fine.
  const std::string ok = temp_copy("marker_ok", "%YAML:1.0\n--- # settings\nCamera.fx: 500\n");
  try {
    read_settings(ok);
  } catch (const ConfigError& e) {  // the missing keys, not the marker
    EXPECT_EQ(std::string(e.what()).find("document marker"), std::string::npos) << e.what();
  }
}

TEST(Settings, MissingFileIsAnIoError) { EXPECT_THROW(read_settings("/nonexistent/settings.yaml"), IoError); }

TEST(Settings, ReadsPlaceRecognitionKeys) {
  const Settings d = read_settings(tum1());  // absent: the default vocabulary, BoW loops, both checks on
  EXPECT_EQ(d.vocabulary_path, kDefaultVocabularyPath);
  EXPECT_FALSE(d.loop.pose_proximity);
  EXPECT_TRUE(d.loop.ambiguity_check);
  EXPECT_DOUBLE_EQ(d.loop.max_drift_rate, 0.01);
  const std::string path =
      temp_copy("place", read_file(tum1()) +
                             "\nVocabulary.path: \"voc/ORBvoc.txt\"\n"
                             "LoopClosing.poseProximity: 1\nLoopClosing.maxDriftRate: 0\n"
                             "LoopClosing.driftFloor: 0.1\nLoopClosing.ambiguityCheck: 0\n"
                             "LoopClosing.ambiguityDistance: 0.5\nLoopClosing.ambiguityInlierShare: 0.25\n");
  const Settings s = read_settings(path);
  EXPECT_TRUE(s.warnings.empty());
  // relative to the settings file's folder
  EXPECT_EQ(s.vocabulary_path, path.substr(0, path.rfind('/') + 1) + "voc/ORBvoc.txt");
  EXPECT_TRUE(s.loop.pose_proximity);
  EXPECT_DOUBLE_EQ(s.loop.max_drift_rate, 0);
  EXPECT_DOUBLE_EQ(s.loop.drift_floor_m, 0.1);
  EXPECT_FALSE(s.loop.ambiguity_check);
  EXPECT_DOUBLE_EQ(s.loop.ambiguity_distance_m, 0.5);
  EXPECT_DOUBLE_EQ(s.loop.ambiguity_inlier_share, 0.25);
  EXPECT_DOUBLE_EQ(d.loop.ambiguity_inlier_share, 0.5);
  EXPECT_EQ(read_settings(temp_copy("none", read_file(tum1()) + "\nVocabulary.path: none\n")).vocabulary_path,
            "none");
  for (const std::string bad :
       {"Vocabulary.path: 3", "LoopClosing.maxDriftRate: 2", "LoopClosing.ambiguityDistance: 0",
        "LoopClosing.ambiguityInlierShare: 1.5"}) {
    const std::string key = bad.substr(0, bad.find(':'));
    try {
      read_settings(temp_copy("bad_place", read_file(tum1()) + "\n" + bad + "\n"));
      ADD_FAILURE() << bad;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  }
}

TEST(Settings, ReadsTheLocalMapsBound) {
  EXPECT_EQ(read_settings(tum1()).max_observing_keyframes, 60);
  const Settings s =
      read_settings(temp_copy("local_map", read_file(tum1()) + "\nTracking.maxObservingKeyFrames: 0\n"));
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.max_observing_keyframes, 0);  // ORB-SLAM2's local map
  try {
    read_settings(temp_copy("bad_local_map", read_file(tum1()) + "\nTracking.maxObservingKeyFrames: -5\n"));
    ADD_FAILURE() << "a negative Tracking.maxObservingKeyFrames was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "Tracking.maxObservingKeyFrames") << e.what();
  }
}

TEST(Settings, ReadsMapReuseTrackingKeys) {
  const Settings d = read_settings(tum1());
  EXPECT_EQ(d.reloc_lookalikes, 10);
  EXPECT_EQ(d.new_map_after_lost, 30);
  EXPECT_EQ(d.merge_reloc_every, 5);
  const Settings s = read_settings(
      temp_copy("reuse", read_file(tum1()) + "\nTracking.relocLookalikes: 4\nTracking.newMapAfter: 0\n"
                                             "Tracking.mergeRelocEvery: 0\n"));
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.reloc_lookalikes, 4);
  EXPECT_EQ(s.new_map_after_lost, 0);
  EXPECT_EQ(s.merge_reloc_every, 0);
  try {
    read_settings(temp_copy("bad_reuse", read_file(tum1()) + "\nTracking.mergeRelocEvery: -1\n"));
    ADD_FAILURE() << "a negative Tracking.mergeRelocEvery was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "Tracking.mergeRelocEvery") << e.what();
  }
}

TEST(Settings, ReadsTheWheelsBoundOnRelocalisation) {
  const Settings d = read_settings(tum1());
  EXPECT_DOUBLE_EQ(d.reloc_odometry_floor_m, 0.5);
  EXPECT_DOUBLE_EQ(d.reloc_odometry_rate, 0.1);
  EXPECT_EQ(d.carried_restart_after, 15);
  const Settings s = read_settings(
      temp_copy("odometry_bound", read_file(tum1()) + "\nTracking.relocOdometryFloor: 1.5\nTracking.relocOdometryRate: 0\n"
                                                      "Tracking.carriedRestartAfter: 0\n"));
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_DOUBLE_EQ(s.reloc_odometry_floor_m, 1.5);
  EXPECT_DOUBLE_EQ(s.reloc_odometry_rate, 0.0);
  EXPECT_EQ(s.carried_restart_after, 0);
  for (const char* bad : {"Tracking.relocOdometryFloor: 0", "Tracking.relocOdometryRate: -0.1",
                          "Tracking.relocOdometryRate: 11", "Tracking.carriedRestartAfter: -1"}) {
    const std::string key = std::string(bad).substr(0, std::string(bad).find(':'));
    try {
      read_settings(temp_copy("bad_odometry_bound", read_file(tum1()) + "\n" + bad + "\n"));
      ADD_FAILURE() << bad << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  }
}

// OpenCV's parser reads the first of two equal keys and ignores the second:
// a key given twice is an error naming both lines.
TEST(Settings, DuplicateKeyNamesBothLines) {
  const std::string text = read_file(tum1());
  const int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  const std::string path = temp_copy("dup", text + "Vocabulary.path: none\nVocabulary.path: other.txt\n");
  try {
    read_settings(path);
    ADD_FAILURE() << "accepted";
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), lines + 2) << e.what();
    EXPECT_NE(e.message().find("key 'Vocabulary.path' given twice (first at line " + std::to_string(lines + 1) + ")"),
              std::string::npos)
        << e.what();
  }
  // The same key name in two nested maps is not a duplicate.
  const std::string nested = temp_copy(
      "nested", text + "M1: !!opencv-matrix\n   rows: 1\n   cols: 1\n   dt: d\n   data: [ 1.0 ]\n"
                       "M2: !!opencv-matrix\n   rows: 1\n   cols: 1\n   dt: d\n   data: [ 2.0 ]\n");
  EXPECT_NO_THROW(read_settings(nested));
}

TEST(Settings, FifoIsRefusedBeforeItIsOpened) {
  const std::string fifo = ::testing::TempDir() + "pvb_settings_fifo_" + std::to_string(::getpid());
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    read_settings(fifo);
    ADD_FAILURE() << "accepted";
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()), fifo + ": is a FIFO; expected a regular file");
  }
  std::remove(fifo.c_str());
}

TEST(Settings, MissingVocabularyIsOneIoErrorNamingIt) {
  Settings s = read_settings(tum1());
  s.vocabulary_path = "/nonexistent/voc.pvbvoc";
  try {
    System system(s, {});
    ADD_FAILURE() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/voc.pvbvoc"), std::string::npos) << e.what();
  }
}


/// ORB-SLAM3's IMU keys and our Robot keys, as a recording writes them.
const std::string kImuKeys =
    "\nIMU.NoiseGyro: 0.00017\nIMU.NoiseAcc: 0.002\nIMU.GyroWalk: 2.0e-05\nIMU.AccWalk: 0.0004\nIMU.Frequency: 200.0\n"
    "IMU.T_b_c1: !!opencv-matrix\n  rows: 4\n  cols: 4\n  dt: f\n"
    "  data: [0.0, 0.0, 1.0, 0.05, -1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.1, 0.0, 0.0, 0.0, 1.0]\n";
const std::string kRobotKeys =
    "Robot.WheelRadius: 0.1\nRobot.Track: 0.42\nRobot.TicksPerRev: 1024\nRobot.EncoderFrequency: 50.0\n"
    "Robot.T_base_c1: !!opencv-matrix\n  rows: 4\n  cols: 4\n  dt: f\n"
    "  data: [0.0, 0.0, 1.0, 0.2, -1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 1.0]\n"
    "Robot.T_base_imu: !!opencv-matrix\n  rows: 4\n  cols: 4\n  dt: f\n"
    "  data: [1.0, 0.0, 0.0, 0.1, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.4, 0.0, 0.0, 0.0, 1.0]\n";

TEST(Settings, ReadsImuAndRobotKeysAndTheSensorSetup) {
  const Settings plain = read_settings(tum1());
  EXPECT_EQ(plain.motion.setup, sensor::SensorSetup::kCamera);
  EXPECT_FALSE(plain.motion.imu.present);
  EXPECT_FALSE(plain.motion.robot.present);
  const Settings s = read_settings(
      temp_copy("imu", read_file(tum1()) + kImuKeys + kRobotKeys + "System.Sensors: \"camera+imu+wheels\"\n"));
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  EXPECT_EQ(s.motion.setup, sensor::SensorSetup::kCameraImuWheels);
  ASSERT_TRUE(s.motion.imu.present);
  EXPECT_DOUBLE_EQ(s.motion.imu.noise.gyro_noise_density, 0.00017);
  EXPECT_DOUBLE_EQ(s.motion.imu.noise.accel_random_walk, 0.0004);
  EXPECT_DOUBLE_EQ(s.motion.imu.rate_hz, 200.0);
  // The accelerometer is weighed with its density inflated, 3x unless set.
  EXPECT_DOUBLE_EQ(s.motion.imu.noise.accel_noise_density, 0.002);
  EXPECT_DOUBLE_EQ(s.motion.imu.fused_noise().accel_noise_density, 0.006);
  EXPECT_DOUBLE_EQ(s.motion.imu.fused_noise().gyro_noise_density, 0.00017);
  // Its bias walks 100x as fast unless set.
  EXPECT_DOUBLE_EQ(s.motion.imu.fused_noise().accel_random_walk, 0.04);
  EXPECT_DOUBLE_EQ(s.motion.imu.fused_noise().gyro_random_walk, s.motion.imu.noise.gyro_random_walk);
  const Settings one = read_settings(temp_copy(
      "imu1", read_file(tum1()) + kImuKeys + "IMU.AccNoiseInflation: 1.0\nIMU.AccWalkInflation: 1\n"));
  EXPECT_DOUBLE_EQ(one.motion.imu.fused_noise().accel_noise_density, 0.002);
  EXPECT_DOUBLE_EQ(one.motion.imu.fused_noise().accel_random_walk, 0.0004);
  // The camera's optical z looks along the IMU's x; its centre 5 cm ahead, 10 cm up.
  EXPECT_NEAR((s.motion.imu.T_b_c.linear() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(), 0, 1e-6);
  EXPECT_NEAR((s.motion.imu.T_b_c.translation() - Eigen::Vector3d(0.05, 0, 0.1)).norm(), 0, 1e-6);
  ASSERT_TRUE(s.motion.robot.present);
  EXPECT_EQ(s.motion.robot.drive.ticks_per_rev, 1024);
  EXPECT_DOUBLE_EQ(s.motion.robot.drive.track_m, 0.42);
  EXPECT_NEAR(s.motion.robot.T_base_imu.translation().z(), 0.4, 1e-6);
  // The wheels' noise keeps its defaults unless set.
  EXPECT_DOUBLE_EQ(s.motion.robot.wheel_noise.yaw_per_sqrt_m, WheelNoise{}.yaw_per_sqrt_m);
  const Settings tight = read_settings(temp_copy(
      "wheels", read_file(tum1()) + kImuKeys + kRobotKeys +
                    "Robot.WheelNoiseTranslation: 0.01\nRobot.WheelNoiseYaw: 0.001\nRobot.WheelNoiseYawTurn: 0.02\n"));
  EXPECT_DOUBLE_EQ(tight.motion.robot.wheel_noise.translation_per_sqrt_m, 0.01);
  EXPECT_DOUBLE_EQ(tight.motion.robot.wheel_noise.yaw_per_sqrt_m, 0.001);
  EXPECT_DOUBLE_EQ(tight.motion.robot.wheel_noise.yaw_per_sqrt_rad, 0.02);
  // The wheels are calibrated online unless Robot.CalibrateWheels says 0.
  EXPECT_TRUE(s.motion.robot.wheel_calibration.enabled);
  const Settings fixed = read_settings(
      temp_copy("wheels_fixed", read_file(tum1()) + kImuKeys + kRobotKeys + "Robot.CalibrateWheels: 0\n"));
  EXPECT_FALSE(fixed.motion.robot.wheel_calibration.enabled);
}

TEST(Settings, SensorSetupWithoutItsKeysOrWithABadExtrinsicIsOneConfigError) {
  const auto error_of = [](const std::string& name, const std::string& text) -> std::string {
    try {
      read_settings(temp_copy(name, text));
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string base = read_file(tum1());
  EXPECT_NE(error_of("s1", base + "System.Sensors: \"camera+imu\"\n").find("IMU.NoiseGyro"), std::string::npos);
  EXPECT_NE(error_of("s2", base + kImuKeys + "System.Sensors: \"camera+imu+wheels\"\n").find("Robot.WheelRadius"),
            std::string::npos);
  EXPECT_NE(error_of("s3", base + "System.Sensors: \"lidar\"\n").find("System.Sensors"), std::string::npos);
  std::string skewed = kImuKeys;
  skewed.replace(skewed.find("[0.0, 0.0, 1.0"), 14, "[0.5, 0.0, 1.0");
  EXPECT_NE(error_of("s4", base + skewed).find("IMU.T_b_c1"), std::string::npos);
  std::string partial = kImuKeys;
  partial.replace(partial.find("IMU.AccWalk"), 3, "XMU");
  EXPECT_NE(error_of("s5", base + partial).find("IMU.AccWalk"), std::string::npos);
  EXPECT_NE(error_of("s6", base + kImuKeys + "IMU.AccNoiseInflation: 0.5\n").find("IMU.AccNoiseInflation"),
            std::string::npos);
  EXPECT_NE(error_of("s7", base + kImuKeys + "IMU.AccWalkInflation: 2000\n").find("IMU.AccWalkInflation"),
            std::string::npos);
  EXPECT_NE(error_of("s8", base + kImuKeys + kRobotKeys + "Robot.WheelNoiseYaw: 0\n").find("Robot.WheelNoiseYaw"),
            std::string::npos);
  EXPECT_NE(error_of("s9", base + kImuKeys + kRobotKeys + "Robot.WheelNoiseTranslation: -1\n")
                .find("Robot.WheelNoiseTranslation"),
            std::string::npos);
  // With a setup that needs them, a flag's choice is checked the same way.
  MotionSensorSettings plain = read_settings(tum1()).motion;
  plain.setup = sensor::SensorSetup::kCameraAccel;
  EXPECT_THROW(plain.check(tum1()), ConfigError);
  plain.setup = sensor::SensorSetup::kCamera;
  EXPECT_NO_THROW(plain.check(tum1()));
}

}  // namespace
}  // namespace pvb::slam
