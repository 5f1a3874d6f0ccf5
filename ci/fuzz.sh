#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) with clang, ASan and UBSan into
# build-fuzz/ and runs each for SECONDS (default 60) from its seed corpus.
# Fails on any crash, sanitizer report, leak, uncaught exception or hang (one
# input over 10 s).  Findings are written to build-fuzz/artifacts/.
#
#   bash ci/fuzz.sh [SECONDS] [TARGET...]      e.g. bash ci/fuzz.sh 3600 fuzz_settings
#
# The short run is the CTest test `fuzz.readers` (label slow); a longer run
# is the same command with more seconds (docs/testing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH="${1:-60}"
shift || true
ALL=(fuzz_settings fuzz_scenario fuzz_tum_trajectory fuzz_tum_lists fuzz_oni fuzz_metrics fuzz_vocabulary fuzz_map_file)
TARGETS=("$@")
[ ${#TARGETS[@]} -gt 0 ] || TARGETS=("${ALL[@]}")
JOBS="${PVB_JOBS:-$(nproc)}"
B=build-fuzz

mkdir -p "$B"
CC=clang CXX=clang++ cmake -S . -B "$B" -DCMAKE_BUILD_TYPE=Release -DPVB_FUZZ=ON \
  -DPVB_BUILD_TESTS=OFF -DPVB_BUILD_BENCHMARKS=OFF > "$B/configure.log" 2>&1 ||
  { cat "$B/configure.log"; exit 1; }
cmake --build "$B" -j "$JOBS" --target "${TARGETS[@]}"

# Seeds: the corpus in the repository plus the repository's own files of
# each kind (and the shared ORB-SLAM2 settings files when they are there).
seeds_of() {
  case "$1" in
    fuzz_settings) echo configs ../shared/data/tum ;;
    fuzz_scenario) echo scenes ;;
    fuzz_tum_trajectory) echo tests/fuzz/corpus/tum_trajectory tests/harness/eval/data ;;
    fuzz_tum_lists) echo tests/fuzz/corpus/tum_lists ;;
    fuzz_oni) echo tests/fuzz/corpus/oni ;;
    fuzz_metrics) echo tests/harness/suite/fixtures ;;
    fuzz_vocabulary) echo tests/fuzz/corpus/vocabulary ;;
    fuzz_map_file) echo tests/fuzz/corpus/map_file ;;
  esac
}

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:symbolize=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$PWD/ci/sanitizers/lsan.supp:print_suppressions=0"
mkdir -p "$B/artifacts"
summary=()
status=0
for t in "${TARGETS[@]}"; do
  corpus="$B/corpus/$t"
  mkdir -p "$corpus"
  dirs=()
  for d in $(seeds_of "$t"); do [ -d "$d" ] && dirs+=("$d"); done
  log="$B/$t.log"
  echo "fuzz: $t for ${SECONDS_EACH} s (seeds: ${dirs[*]:-none})"
  set +e
  max_len=65536
  [ "$t" = fuzz_map_file ] && max_len=262144  # its largest seed, a two-keyframe map, is 150 KB
  "$B/fuzz/$t" -max_total_time="$SECONDS_EACH" -timeout=10 -rss_limit_mb=4096 -max_len=$max_len \
    -print_final_stats=1 -artifact_prefix="$B/artifacts/$t-" "$corpus" "${dirs[@]}" > "$log" 2>&1
  rc=$?
  set -e
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo "?")
  files=$(find "$corpus" -type f | wc -l)
  if [ $rc -eq 0 ]; then
    summary+=("$t: ok, $runs inputs in ${SECONDS_EACH} s, coverage $cov, corpus $files files")
  else
    status=1
    summary+=("$t: FAILED (exit $rc), see $log and $B/artifacts/$t-*")
    tail -n 40 "$log"
  fi
done
printf '%s\n' "${summary[@]}"
exit $status
