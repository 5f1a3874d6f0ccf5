#pragma once
// The default PV station recorded once per build (300 frames, seed 7), read
// by the tests that need a simulated sequence: CTest makes it first
// (shared.pv_station_300, tests/CMakeLists.txt), and keeps it while pvbench
// and the scenario are unchanged.  A test program run by hand without it
// records it there itself (into a private folder, then renamed into place:
// a loser of a race keeps the winner's copy, which is byte-identical).
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

inline const std::string& station_sequence() {
  static const std::string d = [] {
    const std::string final_dir = std::string(PVB_TEST_DATA_DIR) + "/pv_station_300";
    if (::access((final_dir + "/groundtruth.txt").c_str(), F_OK) == 0) return final_dir;
    std::system(("mkdir -p " + std::string(PVB_TEST_DATA_DIR)).c_str());
    const std::string tmp = final_dir + ".tmp" + std::to_string(::getpid());
    const RunResult r =
        run_pvbench("record --scenario " + station_scenario() + " --out " + tmp + " --frames " +
                    std::to_string(kStationFrames) + " --seed " + std::to_string(kStationSeed));
    EXPECT_EQ(r.code, 0) << r.output;
    if (std::rename(tmp.c_str(), final_dir.c_str()) != 0) std::system(("rm -rf " + tmp).c_str());
    return final_dir;
  }();
  return d;
}

}  // namespace pvb::test
