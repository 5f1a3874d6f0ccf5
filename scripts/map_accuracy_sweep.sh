#!/usr/bin/env bash
# Map accuracy over seeds, PE-SLAM against the baseline (docs/map_accuracy.md):
# for each scenario and seed, records the sequence, maps it with
# `pvbench slam --sync` with and without PE-match, scores both maps with
# `pvbench eval-map`, and prints one TSV line per map.
# Usage: scripts/map_accuracy_sweep.sh [BUILD_DIR] [OUT_DIR] [SEEDS] [SCENARIO...]
#   e.g. scripts/map_accuracy_sweep.sh build /tmp/mapacc "1 2 3" pv_station along_row
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
out="${2:-/tmp/pvb_map_accuracy}"
seeds="${3:-1 2 3}"
shift 3 2>/dev/null || true
scenarios=("${@:-pv_station}")
pv="$build/bin/pvbench"
mkdir -p "$out"
printf "scenario\tseed\tmethod\tate_mm\tacc_median_mm\tacc_p95_mm\tcomp2_pct\tcomp5_pct\tpanel_comp5_pct\twall_comp5_pct\tghost_pct\n"
for sc in "${scenarios[@]}"; do
  for seed in $seeds; do
    seq="$out/$sc-$seed/seq"
    [ -f "$seq/groundtruth.txt" ] || "$pv" record --scenario "$here/scenes/$sc.yaml" --seed "$seed" --out "$seq" >/dev/null
    for method in pe baseline; do
      run="$out/$sc-$seed/$method"
      flag=""; [ "$method" = baseline ] && flag="--no-pe-match"
      "$pv" slam --sequence "$seq" --settings "$seq/camera.yaml" --sync $flag --out "$run" >/dev/null
      "$pv" eval-map --map "$run/PointCloud.ply" --scenario "$here/scenes/$sc.yaml" --seed "$seed" \
        --trajectory "$run/CameraTrajectory.txt" --gt "$seq/groundtruth.txt" --out "$run/eval" >/dev/null
      python3 - "$run/eval/map_accuracy.json" "$sc" "$seed" "$method" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
a, pc = d["all"], d["per_class"]
c5 = lambda k: 100 * pc[k]["completeness_at"][2] if k in pc else float("nan")
print("\t".join([sys.argv[2], sys.argv[3], sys.argv[4], "%.2f" % (1000 * d["ate_rmse_m"]),
                 "%.1f" % (1000 * a["accuracy_m"]["median"]), "%.1f" % (1000 * a["accuracy_m"]["p95"]),
                 "%.1f" % (100 * a["completeness_at"][1]), "%.1f" % (100 * a["completeness_at"][2]),
                 "%.1f" % c5("panel"), "%.1f" % c5("wall"), "%.2f" % (100 * a["ghosting"])]))
PY
    done
  done
done
