#!/usr/bin/env bash
# The README's first command: install, build, and run the main job on the
# default photovoltaic scenario, end to end:
#   1. render the station (751 frames) into a TUM RGB-D sequence that
#      ORB-SLAM2 and other systems read unchanged;
#   2. simulation in the loop: render again and feed PE-SLAM and the
#      baseline (PE-match off, ORB-SLAM2 motion model) in memory, evaluate against ground truth, print the
#      ATE/RPE comparison and write the report (index.html, metrics.json,
#      figures, trajectories, contact sheet, run.log).
# Output goes to ./out/pv_station (override the root with PVB_OUT).
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
# pvbench, its render and camera plug-ins and the ORB vocabulary: the test
# programs and benchmarks are left to the test command.
bash ci/build.sh pvbench pvb_vocabulary
B=./build/bin/pvbench
OUT="${PVB_OUT:-out}/pv_station"
rm -rf "$OUT"
mkdir -p "$OUT"
echo "== 1/2 rendering scenes/pv_station.yaml into a TUM RGB-D sequence"
$B record --scenario scenes/pv_station.yaml --out "$OUT/sequence"
echo "== 2/2 PE-SLAM against the baseline (ORB-SLAM2 motion model), simulator in the loop"
$B run --scenario scenes/pv_station.yaml --compare --out "$OUT/report" | tee "$OUT/summary.txt"
echo "sequence: $OUT/sequence (TUM RGB-D, camera.yaml for ORB-SLAM2)"
echo "report:   $OUT/report/index.html (metrics.json, figures, trajectories, run.log)"
