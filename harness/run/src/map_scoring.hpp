#pragma once
// A run's dense maps scored against the scenario's true surface: sampled
// once along the route's frames, then every system's maps (corrected, live,
// around the first loop) are put into the world by their first frame and
// scored.  The corrected map of each system also gets map_errors.ply and a
// top view coloured by error.
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/gl_context.hpp"
#include "run_log.hpp"
#include "system_sink.hpp"

namespace pvb::run {

/// Scores the maps the sinks hold (those with an evaluated trajectory) and
/// frees them; fills each run.dense_map.  A failure to sample the surface
/// is a note in the report, not an error.  Returns the time taken (ms).
double score_dense_maps(const scenes::Scenario& scenario, sim::GlBackend backend, const eval::Trajectory& gt,
                        SystemSinks& sinks, RunLog& log);

}  // namespace pvb::run
