#!/usr/bin/env bash
# Reproduces docs/matching.md: the paper's matching experiment (Figs. 11-12,
# Table 1) on the Oxford wall/trees pairs, the TUM RGB-D pairs and pairs of a
# simulated PV station sequence.
# Usage: scripts/matching_experiment.sh [BUILD_DIR] [OUT_DIR] [RUNS]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
out="${2:-/tmp/pvb_matching}"
runs="${3:-10}"
data="$here/../shared/data"
pv="$build/bin/pvbench"
mkdir -p "$out"
for s in wall trees; do
  for k in 2 3 4; do
    "$pv" match --img1 "$data/oxford/$s/img1.ppm" --img2 "$data/oxford/$s/img$k.ppm" \
      --homography "$data/oxford/$s/H1to${k}p" --runs "$runs" --json "$out/oxford_${s}_1-$k.json" >/dev/null
  done
done
"$pv" match --sequence "$data/tum/fr1_xyz_pair" --frames 0,1 --settings "$data/tum/TUM1.yaml" \
  --runs "$runs" --json "$out/tum_fr1_xyz.json" >/dev/null
"$pv" match --sequence "$data/tum/fr1_xyz_pair" --frames 0,1 --settings "$data/tum/TUM1.yaml" \
  --gt-time-offset -0.02 --runs "$runs" --json "$out/tum_fr1_xyz_offset-0.02.json" >/dev/null
"$pv" match --sequence "$data/tum/fr3_long_office_household_pair" --frames 0,1 \
  --settings "$here/configs/tum/TUM3.yaml" --runs "$runs" --json "$out/tum_fr3_office.json" >/dev/null
# Simulated PV station (default scenario, seed 7): pairs at 1, 5 and 10 frames.
seq="$out/pv_station_seq"
[ -f "$seq/groundtruth.txt" ] || "$pv" record --scenario "$here/scenes/pv_station.yaml" --out "$seq" --frames 160 --seed 7 >/dev/null
for base in 40 120; do
  for d in 1 5 10; do
    "$pv" match --sequence "$seq" --frames "$base,$((base + d))" --runs "$runs" \
      --json "$out/sim_pv_station_${base}+${d}.json" >/dev/null
  done
done
python3 - "$out" <<'PY'
import json, sys, glob, os
out = sys.argv[1]
for f in sorted(glob.glob(os.path.join(out, "*.json"))):
    j = json.load(open(f))
    m0 = j["methods"][0]
    print(f"\n**{os.path.basename(f)[:-5]}** — coarse {m0['coarse']} checked, {m0['coarse_correct']} correct"
          f" ({m0['unknown']} without ground truth); ORB on both images + matching {j['extract_match_ms']:.1f} ms\n")
    print("| method | precision mean ± std [min, max] | recall mean ± std [min, max] | kept | filter ms mean ± std |")
    print("|---|---|---|---|---|")
    for m in j["methods"]:
        print(f"| {m['name']} | {m['precision']:.3f} ± {m['precision_std']:.3f} [{m['precision_min']:.3f}, {m['precision_max']:.3f}]"
              f" | {m['recall']:.3f} ± {m['recall_std']:.3f} [{m['recall_min']:.3f}, {m['recall_max']:.3f}]"
              f" | {m['kept']:.1f} | {m['time_ms']:.3f} ± {m['time_ms_std']:.3f} |")
PY
