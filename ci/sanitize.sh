#!/usr/bin/env bash
# The sanitizer job: builds the libraries, pvbench and the unit tests with
# ASan and UBSan into build-asan/ (-O1, line tables, the test programs' own
# sources at -O0, no benchmarks, no scenario test programs; configured as
# ci/configure.sh says) and runs the unit tests and one short scenario run
# under them.  It builds with clang where it is installed (ci/install-deps.sh
# installs it for the fuzzers): clang compiles the instrumented code about
# 2.5 times faster than GCC (docs/testing.md).  PVB_SANITIZE_CXX=g++ builds
# with GCC instead.  A report from our own code fails it; known reports inside
# Mesa, llvmpipe, MuJoCo and OpenNI2 are suppressed by ci/sanitizers/*.supp,
# each entry with its reason.
# `.ci/run` runs it after the default tests (docs/testing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${PVB_JOBS:-$(nproc)}"
B=build-asan

# The main build's vocabulary, when there is one, instead of training it
# again with the sanitized pvbench.
VOCAB="$PWD/build/vocabulary/pvbench_orb.pvbvoc"
[ -f "$VOCAB" ] && VOCAB_ARG="-DPVB_PREBUILT_VOCABULARY=$VOCAB" || VOCAB_ARG=""
# PVB_SANITIZE_CXX names the C++ compiler (clang++ where it is installed,
# else g++).  A build folder made with another compiler is made again.
DEFAULT_CXX_SAN=g++
command -v clang++ > /dev/null && DEFAULT_CXX_SAN=clang++
CXX_SAN="$(command -v "${PVB_SANITIZE_CXX:-$DEFAULT_CXX_SAN}" || true)"
if [ -n "$CXX_SAN" ]; then
  case "$(basename "$CXX_SAN")" in
    clang++*) CC_SAN="${CXX_SAN/clang++/clang}" ;;
    g++*) CC_SAN="${CXX_SAN/g++/gcc}" ;;
    *) CC_SAN="$(command -v cc)" ;;
  esac
  export CXX="$CXX_SAN" CC="$CC_SAN"
  if [ -f "$B/CMakeCache.txt" ] && ! grep -qx "CMAKE_CXX_COMPILER:FILEPATH=$CXX_SAN" "$B/CMakeCache.txt"; then
    rm -rf "$B"
  fi
fi
source ci/configure.sh
pvb_configure "$B" -DCMAKE_BUILD_TYPE=Release -DPVB_SANITIZE=address,undefined -DPVB_BUILD_BENCHMARKS=OFF -DPVB_UNIT_TESTS_ONLY=ON -DPVB_TEST_CXX_FLAGS=-O0 \
  -DCMAKE_CXX_FLAGS_RELEASE="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELEASE="-O1 -g1 -DNDEBUG" $VOCAB_ARG ${PVB_CMAKE_ARGS:-}
cmake --build "$B" -j "$JOBS"

S="$PWD/ci/sanitizers"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=0:suppressions=$S/asan.supp"
export LSAN_OPTIONS="suppressions=$S/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$S/ubsan.supp"

# Mesa's EGL unloads its llvmpipe driver at eglTerminate, before
# LeakSanitizer reports at exit, so the driver's known per-process leak
# (240 B) shows up in "<unknown module>", which no suppression can name.
# So every process renders through OSMesa (its leak is suppressed by name),
# and the tests that must use EGL run with leak checking off (ASan's other
# checks and UBSan stay on): the test programs name them (pvb_add_test's
# NOLEAK, run as PROGRAM.noleak).
export MUJOCO_GL=osmesa

# The unit tests (the default set's fast tests; the CLI tests among them run
# the sanitized pvbench too), one CTest test per program.
ctest --test-dir "$B" --output-on-failure -j "$JOBS" -L '^unit$' ${PVB_CTEST_ARGS:-}

# One short scenario run, threaded (tracking, local mapping, dense mapping
# and the render/sensor pipeline), PE-SLAM and the baseline.
out="$B/scenario_run"
rm -rf "$out"
"$B/bin/pvbench" run --scenario scenes/pv_station.yaml --frames 60 --compare --no-pace --out "$out" \
  > "$out.log" 2>&1 || { tail -n 60 "$out.log"; echo "sanitize: the scenario run failed"; exit 1; }
tail -n 3 "$out.log"
echo "sanitize: ok"
