#pragma once
// The default PV station recorded once per build (300 frames, seed 7), and
// two runs of it, read by the tests that need them: CTest makes each first
// (shared.NAME, tests/CMakeLists.txt), and keeps it while pvbench and the
// scenario are unchanged.  A test program run by hand without one makes it
// there itself (into a private folder, then renamed into place: a loser of
// a race keeps the winner's copy, which is byte-identical).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "run_pvbench.hpp"

namespace pvb::test {

inline const std::string& station_scenario() {
  static const std::string path = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  return path;
}
constexpr int kStationFrames = 300;
constexpr int kStationSeed = 7;

/// The shared output `name` (tests/CMakeLists.txt, pvb_add_shared_output):
/// PVB_TEST_DATA_DIR/name, made with `pvbench ARGS --out ...` first when a
/// test program run by hand finds it missing.  `key_file` is a file every
/// finished output holds.
inline std::string shared_output(const std::string& name, const std::string& args,
                                 const std::string& key_file) {
  const std::string final_dir = std::string(PVB_TEST_DATA_DIR) + "/" + name;
  if (::access((final_dir + "/" + key_file).c_str(), F_OK) == 0) return final_dir;
  std::system(("mkdir -p " + std::string(PVB_TEST_DATA_DIR)).c_str());
  const std::string tmp = final_dir + ".tmp" + std::to_string(::getpid());
  const RunResult r = run_pvbench(args + " --out " + tmp);
  EXPECT_EQ(r.code, 0) << r.output;
  if (std::rename(tmp.c_str(), final_dir.c_str()) != 0) std::system(("rm -rf " + tmp).c_str());
  return final_dir;
}

inline const std::string& station_sequence() {
  static const std::string d =
      shared_output("pv_station_300",
                    "record --scenario " + station_scenario() + " --frames " + std::to_string(kStationFrames) +
                        " --seed " + std::to_string(kStationSeed),
                    "groundtruth.txt");
  return d;
}

/// The fast CI set's run of the default station (shared output
/// pv_station_ci_run): 150 frames, synchronous, PE-SLAM, map scoring on.
constexpr int kStationRunFrames = 150;
inline const std::string& station_ci_run() {
  static const std::string d = shared_output(
      "pv_station_ci_run",
      "run --scenario " + station_scenario() + " --sync --frames " + std::to_string(kStationRunFrames),
      "metrics.json");
  return d;
}

/// pvbench slam on the recording's first 120 frames (shared output
/// pv_station_slam_120): synchronous, with its dense map, Map.txt dumped.
inline const std::string& station_slam_120() {
  static const std::string d = shared_output("pv_station_slam_120",
                                             "slam --sequence " + station_sequence() + " --settings " +
                                                 station_sequence() +
                                                 "/camera.yaml --sync --dump-map --max-frames 120",
                                             "stats.json");
  return d;
}

/// The station's 200-frame synchronous run with its IMU (shared output
/// pv_station_imu_200), without map scoring.
constexpr int kStationImuRunFrames = 200;
inline const std::string& station_imu_run() {
  static const std::string d = shared_output("pv_station_imu_200",
                                             "run --scenario " + station_scenario() + " --sync --frames " +
                                                 std::to_string(kStationImuRunFrames) +
                                                 " --no-map-eval --sensors camera+imu",
                                             "metrics.json");
  return d;
}

/// A Kinect v1 dump of the station's first 60 frames (shared output
/// pv_station_fakenect_60, `record --format fakenect`).  Tests copy it
/// before they break it.
constexpr int kStationFakenectFrames = 60;
inline const std::string& station_fakenect_dump() {
  static const std::string d = shared_output("pv_station_fakenect_60",
                                             "record --scenario " + station_scenario() +
                                                 " --format fakenect --frames " +
                                                 std::to_string(kStationFakenectFrames),
                                             "INDEX.txt");
  return d;
}

}  // namespace pvb::test
