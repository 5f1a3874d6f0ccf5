#pragma once
// ORB-SLAM2 settings for a scenario's simulated camera (pvbench record and
// pvbench camera with a sim:// device).
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/scenes/scenario.hpp"

namespace pvb::cli {

/// Intrinsics, rate and depth model of the scenario's camera.
dataset::OrbSlamSettings settings_for_scenario(const scenes::Scenario& s);

}  // namespace pvb::cli
