#!/usr/bin/env bash
# The README's first command: install, build, and run the main job on the
# default photovoltaic scenario, end to end:
#   render the station (751 frames) -> PE-SLAM and the ORB-SLAM2 baseline
#   (synchronous, deterministic) -> ATE/RPE table, plots and JSON.
# Output goes to ./out/pv_station (override the root with PVB_OUT).
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
bash ci/build.sh
B=./build/bin/pvbench
OUT="${PVB_OUT:-out}/pv_station"
rm -rf "$OUT"
mkdir -p "$OUT/report"
echo "== 1/4 rendering scenes/pv_station.yaml"
$B record --scenario scenes/pv_station.yaml --out "$OUT/sequence"
echo "== 2/4 PE-SLAM"
$B slam --sequence "$OUT/sequence" --settings "$OUT/sequence/camera.yaml" --out "$OUT/pe_slam" --sync
echo "== 3/4 ORB-SLAM2 baseline (same binary, --no-pe-match)"
$B slam --sequence "$OUT/sequence" --settings "$OUT/sequence/camera.yaml" --out "$OUT/baseline" --sync --no-pe-match
echo "== 4/4 evaluation"
$B eval --gt "$OUT/sequence/groundtruth.txt" \
  --est "$OUT/pe_slam/CameraTrajectory.txt" --est "$OUT/baseline/CameraTrajectory.txt" \
  --json "$OUT/report/metrics.json" --plot "$OUT/report/trajectory.svg" | tee "$OUT/report/summary.txt"
cp "$OUT/sequence/contact_sheet.png" "$OUT/report/"
echo "report: $OUT/report (summary.txt, metrics.json, trajectory.svg/png, contact_sheet.png)"
