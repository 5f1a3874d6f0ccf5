# Sourced by ci/build.sh and ci/sanitize.sh: pvb_configure DIR [cmake args]
# configures DIR the way CI builds it.
#  - A unity build (16 sources a compiler run): a cold build takes about a
#    third less time, and runs write byte-identical trajectories
#    (docs/testing.md).  PVB_UNITY=OFF builds file by file, as a plain
#    `cmake` configure does.
#  - Ninja where it is installed: it compiles a target's sources while the
#    libraries it links are still being built, which keeps both cores of a
#    small machine busy.  A folder keeps the generator it was made with.
pvb_configure() {
  local dir="$1"
  shift
  local gen=()
  if [ ! -f "$dir/CMakeCache.txt" ] && command -v ninja > /dev/null; then gen=(-G Ninja); fi
  cmake -S . -B "$dir" "${gen[@]}" -DCMAKE_UNITY_BUILD="${PVB_UNITY:-ON}" -DCMAKE_UNITY_BUILD_BATCH_SIZE=16 "$@"
}
