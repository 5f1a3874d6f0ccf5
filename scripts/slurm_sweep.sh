#!/usr/bin/env bash
# A pvbench seed sweep as a Slurm job array: each array task runs one seed,
# exactly the command `pvbench sweep --print-commands` prints for it, into
# OUT_DIR/seed_<task id>.  Aggregate afterwards with --aggregate-only.
#
#   jid=$(sbatch --parsable --array=1-20 scripts/slurm_sweep.sh scenes/pv_station.yaml /shared/sweeps/pv --compare --sync)
#   sbatch --dependency=afterany:$jid --wrap \
#     "build/bin/pvbench sweep --scenario scenes/pv_station.yaml --out /shared/sweeps/pv --aggregate-only"
#
# Usage: sbatch --array=SEEDS scripts/slurm_sweep.sh SCENARIO OUT_DIR [pvbench run options...]
#   SEEDS is Slurm's array syntax (1-20, 1,3,5, 1-5,9; add %4 to run at most 4 at once).
#   Paths are relative to the directory sbatch was called from (run it from the repository root).
#   PVBENCH overrides the program (default: build/bin/pvbench there).
#SBATCH --job-name=pvb-sweep
#SBATCH --cpus-per-task=2
#SBATCH --mem=4G
#SBATCH --time=01:00:00
#SBATCH --output=slurm-%A_%a.out
set -euo pipefail
if [[ $# -lt 2 ]]; then
  echo "usage: sbatch --array=1-20 $0 SCENARIO OUT_DIR [pvbench run options...]" >&2
  exit 2
fi
scenario="$1"
out="$2"
shift 2
seed="${SLURM_ARRAY_TASK_ID:?not an array task: submit with sbatch --array=SEEDS}"
cd "${SLURM_SUBMIT_DIR:-.}"
pvbench="${PVBENCH:-build/bin/pvbench}"
dir="$out/seed_$seed"
mkdir -p "$dir"
# One process per task; OpenCV and Ceres may use the task's CPUs.  A task
# run again replaces its seed's earlier output (--overwrite).
exec "$pvbench" run --scenario "$scenario" --seed "$seed" --out "$dir" --overwrite "$@" > "$dir/stdout.log" 2>&1
