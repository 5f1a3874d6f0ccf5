#!/usr/bin/env bash
# The README's test command: install, build, run the default test set.
# Slow tests (labels "slow" and "scenario-full") run with
#   ctest --test-dir build -L "slow|scenario-full"
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
bash ci/build.sh
ctest --test-dir build --output-on-failure -j "${PVB_JOBS:-$(nproc)}" -LE "slow|scenario-full" ${PVB_CTEST_ARGS:-}
