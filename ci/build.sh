#!/usr/bin/env bash
# Configures and builds into ./build (Release; each unit test program one
# CTest test, tests/CMakeLists.txt).  Uses every core unless PVB_JOBS says
# otherwise.  ci/configure.sh says how (unity build, Ninja).
# With arguments it builds just those targets (and what they need), e.g.
#   bash ci/build.sh pvbench pvb_vocabulary
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${PVB_JOBS:-$(nproc)}"
source ci/configure.sh
pvb_configure build -DCMAKE_BUILD_TYPE=Release -DPVB_TEST_CXX_FLAGS=-O1 -DPVB_BATCH_UNIT_TESTS=ON ${PVB_CMAKE_ARGS:-}
if [ "$#" -gt 0 ]; then
  cmake --build build -j "$JOBS" --target "$@"
else
  cmake --build build -j "$JOBS"
fi
