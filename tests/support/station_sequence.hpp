#pragma once
// The default PV station recorded once (300 frames, seed 7) and shared by
// the scenario tests that need a simulated sequence.  The folder name
// carries a fingerprint of the scenario file and of the pvbench binary, so
// a changed simulator or scenario never reuses a stale recording.  Recorded
// into a private folder, then renamed into place (a loser of a race keeps
// the winner's copy, which is byte-identical).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

#include "pvb/common/text.hpp"
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
    const std::string& bin = pvbench_path();
    const auto stamp = std::filesystem::last_write_time(bin).time_since_epoch().count();
    const std::size_t key = std::hash<std::string>{}(read_file(station_scenario()) + std::to_string(stamp) +
                                                     std::to_string(std::filesystem::file_size(bin)));
    const std::string final_dir =
        std::string(PVB_BINARY_DIR) + "/test_data/slam_pv_station_300_" + std::to_string(key % 1000000007);
    if (::access((final_dir + "/groundtruth.txt").c_str(), F_OK) == 0) return final_dir;
    std::system(("mkdir -p " + std::string(PVB_BINARY_DIR) + "/test_data").c_str());
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
