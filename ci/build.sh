#!/usr/bin/env bash
# Configures and builds into ./build (Release).  Uses every core unless
# PVB_JOBS says otherwise.  ci/configure.sh says how (unity build, Ninja).
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${PVB_JOBS:-$(nproc)}"
source ci/configure.sh
pvb_configure build -DCMAKE_BUILD_TYPE=Release -DPVB_TEST_CXX_FLAGS=-O1 ${PVB_CMAKE_ARGS:-}
cmake --build build -j "$JOBS"
