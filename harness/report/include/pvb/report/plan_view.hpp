#pragma once
// A station seen from above, drawn from its scenario (no rendering): the
// ground, every table's footprint, the walls and inverter stations, and
// the route with its start; north up.  For people: where the rows lie and
// where the robot drives (docs/plants.md).
#include <opencv2/core.hpp>

#include "pvb/scenes/scenario.hpp"

namespace pvb::run {

inline const cv::Vec3b kPlanTableRgb{40, 60, 120};
inline const cv::Vec3b kPlanRouteRgb{240, 120, 20};

/// R, G, B (CV_8UC3): the ground's extent (or the plant's, with a margin,
/// when the ground is far larger) at most max_side_px on its longer side,
/// a scale bar and a title line below.
cv::Mat make_plan_view(const scenes::Scenario& s, int max_side_px = 1600);

}  // namespace pvb::run
