#pragma once
// A SLAM system's loops and relocalisations as place-recognition events,
// and their ground-truth labels (eval/place_labels.hpp).  Shared by
// `pvbench run` and `pvbench slam`.
#include <cstdint>
#include <vector>

#include "pvb/eval/trajectory.hpp"
#include "pvb/report/report.hpp"
#include "pvb/slam/core/system.hpp"

namespace pvb::run {

/// The detectors' counts and events of `system` (after shutdown()), with
/// the times of every keyframe it made.
PlaceRecognition collect_place_recognition(const slam::System& system, std::vector<std::int64_t> keyframe_t_ns);

/// Labels p's events against ground truth `gt` (p->labels).
void label_place_recognition(PlaceRecognition* p, const eval::Trajectory& gt);

}  // namespace pvb::run
