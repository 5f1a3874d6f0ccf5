#pragma once
// Which surfaces a session's matched landmarks lie on: the loaded map's
// landmarks that the session matched (their found count grew), taken into
// the world with T_world_map and labelled by the nearest sample of the true
// surface of the scenario the map was made in (sim::sample_truth_surface),
// so that moving panels (trackers) can be told from what stays (posts,
// ground, walls).
#include "pvb/run/map_session.hpp"
#include "pvb/sim/gl_context.hpp"

namespace pvb::run {

/// Fills report->matched_landmarks (or its note).  Renders the map's
/// scenario: seconds to a minute.
void classify_matched_landmarks(slam::System& system, sim::GlBackend backend, MapReport* report);

}  // namespace pvb::run
