#!/usr/bin/env bash
# The README's first command: install, build, and run the main job on the
# default photovoltaic scenario.  Output goes to ./out/pv_station.
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
bash ci/build.sh
OUT="${PVB_OUT:-out}/pv_station"
rm -rf "$OUT"
./build/bin/pvbench record --scenario scenes/pv_station.yaml --out "$OUT"
echo "sequence: $OUT (TUM RGB-D layout; contact sheet: $OUT/contact_sheet.png)"
