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
ctest --test-dir build --output-on-failure -j "${PVB_JOBS:-$(nproc)}" -LE "slow|scenario-full" ${PVB_CTEST_ARGS:-}
[ "${PVB_SKIP_SANITIZE:-0}" = 1 ] || bash ci/sanitize.sh
