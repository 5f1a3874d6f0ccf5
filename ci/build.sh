#!/usr/bin/env bash
# Configures and builds into ./build (Release).  Uses every core unless
# PVB_JOBS says otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${PVB_JOBS:-$(nproc)}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release ${PVB_CMAKE_ARGS:-}
cmake --build build -j "$JOBS"
