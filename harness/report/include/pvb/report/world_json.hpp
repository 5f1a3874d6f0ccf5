#pragma once
// The station and the day a run or recording was made in, as a JSON object
// (metrics.json's and meta.json's "world"): both seeds, the files the
// scenario derives from, the site, the sun, every array's mount and
// angle, and an uneven ground's relief and the soil's friction.
#include <string>

#include "pvb/scenes/scenario.hpp"

namespace pvb::run {

/// The object, one line; numbers as JSON allows (never NaN or inf).  A flat
/// ground with the default friction adds nothing ("ground" is absent).
std::string world_json(const scenes::Scenario& s);

}  // namespace pvb::run
