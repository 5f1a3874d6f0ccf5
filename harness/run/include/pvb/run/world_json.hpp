#pragma once
// The station and the day a run or recording was made in, as a JSON object
// (metrics.json's and meta.json's "world"): both seeds, the files the
// scenario derives from, the site, the sun and every array's mount and
// angle.
#include <string>

#include "pvb/scenes/scenario.hpp"

namespace pvb::run {

/// The object, one line; numbers as JSON allows (never NaN or inf).
std::string world_json(const scenes::Scenario& s);

}  // namespace pvb::run
