#pragma once
// The real two-frame Kinect sequence in ../shared/data that the map file
// tests map (test_map_file.cpp, test_map_file_checks.cpp), its settings and
// the synchronous System they map it with.
#include <string>
#include <vector>

#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/slam/core/system.hpp"
#include "shared_data.hpp"

namespace pvb::test {

inline std::string pair_dir() { return shared_path("data/tum/fr3_long_office_household_pair"); }
inline const std::string kTum3 = std::string(PVB_SOURCE_DIR) + "/configs/tum/TUM3.yaml";

inline std::vector<sensor::RgbdFrame> pair_frames(const slam::Settings& s) {
  dataset::TumSequenceReader reader(pair_dir(), s.depth_map_factor);
  std::vector<sensor::RgbdFrame> out;
  while (auto f = reader.next()) out.push_back(*f);
  return out;
}

inline slam::SystemOptions sync_options() {
  slam::SystemOptions o;
  o.synchronous = true;
  return o;
}

}  // namespace pvb::test
