#pragma once
// Whether a sweep's seed failed, for the aggregate (aggregate.cpp) and the
// sweep's figure (sweep_figure.cpp).
#include "pvb/suite/aggregate.hpp"

namespace pvb::suite {

/// A seed failed: it has no metrics, or its run exited with an error.
inline bool seed_failed(const SeedRun& r) { return !r.metrics || r.exit_code != 0; }

}  // namespace pvb::suite
