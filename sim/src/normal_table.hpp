#pragma once
// Standard normal quantiles for per-pixel noise (sensor_model.cpp).
#include <array>

namespace pvb::sim {

/// Standard normal quantiles at 4096 evenly spaced probabilities: a table
/// lookup per draw keeps per-pixel noise cheap.
const std::array<float, 4096>& normal_table();

}  // namespace pvb::sim
