#!/usr/bin/env bash
# The README's test command (and `.ci/run`): install, build, run the default
# test set, then the sanitizer job (ci/sanitize.sh: ASan + UBSan build, unit
# tests, one short scenario run).  PVB_SKIP_SANITIZE=1 leaves that out.
# Slow tests (labels "slow" and "scenario-full") run with
#   ctest --test-dir build -L "slow|scenario-full"
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
bash ci/build.sh
# The tests render through EGL (llvmpipe where there is no GPU), named here
# once: with the backend left to `auto`, each of the default set's ~1,300
# processes that renders would first probe for one in a child process
# (about 0.3 s each).  A MUJOCO_GL already set wins; the probe keeps tests
# of its own (tests/sim/test_renderer.cpp).
export MUJOCO_GL="${MUJOCO_GL:-egl}"
ctest --test-dir build --output-on-failure -j "${PVB_JOBS:-$(nproc)}" -LE "slow|scenario-full" ${PVB_CTEST_ARGS:-}
[ "${PVB_SKIP_SANITIZE:-0}" = 1 ] || bash ci/sanitize.sh
