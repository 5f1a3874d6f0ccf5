#!/usr/bin/env bash
# Configures and builds into ./build (Release).  Uses every core unless
# PVB_JOBS says otherwise.  A unity build (16 sources a compiler run) cuts a
# cold build by a third; its runs write byte-identical trajectories (docs/testing.md);
# PVB_UNITY=OFF builds file by file, as a plain `cmake` configure does.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${PVB_JOBS:-$(nproc)}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_UNITY_BUILD="${PVB_UNITY:-ON}" -DCMAKE_UNITY_BUILD_BATCH_SIZE=16 ${PVB_CMAKE_ARGS:-}
cmake --build build -j "$JOBS"
